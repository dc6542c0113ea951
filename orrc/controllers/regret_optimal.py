"""The regret-optimal controller over a finite horizon (Goel and Hassibi, "Regret-optimal control in
dynamic environments", 2021; Sabag, Goel, Lale and Hassibi, "Regret-optimal controller for the
full-information problem", ACC 2021).

Among all causal controllers, the one whose worst-case dynamic regret against the clairvoyant
optimum, over disturbances of unit energy ‖w‖ <= 1 from x_0 = 0, is smallest. For a linear-
quadratic problem over T steps a causal linear controller is u_t = −K x_t + v_t, v = Φ w, with Φ
strictly block lower triangular (v_t depends on w_0..w_{t-1}, equivalently on x_0..x_t; K is the
LQR gain, a pre-stabilisation that keeps the matrices well conditioned and changes nothing else),
and its regret is ‖S^½(Φ − Φ*)w‖² (:mod:`orrc.solvers.condensed`). So the worst-case regret is
‖S^½(Φ − Φ*)‖₂², and the regret-optimal Φ solves the convex problem

    minimise ‖S^½(Φ − Φ*)‖₂  over strictly block-lower-triangular Φ,

solved by default with its structure (``method="structured"``, :mod:`orrc.solvers.regret`): a causal
factor Δ of S (ΔᵀΔ = S, Δ lower triangular) turns it into the distance from ΔΦ* to the strictly
causal operators, whose value is Arveson's distance formula and whose optimum Parrott's theorem
builds one block row at a time (Goel and Hassibi's reduction to a Nehari-type problem, in finite
dimensions): T = 200 with n = 2, m = 1 in seconds. ``method="sdp"`` solves the same problem as a
semidefinite program (the spectral norm is an LMI of size T(m+n)) with cvxpy and the open-source
conic solver Clarabel: the cross-check, for small problems (T(m + n) <= 64).

By default the controller is *strictly causal*: u_t depends on x_0..x_t (equivalently
w_0..w_{t-1}), never on w_t, as in Goel and Hassibi's causal class. With
``causality="full-information"`` u_t may also use w_t (Sabag et al.'s full-information class): Φ is
then block lower triangular with its diagonal free. That problem is the strictly causal one on Φ*
with its block columns shifted left by one (column s of the full-information problem is column
s − 1 of the shifted one; the first column is unconstrained and is matched exactly), so the same
structured solver serves both.
"""
from __future__ import annotations

import warnings

import numpy as np

from .._validate import OrrcValueError, as_int
from .._problem import check_problem
from ..costs import QuadraticCost
from ..solvers.condensed import condensed
from ..solvers.nlp import SolverWarning
from ..solvers.regret import regret_optimal_operator
from ..systems import LinearSystem
from .base import Controller, Decision, Observation

__all__ = ["RegretOptimal", "MAX_LMI_DIM", "METHODS", "CAUSALITY"]

MAX_LMI_DIM = 64  # T (m + n): the size of the SDP's matrix inequality (a few seconds with Clarabel at the limit)
#: the values of ``RegretOptimal(method=...)``
METHODS = ("structured", "sdp")
#: the values of ``RegretOptimal(causality=...)``: u_t without w_t, or with it
CAUSALITY = ("strict", "full-information")
#: the structured method's operations (module orrc.solvers.regret: about (T m)³ (T n) / 2, plus the
#: condensed operators), measured here at about 1e9 per second on one core
_OPS_PER_SECOND = 1e9


def _check_sdp_size(T: int, n: int, m: int) -> None:
    """The SDP's own limit (its time is set by the size of the matrix inequality, measured with Clarabel
    here: about 0.5 s at size 40, 3 s at 60, 15 s at 80, 90 s at 120), then the package's memory and
    operation limits for the condensed operators (orrc._validate.check_size)."""
    from .._validate import check_size

    dim = T * (m + n)
    if dim > MAX_LMI_DIM:
        free = T * (T - 1) // 2 * m * n
        raise OrrcValueError(
            f"T = {T} is too large for the regret-optimal SDP: its matrix inequality has size "
            f"T(m + n) = {dim} (limit {MAX_LMI_DIM}) with {free} free entries of Φ and "
            f"{dim * (dim + 1) // 2} entries in the semidefinite cone; use T <= {MAX_LMI_DIM // (m + n)} "
            f"for n = {n}, m = {m}")
    _check_operator_size(T, n, m)


