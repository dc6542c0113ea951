"""The NLP solvers of :mod:`orrc.solvers.nlp` (SQP and IPOPT), their default options, and how a user's
``solver_options`` reach them.

**Options.** ``solver_options`` keys that start with ``"sqpmethod."`` go to the SQP solver (the
prefix removed; e.g. ``{"sqpmethod.max_iter": 20}``, ``{"sqpmethod.qpsol": "osqp"}``), keys that
start with ``"ipopt."`` to IPOPT (CasADi's own syntax, e.g. ``{"ipopt.max_iter": 100}``), and other
keys (options of every CasADi ``nlpsol``, e.g. ``"print_time"``) to each solver that is built.

**SQP's QP solver by size.** From the horizon :data:`HPIPM_FROM` on, SQP solves its QPs with HPIPM (a
Riccati recursion, whose work grows linearly with M) instead of ``qrqp``, unless ``solver_options`` name a
QP solver (``{"sqpmethod.qpsol": "qrqp"}`` keeps qrqp at any size); HPIPM needs the NLP's variables in stage
order (:func:`structured_qpsol`), which :class:`~orrc.solvers.nlp.ShootingNLP` then uses.
Two of SQP's defaults serve the closed loop's speed and change no answer: ``error_on_fail`` (an
unsuccessful solve raises, so a successful one is known without reading the solver's statistics;
:meth:`ShootingNLP.solve <orrc.solvers.nlp.ShootingNLP.solve>` reads an unsuccessful one as before) and no multipliers of the parameters
(``calc_lam_p`` off: nothing here uses them, and each solve saves a gradient evaluation).
"""
from __future__ import annotations

import re

import casadi as ca

from .._validate import OrrcValueError

SQP, IPOPT = "sqp", "ipopt"
#: the NLP solvers, in the order of the default failure ladder (SQP first, IPOPT as the fallback)
NLP_SOLVERS = (SQP, IPOPT)
#: how the solvers are named in statuses and messages
SOLVER_LABELS = {SQP: "SQP", IPOPT: "IPOPT"}
#: the prefix of a solver's own keys in ``solver_options``
OPTION_PREFIX = {SQP: "sqpmethod.", IPOPT: "ipopt."}
_PLUGIN = {SQP: "sqpmethod", IPOPT: "ipopt"}

DEFAULT_IPOPT = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "ipopt.tol": 1e-9,
    "ipopt.acceptable_tol": 1e-6,
    "ipopt.max_iter": 500,
}

_QRQP_QUIET = {"print_iter": False, "print_header": False, "print_info": False}

DEFAULT_SQP = {
    "qpsol": "qrqp",
    "qpsol_options": dict(_QRQP_QUIET, error_on_fail=False),
    "hessian_approximation": "exact",
    "convexify_strategy": "eigen-clip",
    "tol_pr": 1e-8,
    "tol_du": 1e-8,
    "max_iter": 50,
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "print_time": False,
    # an unsuccessful solve raises (CasADi's error text: UNSUCCESSFUL), so that a successful one is known
    # without reading its statistics; its answer and statistics are there as without the option
    "error_on_fail": True,
    # no multipliers of the parameters (nothing here uses them): no gradient evaluation after each solve
    "calc_lam_p": False,
    "no_nlp_grad": True,
}
#: what CasADi raises for an unsuccessful solve with ``error_on_fail`` (the solve itself ran as without it)
UNSUCCESSFUL = "nlpsol process failed"
#: the status of every successful ``sqpmethod`` solve (the only one with ``success``)
SQP_SOLVED = "Solve_Succeeded"
_NEEDS_NLP_GRAD = ("calc_lam_p", "calc_lam_x", "calc_f", "calc_g")

#: the horizon from which SQP's QP solver is HPIPM (a Riccati recursion: work linear in M) instead of qrqp
#: (a general sparse QP solver), unless ``solver_options`` name one. Measured on orrc's closed loop of the
#: pendulum (``benchmarks/structure.py``): HPIPM is 1.5x slower at M = 10, 1.1x slower at M = 20, and 1.2x
#: faster at M = 30, 1.35x at M = 50, 2.3x at M = 100, 4.8x at M = 200, with the same closed loop. Its
#: interior-point multipliers are complementary to about 1e-9: where the optimal cost J is tiny (below about
#: 0.1), an answer can fail the acceptance check (1e-8 |J|) and the step is solved again by the next rung
HPIPM_FROM = 30
#: HPIPM's options: quiet (its own stopping tolerances: SQP's answers pass the acceptance checks with them, and
#: tighter ones cost many more of its iterations)
_HPIPM = {"error_on_fail": False}



