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

The controller is *strictly causal*: u_t depends on x_0..x_t (equivalently w_0..w_{t-1}), never on
w_t, as in the regret-optimal papers' causal class.
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

__all__ = ["RegretOptimal", "MAX_LMI_DIM", "METHODS"]

MAX_LMI_DIM = 64  # T (m + n): the size of the SDP's matrix inequality (a few seconds with Clarabel at the limit)
#: the values of ``RegretOptimal(method=...)``
METHODS = ("structured", "sdp")
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


def _solve_sdp(c, T: int, m: int, n: int):
    """(Φ, optimal value squared, status) of the regret-optimal SDP: minimise ‖S^½(Φ − Φ*)‖₂ over strictly
    block-lower-triangular Φ, with cvxpy and Clarabel (the cross-check of the structured method)."""
    import cvxpy as cp

    mask = np.kron(np.tril(np.ones((T, T)), k=-1), np.ones((m, n)))   # strictly causal
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
    """The causal controller with the smallest worst-case dynamic regret over a horizon of T steps.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : a :class:`~orrc.QuadraticCost`.
    T : the horizon.
    method : "structured" (default; Arveson's distance formula and Parrott's completion on a causal
        factor of S, :mod:`orrc.solvers.regret`; refused with the estimate beyond the package's size
        limits, ``orrc.config``) or "sdp" (the semidefinite program with Clarabel, the cross-check;
        T(m + n) <= :data:`MAX_LMI_DIM`, else a clear error with the limit).

    Attributes
    ----------
    Phi : (Tm, Tn) the optimal disturbance-feedback operator, v = Φ w with u_t = −K x_t + v_t (block (t, s)
        nonzero only for s < t; K = ``condensed.K``, the LQR gain).
    regret : its worst-case dynamic regret over ‖w‖ <= 1, ‖S^½(Φ − Φ*)‖₂² (computed from Φ with numpy).
    value : the optimal worst-case regret the method computed: Arveson's distance squared (structured)
        or the SDP's optimal value squared (equal to ``regret`` up to the method's tolerance).
    sdp_value : the same number (its name from the SDP-only version).
    method, status : the method used and its status ("optimal" for the structured method).

    As a controller (in :func:`orrc.simulate`) it plays u_t = −K x_t + Σ_{s<t} Φ_{ts} w_s with w_s recovered from
    the observed states and applied inputs (x_{s+1} − A x_s − B u_s). It is designed from x_0 = 0 (the
    setting of the regret-optimal papers) and for t < T: another start or a longer run is refused.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear, the cost not quadratic, T out of range, or the problem beyond
        the method's size limit.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> ro = orrc.RegretOptimal(di.system, di.cost, T=20)
    >>> ro.Phi.shape
    (20, 40)
    >>> traj = orrc.simulate(di.system, ro, np.zeros(2), w, T=20)
    >>> print(f"{traj.costs.sum():.4f}")
    0.7876
    """

    name = "regret-optimal"

    def __init__(self, system: LinearSystem, cost: QuadraticCost, T: int, method: str = "structured"):
        check_problem(system, cost, linear=True, quadratic=True, who="RegretOptimal",
                      why_linear=" (x⁺ = Ax + Bu + w)")
        self.T = as_int("T", T, minimum=2)
        if not isinstance(method, str) or method not in METHODS:
            raise OrrcValueError(f"method must be one of {', '.join(map(repr, METHODS))}; got {method!r}")
        n, m = system.n, system.m
        if method == "sdp":
            _check_sdp_size(self.T, n, m)
        else:
            _check_operator_size(self.T, n, m)
        self.system, self.cost, self.method = system, cost, method
        self.preview_w = self.preview_c = 0
        from .baselines import LQR

        K_pre = LQR(system, cost).K   # pre-stabilisation: well-conditioned operators (any K gives the same optimum)
        self.condensed = c = condensed(system.A, system.B, cost.Q, cost.R, self.T, K=K_pre)
        if method == "structured":
            self.Phi, self.value = regret_optimal_operator(c.S, c.Phi_star, self.T, m, n)
            self.status = "optimal"
        else:
            self.Phi, self.value, self.status = _solve_sdp(c, self.T, m, n)
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
        u = -self.condensed.K @ obs.x + self.Phi[t * m:(t + 1) * m, :t * n] @ self._w[:t].reshape(-1)
        self._x_prev, self._u_prev = np.array(obs.x), u
        return Decision(u=u)

    def __repr__(self):
        return f"RegretOptimal(T={self.T}, method={self.method!r}, regret={self.regret:.6g}, system={self.system!r})"
