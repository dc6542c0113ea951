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

**SQP's Hessian** (:func:`sqp_hessian`). ``"exact"``: the Hessian of the Lagrangian, the cost's and the
dynamics' second derivatives, convexified block by block (``eigen-clip``). ``"gauss-newton"``: the Hessian of
the objective alone, the curvature of the dynamics dropped (what acados calls the Gauss-Newton Hessian of a
least-squares cost; for a quadratic stage cost it is the cost's own, positive semi-definite, so it is not
convexified). Either converges to the same KKT point (SQP stops on the gradient of the Lagrangian and the
constraint violation, which do not involve the Hessian); they differ in the steps taken, and the
Gauss-Newton Hessian costs nothing to evaluate and converges linearly, at a rate set by the dynamics'
curvature times the multipliers. ``"auto"`` (the default) takes the Gauss-Newton Hessian for a
:class:`~orrc.QuadraticCost` from :data:`GAUSS_NEWTON_FROM` variables per stage (n + m) on, where it is measured
to pay, and the exact one otherwise. The choice is forced by :class:`~orrc.solvers.nlp.ShootingNLP`'s ``hessian``
or by ``solver_options={"sqpmethod.hessian_approximation": "gauss-newton"}`` (or ``"exact"``).
"""
from __future__ import annotations

import math
import re

import casadi as ca
import numpy as np

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
#: pendulum (``benchmarks/structure.py``, HPIPM in its speed mode): HPIPM is 1.05x slower at M = 10, even at
#: M = 20 (1.05x faster, within a run's noise), and 1.3x faster at M = 30, 2.0x at M = 50, 3.0x at M = 100,
#: 5.9x at M = 200, with the same closed loop. Its
#: interior-point multipliers are complementary to about 1e-9: where the optimal cost J is tiny (below about
#: 0.1), an answer can fail the acceptance check (1e-8 |J|); it is then polished by SQP with qrqp
#: (:mod:`orrc.solvers.nlp`, "Accepting an SQP answer")
HPIPM_FROM = 30
#: SQP's Hessians (:func:`sqp_hessian`): of the Lagrangian, or of the objective alone
EXACT, GAUSS_NEWTON = "exact", "gauss-newton"
#: what ``hessian`` may be (:class:`~orrc.solvers.nlp.ShootingNLP`)
HESSIANS = ("auto", EXACT, GAUSS_NEWTON)
#: the variables per stage (n + m) from which ``hessian="auto"`` takes the Gauss-Newton Hessian (quadratic stage
#: costs only). Measured on orrc's closed loops at M = 50 (``benchmarks/scaling.py``): with the exact Hessian,
#: CasADi's eigenvalue convexification (``eigen-clip``, and ``eigen-reflect`` alike) of stage blocks of 16 and 25
#: variables gave non-finite steps (the quadrotor, n + m = 16: SQP failed at 28 of 30 steps and IPOPT took them;
#: the chain of 12 masses, n + m = 25: at 7 of 100), while the Gauss-Newton Hessian, not convexified, solved every
#: step by SQP (quadrotor 4.6 ms a step against 23.5 ms; chain 15 ms against 20 ms). Below, the exact Hessian's
#: quadratic convergence pays: the chain of 4 and 6 masses (n + m = 9, 13) took 2.4 and 2.7 SQP iterations a step
#: with it, 4.1 and 4.6 with Gauss-Newton, 1.4x and 1.3x the time
GAUSS_NEWTON_FROM = 16
#: HPIPM's options: quiet, and its ``"speed"`` mode (its own stopping tolerances: SQP's answers pass the acceptance
#: checks with them, and tighter ones cost many more of its iterations). The mode changes how HPIPM iterates, not
#: its tolerances: on the pendulum at M = 100 it gave the default mode's closed loop (the same costs to 1e-15)
#: 1.3x sooner, and the chain's of 6 and 12 masses at M = 50 (to 1e-11) 1.1x and 1.15x sooner. Where the optimal
#: cost is small (the chain of one mass near rest, J about 0.004 at M = 50), 2 of 100 answers fail the
#: complementarity check (Σ λ·gap about 1e-10..1e-9 against 1e-8 |J|) from the warm and the cold start alike.
#: Tightening HPIPM's complementarity tolerance (``res_m_max`` 1e-10 or 1e-12) makes every answer pass but made
#: that closed loop 2.8x slower, and qrqp (exactly complementary) for every solve 1.4x slower; so the check is
#: kept as it is and such an answer is polished instead: one SQP iteration with qrqp from it (about 0.6 ms
#: there), where IPOPT took those steps before
_HPIPM = {"error_on_fail": False, "hpipm": {"mode": "speed"}}



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


def sqp_hessian(hessian: str, opts: dict, given: dict | None, stage: int, quadratic: bool) -> str | None:
    """Choose SQP's Hessian for Eq. (3), the M-step problem of Algorithm 1: the exact Hessian of the Lagrangian
    or the Gauss-Newton one (the objective's alone; module docstring), in place in ``opts``.

    Parameters
    ----------
    hessian : str
        One of :data:`HESSIANS`: ``"auto"`` takes the ``"hessian_approximation"`` the user named in ``given``,
        else Gauss-Newton for a quadratic stage cost from :data:`GAUSS_NEWTON_FROM` variables per stage on;
        ``"exact"`` or ``"gauss-newton"`` force it.
    opts : dict
        ``{solver: options}`` (:func:`_split_options`' result), changed in place: SQP's options keep CasADi's
        own value ``"exact"`` (the Gauss-Newton Hessian reaches the solver as its ``hess_lag`` function, built by
        :class:`~orrc.solvers.nlp.ShootingNLP`), and lose their convexification for a quadratic cost with
        Gauss-Newton (its Hessian is positive semi-definite already).
    given : dict or None
        The user's ``solver_options``.
    stage : int
        The variables per stage, n + m.
    quadratic : bool
        Whether the stage cost is a :class:`~orrc.QuadraticCost` (and there is no terminal cost).

    Returns
    -------
    str or None
        :data:`EXACT` or :data:`GAUSS_NEWTON`; None without an SQP solver or with CasADi's ``"limited-memory"``.

    Raises
    ------
    orrc.OrrcValueError
        When ``hessian`` is not one of :data:`HESSIANS`, or contradicts the options' named Hessian.

    Examples
    --------
    >>> from orrc.solvers.nlp_solvers import sqp_hessian, _split_options
    >>> opts, _ = _split_options(None, ("sqp",))
    >>> sqp_hessian("auto", opts, None, stage=25, quadratic=True), "convexify_strategy" in opts["sqp"]
    ('gauss-newton', False)
    >>> opts, _ = _split_options(None, ("sqp",))
    >>> sqp_hessian("auto", opts, None, stage=3, quadratic=True)
    'exact'
    """
    if hessian not in HESSIANS:
        raise OrrcValueError(f"hessian must be one of {HESSIANS}; got {hessian!r}")
    sqp = opts.get(SQP)
    if sqp is None:
        return None
    named = sqp.get("hessian_approximation", EXACT)
    if named not in (EXACT, GAUSS_NEWTON):
        if hessian == GAUSS_NEWTON:
            raise OrrcValueError(f"hessian='gauss-newton' contradicts solver_options' "
                                 f"'sqpmethod.hessian_approximation': {named!r}")
        return None   # CasADi's own approximation (limited-memory), as the user asked
    sqp["hessian_approximation"] = EXACT
    if hessian == "auto":
        asked = any(k.removeprefix(OPTION_PREFIX[SQP]) == "hessian_approximation" for k in (given or {}))
        hessian = named if asked else (GAUSS_NEWTON if quadratic and stage >= GAUSS_NEWTON_FROM else EXACT)
    elif named != hessian and any(k.removeprefix(OPTION_PREFIX[SQP]) == "hessian_approximation" for k in (given or {})):
        raise OrrcValueError(f"hessian={hessian!r} contradicts solver_options' 'sqpmethod.hessian_approximation': "
                             f"{named!r}")
    if hessian == GAUSS_NEWTON and quadratic:
        sqp.pop("convexify_strategy", None)   # the cost's Hessian: positive semi-definite already
    return hessian


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


def _stats(call) -> dict:
    """The solver's statistics of its last solve; where CasADi cannot produce them (``sqpmethod`` stopped by an
    internal error leaves its status unset, and reading it raises), an unsuccessful solve saying so."""
    try:
        return call.stats()
    except RuntimeError as exc:
        return {"success": False, "iter_count": 0,
                "return_status": f"error: the solver stopped without a status ({_last_line(exc)})"}


def _qrqp_sqp(problem: dict, sqp_options: dict) -> ca.Function:
    """SQP with the QP solver qrqp on ``problem`` with SQP's other options (the Hessian among them): what polishes an
    answer of SQP with HPIPM whose multipliers are not complementary enough (:mod:`orrc.solvers.nlp`)."""
    opts = dict(sqp_options, qpsol="qrqp", qpsol_options=dict(_QRQP_QUIET, error_on_fail=False), error_on_fail=False)
    return ca.nlpsol("rhc_sqp_polish", _PLUGIN[SQP], problem, opts)


def _solve_once(solver: ca.Function, z, p, lbz, ubz):
    """One solve of ``solver`` from z with parameters p (g = 0): ((z, None, g, λ_x, λ_g), J, iterations), or None
    where it fails, raises or gives a non-finite answer."""
    try:
        out = solver(x0=z, p=p.copy(), lbx=lbz, ubx=ubz, lbg=0.0, ubg=0.0)
        stats = solver.stats()
    except RuntimeError:
        return None
    zp, value = np.asarray(out["x"]).ravel(), float(out["f"])
    if not (stats.get("success") and math.isfinite(value) and np.isfinite(zp).all()):
        return None
    res = (zp, None, np.asarray(out["g"]).ravel(), np.asarray(out["lam_x"]).ravel(), np.asarray(out["lam_g"]).ravel())
    return res, value, int(stats.get("iter_count", 0) or 0)


def _last_line(exc: Exception) -> str:
    """The informative line of a CasADi error (its source location dropped): the one naming the unknown
    option or missing plugin when there is one, else the last."""
    lines = [ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()]
    if not lines:
        return type(exc).__name__
    keys = ("Unknown option", "No such", "not found", "Invalid", "failed")
    line = next((ln for ln in lines if any(k in ln for k in keys)), lines[-1])
    return re.sub(r"^(\.\.\./)?\S+\.(cpp|hpp):\d+: ", "", line)[:200]