def _split_options(solver_options: dict | None, solvers) -> tuple[dict, list]:
    """``{solver: options}`` for the ``solvers`` to build, from the user's ``solver_options`` merged
    into the defaults (module docstring: ``"sqpmethod."`` keys for SQP, ``"ipopt."`` keys for
    IPOPT, other keys for each), and the keys that none of ``solvers`` takes (to warn about)."""
    given = dict(solver_options or {})
    out, unused = {}, []
    for key in given:
        owner = [s for s, pre in OPTION_PREFIX.items() if key.startswith(pre)]
        if owner and owner[0] not in solvers:
            unused.append(key)
    for s in solvers:
        opts = dict(DEFAULT_SQP if s == SQP else DEFAULT_IPOPT)
        if s == SQP:
            opts["qpsol_options"] = dict(opts["qpsol_options"])
        for key, value in given.items():
            own = [t for t, pre in OPTION_PREFIX.items() if key.startswith(pre)]
            if own and own[0] != s:
                continue
            if s == SQP and own:
                key = key[len(OPTION_PREFIX[SQP]):]
            if s == SQP and key == "qpsol" and value != opts["qpsol"]:
                opts["qpsol_options"] = {"error_on_fail": False}  # qrqp's print options are qrqp's own
            if s == SQP and key == "qpsol_options" and isinstance(value, dict):
                opts["qpsol_options"].update(value)
            else:
                opts[key] = value
        if s == SQP and any(opts.get(key) for key in _NEEDS_NLP_GRAD):
            opts["no_nlp_grad"] = False   # the user asked for what the gradient function computes
        out[s] = opts
    return out, unused


def structured_qpsol(opts: dict, given: dict | None, M: int, n: int, m: int) -> bool:
    """Choose SQP's QP solver by size, in place in ``opts`` (:func:`_split_options`' result): HPIPM from the
    horizon :data:`HPIPM_FROM` on, where ``given`` (the user's ``solver_options``) names no QP solver; with
    HPIPM (chosen here or by the user), its stage dimensions. Returns whether the NLP's variables must be in
    stage order (HPIPM's)."""
    sqp = opts.get(SQP)
    if sqp is None:
        return False
    named = any(k.removeprefix(OPTION_PREFIX[SQP]) in ("qpsol", "qpsol_options") for k in (given or {}))
    if not named and M >= HPIPM_FROM and ca.has_conic("hpipm"):
        sqp["qpsol"], sqp["qpsol_options"] = "hpipm", {k: (dict(v) if isinstance(v, dict) else v)
                                                        for k, v in _HPIPM.items()}
    if sqp["qpsol"] != "hpipm":
        return False
    stages = {"N": M, "nx": [0] + [n] * M, "nu": [m] * M + [0], "ng": [0] * (M + 1)}
    sqp["qpsol_options"] = stages | dict(sqp["qpsol_options"])
    return True


def _nlpsol(solver: str, problem: dict, opts: dict, given: dict | None):
    try:
        return ca.nlpsol(f"rhc_{solver}", _PLUGIN[solver], problem, opts)
    except RuntimeError as exc:  # CasADi rejects unknown options at construction
        first = _last_line(exc)
        hint = (" (options of one solver take its prefix: 'sqpmethod.max_iter', 'ipopt.max_iter'; "
                "unprefixed keys go to every solver)") if given else ""
        raise OrrcValueError(
            f"CasADi rejected the NLP solver {SOLVER_LABELS[solver]} ({_PLUGIN[solver]}) with solver_options "
            f"{sorted(given or {})}: {first}{hint}") from exc


def _last_line(exc: Exception) -> str:
    """The informative line of a CasADi error (its source location dropped): the one naming the unknown
    option or missing plugin when there is one, else the last."""
    lines = [ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()]
    if not lines:
        return type(exc).__name__
    keys = ("Unknown option", "No such", "not found", "Invalid", "failed")
    line = next((ln for ln in lines if any(k in ln for k in keys)), lines[-1])
    return re.sub(r"^(\.\.\./)?\S+\.(cpp|hpp):\d+: ", "", line)[:200]