def _check_operator_size(T: int, n: int, m: int) -> None:
    """The package's memory and operation limits (orrc._validate.check_size) for the condensed operators
    and the structured method's sweep (:mod:`orrc.solvers.regret`), with the estimate in the message."""
    from .._validate import check_size

    ops = 20.0 * (T * max(n, m)) ** 3 + 0.5 * (T * m) ** 3 * (T * n) + T * (T * m) * (T * n) ** 2
    check_size(f"RegretOptimal over T={T} steps (n={n}, m={m}): the condensed operators and the structured "
               f"solve (about {ops / _OPS_PER_SECOND:.2g} s)",
               nbytes=8.0 * 8 * (T * max(n, m)) ** 2, ops=ops, hint="lower T")


def _causal_mask(T: int, m: int, n: int, causality: str = "strict") -> np.ndarray:
    """The (T m, T n) 0/1 pattern of the admissible Φ: block (t, s) free for s < t ("strict") or
    s <= t ("full-information")."""
    k = -1 if causality == "strict" else 0
    return np.kron(np.tril(np.ones((T, T)), k=k), np.ones((m, n)))


def _full_information_operator(S, Phi_star, T: int, m: int, n: int):
    """(Φ, γ*²) of the full-information problem by the strictly causal solver on the shifted Φ*:
    block column s of Φ* becomes column s − 1 (the last column is 0), the strictly causal optimum is
    shifted back, and Φ's first block column, free in every row, is Φ*'s own."""
    shifted = np.zeros_like(Phi_star)
    shifted[:, :-n] = Phi_star[:, n:]
    Phi_shift, value = regret_optimal_operator(S, shifted, T, m, n)
    Phi = np.zeros_like(Phi_star)
    Phi[:, n:] = Phi_shift[:, :-n]
    Phi[:, :n] = Phi_star[:, :n]
    return Phi, value


def _solve_sdp(c, T: int, m: int, n: int, causality: str = "strict"):
    """(Φ, optimal value squared, status) of the regret-optimal SDP: minimise ‖S^½(Φ − Φ*)‖₂ over the
    causal Φ (:func:`causal_mask`), with cvxpy and Clarabel (the cross-check of the structured method)."""
    import cvxpy as cp

    mask = _causal_mask(T, m, n, causality)
    V = cp.Variable((T * m, T * n))
    Phi = cp.multiply(mask, V)
    objective = cp.Minimize(cp.sigma_max(c.S_half @ Phi - c.S_half @ c.Phi_star))
    prob = cp.Problem(objective)
    try:
        prob.solve(solver="CLARABEL")
    except cp.error.SolverError as exc:
        raise RuntimeError(f"the regret-optimal SDP failed in Clarabel: {exc}") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or V.value is None:
        raise RuntimeError(f"the regret-optimal SDP was not solved (Clarabel status {prob.status!r})")
    if prob.status == "optimal_inaccurate":
        warnings.warn("the regret-optimal SDP was solved only inaccurately (Clarabel); the reported "
                      "regret is that of the operator found", SolverWarning, stacklevel=3)
    return mask * np.asarray(V.value), float(prob.value) ** 2, prob.status


