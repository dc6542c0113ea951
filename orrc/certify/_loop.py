"""A linear closed loop as the certificates see it: the controller's law read off, and the loop's
responses to a disturbance sequence as matrices.

* :func:`_linear_loop` -- the law u_t = −K x_t − Σ_{i<Mw} L_i w_{t+i} + Σ_{i=1..Hp} Lp_i w_{t−i} (or the
  finite-horizon v = Φ w) of a supported linear controller: Algorithm 1 on the LQ path with any
  preview, HInfinity (with preview), LQR, zero input, a frozen GPC, RegretOptimal;
* :func:`_operators` -- the stacked states and inputs over T steps from x_0 = 0 as linear maps of
  W = (w_0, ..., w_{T-1});
* :func:`_top_singular` -- the top singular pair of such a map (the worst disturbance).

:mod:`orrc.certify.attenuation` and :mod:`orrc.certify.regret` build on them.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import OrrcValueError
from ..controllers.base import Controller
from ..controllers.baselines import LQR, ZeroInput
from ..controllers.gpc import GPC, DisturbanceAction
from ..controllers.hinf import HInfinity
from ..controllers.preview import PreviewRHC
from ..controllers.regret_optimal import RegretOptimal
from ..systems import LinearSystem
from .constants import _check_linear_system, _check_quadratic_cost


@dataclass
class _Loop:
    """A linear controller as the certify functions see it:

    u_t = −K x_t − Σ_{i<Mw} L_i w_{t+i} + Σ_{i=1..Hp} Lp_i w_{t−i}   (time-invariant), or
    u_t = −K x_t + v_t with v = Phi w over a finite horizon (``Phi`` (T_max m, T_max n), causal).
    """

    K: np.ndarray
    L: np.ndarray
    Mw: int
    Lp: np.ndarray
    Hp: int
    Q: np.ndarray
    R: np.ndarray
    Phi: np.ndarray | None = None
    T_max: int | None = None


def _linear_loop(system, controller, cost, who: str = "worst_case_attenuation") -> _Loop:
    """The linear description of the supported controllers (PreviewRHC on the LQ path, any preview_w;
    HInfinity, with preview; LQR; ZeroInput; DisturbanceAction, a GPC frozen at M; RegretOptimal)."""
    _check_linear_system(system)
    if not isinstance(controller, Controller):
        raise OrrcValueError(f"controller must be an orrc Controller; got {type(controller).__name__}")
    n, m = system.n, system.m
    none = np.zeros((m, 0))
    Lp, Hp, Phi, T_max = none, 0, None, None
    own = getattr(controller, "system", None)
    if isinstance(own, LinearSystem) and own is not system and not (
            np.array_equal(own.A, system.A) and np.array_equal(own.B, system.B)):
        raise OrrcValueError(f"the {type(controller).__name__} controller was built for a different (A, B) than `system`")
    if isinstance(controller, PreviewRHC):
        if controller.solver != "lq":  # PreviewRHC.law is None exactly off the LQ path
            raise OrrcValueError(
                f"{who} needs a linear controller: PreviewRHC on the exact LQ path "
                f"(LinearSystem, QuadraticCost, no bounds); this one uses solver={controller.solver!r}")
        Mw = controller.preview_w  # the unseen disturbances' feed-forward columns drop out (exact)
        K, L = controller.law.K, controller.law.L[:, :Mw * n]
    elif isinstance(controller, HInfinity):
        K, L, Mw = controller.K, controller.L, controller.preview
    elif isinstance(controller, LQR):
        K, L, Mw = controller.K, none, 0
    elif isinstance(controller, ZeroInput):
        K, L, Mw = np.zeros((m, n)), none, 0
    elif isinstance(controller, GPC):
        raise OrrcValueError(
            f"{who} needs a linear controller; GPC changes its policy M at every step: freeze it first "
            "(gpc.frozen(), the policy it ended with, or DisturbanceAction(system, cost, M))")
    elif isinstance(controller, DisturbanceAction):
        K, L, Mw = controller.K, none, 0
        Hp = controller.H
        Lp = np.hstack(list(controller.M))            # [M_1 ... M_H], (m, H n)
    elif isinstance(controller, RegretOptimal):
        K, L, Mw = controller.condensed.K, none, 0
        Phi, T_max = controller.Phi, controller.T
    else:
        raise OrrcValueError(
            f"{who} supports PreviewRHC (LQ path), HInfinity, LQR, ZeroInput, DisturbanceAction (a frozen "
            f"GPC) and RegretOptimal; got {type(controller).__name__}")
    if K.shape != (m, n):
        raise OrrcValueError(f"the controller's gain has shape {K.shape}; the system needs ({m}, {n})")
    cost = controller.cost if cost is None else cost
    _check_quadratic_cost(system, cost, f"{who} needs the problem's QuadraticCost: pass "
                                        f"cost=... (the controller has {type(cost).__name__})")
    return _Loop(np.asarray(K, float), np.asarray(L, float), Mw, np.asarray(Lp, float), Hp, cost.Q, cost.R,
                 Phi, T_max)


def _operators(system, loop: _Loop, T: int) -> tuple[np.ndarray, np.ndarray]:
    """(X (T n, T n), U (T m, T n)): x_t and u_t for t < T as linear maps of W = (w_0..w_{T-1}), from
    x_0 = 0 (the preview past T sees zeros, the :func:`orrc.simulate` convention)."""
    A, B = system.A, system.B
    n, m = system.n, system.m
    if loop.Phi is not None and T > loop.T_max:
        raise OrrcValueError(f"T = {T} is beyond the horizon T = {loop.T_max} the RegretOptimal controller was "
                             "designed for")
    N = T * n
    X = np.zeros((n, N))  # x_t = X vec W
    Xs, Us = [], []
    for t in range(T):
        U = -loop.K @ X
        for i in range(loop.Mw):
            k = t + i
            if k < T:
                U[:, k * n:(k + 1) * n] -= loop.L[:, i * n:(i + 1) * n]
        for i in range(1, loop.Hp + 1):
            k = t - i
            if k >= 0:
                U[:, k * n:(k + 1) * n] += loop.Lp[:, (i - 1) * n:i * n]
        if loop.Phi is not None:
            U[:, :(t + 1) * n] += loop.Phi[t * m:(t + 1) * m, :(t + 1) * n]   # with full information, w_t too
        Xs.append(X)
        Us.append(U)
        X = A @ X + B @ U
        X[:, t * n:(t + 1) * n] += np.eye(n)
    return np.vstack(Xs), np.vstack(Us)


def _top_singular(G: np.ndarray) -> tuple[float, np.ndarray]:
    """(σ_max(G)², top right singular vector): dense SVD for small G, else ARPACK (``svds``,
    tol=0, i.e. to machine precision; deterministic start vector), dense if it fails."""
    if min(G.shape) > 200:
        from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, svds

        v0 = np.random.default_rng(0).standard_normal(G.shape[1])
        try:
            _, s, Vt = svds(G, k=1, tol=0, v0=v0, solver="arpack", maxiter=20 * G.shape[1])
            return float(s[0] ** 2), Vt[0]
        except (ArpackNoConvergence, ArpackError):
            pass
    from scipy import linalg

    _, s, Vt = linalg.svd(G, full_matrices=False)
    return float(s[0] ** 2), Vt[0]