class RegretOptimal(Controller):
    """The causal controller with the smallest worst-case dynamic regret over T steps, min ‖S^½(Φ − Φ*)‖₂.

    Parameters
    ----------
    system : LinearSystem
        The linear system x⁺ = Ax + Bu + w.
    cost : QuadraticCost
        The stage cost xᵀQx + uᵀRu.
    T : int
        The horizon (>= 2); the controller is designed from x_0 = 0 for t < T.
    method : {"structured", "sdp"}
        "structured" (default): Arveson's distance formula and Parrott's completion on a causal
        factor of S (:mod:`orrc.solvers.regret`), refused with the estimate beyond the package's size
        limits (``orrc.config``); "sdp": the semidefinite program with Clarabel, the cross-check
        (T(m + n) <= :data:`MAX_LMI_DIM`, else a clear error with the limit).
    causality : {"strict", "full-information"}
        "strict" (default): u_t uses x_0..x_t, i.e. w_0..w_{t-1}; "full-information": u_t may also
        use w_t (the controller then declares one step of preview).

    Attributes
    ----------
    Phi : ndarray (T m, T n)
        The optimal disturbance-feedback operator, v = Φ w with u_t = −K x_t + v_t (block (t, s) nonzero
        only for s < t, or s <= t with full information; K = ``condensed.K``, the LQR gain).
    regret : float
        Its worst-case dynamic regret over ‖w‖ <= 1, ‖S^½(Φ − Φ*)‖₂² (computed from Φ with numpy).
    value : float
        The optimal worst-case regret the method computed: Arveson's distance squared (structured)
        or the SDP's optimal value squared (equal to ``regret`` up to the method's tolerance).
    sdp_value : float
        The same number (its name from the SDP-only version).
    method, status, causality : str
        The method used, its status ("optimal" for the structured method) and the information pattern.

    Notes
    -----
    In :func:`orrc.simulate` it plays u_t = −K x_t + Σ_s Φ_{ts} w_s, with the past w_s recovered from
    the observed states and applied inputs (x_{s+1} − A x_s − B u_s) and, with full information, w_t
    read from the one-step preview. Another start than x_0 = 0 or a longer run is refused.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear, the cost not quadratic, T out of range, ``causality`` unknown,
        or the problem beyond the method's size limit.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable()
    >>> strict = orrc.RegretOptimal(ex.system, ex.cost, 8)
    >>> full = orrc.RegretOptimal(ex.system, ex.cost, 8, causality="full-information")
    >>> bool(full.regret < strict.regret)
    True
    """

    name = "regret-optimal"

    def __init__(self, system: LinearSystem, cost: QuadraticCost, T: int, method: str = "structured",
                 causality: str = "strict"):
        check_problem(system, cost, linear=True, quadratic=True, who="RegretOptimal",
                      why_linear=" (x⁺ = Ax + Bu + w)")
        self.T = as_int("T", T, minimum=2)
        if not isinstance(method, str) or method not in METHODS:
            raise OrrcValueError(f"method must be one of {', '.join(map(repr, METHODS))}; got {method!r}")
        if not isinstance(causality, str) or causality not in CAUSALITY:
            raise OrrcValueError(f"causality must be one of {', '.join(map(repr, CAUSALITY))}; got {causality!r}")
        n, m = system.n, system.m
        if method == "sdp":
            _check_sdp_size(self.T, n, m)
        else:
            _check_operator_size(self.T, n, m)
        self.system, self.cost, self.method, self.causality = system, cost, method, causality
        self.preview_w = 1 if causality == "full-information" else 0
        self.preview_c = 0
        if causality == "full-information":
            self.name = "regret-optimal, full information"
        from .baselines import LQR

        K_pre = LQR(system, cost).K   # pre-stabilisation: well-conditioned operators (any K gives the same optimum)
        self.condensed = c = condensed(system.A, system.B, cost.Q, cost.R, self.T, K=K_pre)
        if method == "sdp":
            self.Phi, self.value, self.status = _solve_sdp(c, self.T, m, n, causality)
        elif causality == "strict":
            self.Phi, self.value = regret_optimal_operator(c.S, c.Phi_star, self.T, m, n)
            self.status = "optimal"
        else:
            self.Phi, self.value = _full_information_operator(c.S, c.Phi_star, self.T, m, n)
            self.status = "optimal"
        self.sdp_value = self.value
        self.regret = float(np.linalg.norm(c.regret_operator(self.Phi), 2) ** 2)
        self.reset()

    def reset(self) -> None:
        self._w = np.zeros((self.T, self.system.n))
        self._x_prev = self._u_prev = None

    def control(self, obs: Observation) -> Decision:
        n, m = self.system.n, self.system.m
        t = obs.t
        if t >= self.T:
            raise OrrcValueError(f"RegretOptimal was designed for T = {self.T} steps; simulate asked for step t = {t}")
        if t == 0:
            self.reset()
            if np.any(obs.x != 0):
                raise OrrcValueError(f"RegretOptimal is designed from x_0 = 0 (the regret-optimal setting); got "
                                     f"x0 = {np.asarray(obs.x)}")
        else:
            self._w[t - 1] = obs.x - self.system.A @ self._x_prev - self.system.B @ self._u_prev
        seen = t
        if self.preview_w:   # full information: w_t, from the one-step preview
            self._w[t] = obs.w_preview[0]
            seen = t + 1
        u = -self.condensed.K @ obs.x + self.Phi[t * m:(t + 1) * m, :seen * n] @ self._w[:seen].reshape(-1)
        self._x_prev, self._u_prev = np.array(obs.x), u
        return Decision(u=u)

    def __repr__(self):
        return (f"RegretOptimal(T={self.T}, method={self.method!r}, causality={self.causality!r}, "
                f"regret={self.regret:.6g}, system={self.system!r})")
