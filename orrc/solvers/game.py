"""The linear-quadratic game Riccati equations (the soft-constrained dynamic game behind H∞ control).

Problem: x_{j+1} = A x_j + B u_j + E w_j (E = I unless given), stage payoff

    x_jᵀQx_j + u_jᵀRu_j − γ ‖w_j‖²,

u minimises, w maximises, feedback (closed-loop, perfect state information) saddle point
(Başar and Bernhard, *H∞-Optimal Control and Related Minimax Design Problems*, 2nd ed. 1995,
Ch. 3). Convention: the paper's, γ multiplies the *squared* disturbance norm
(Σ c <= γ Σ ‖w‖², so γ is the squared gain); a caller who thinks in γ² (H∞ texts) converts.

With G = [B E] and R̃ = diag(R, −γI), the value-to-go is xᵀP_jx with

    P_j = Q + AᵀP_{j+1}A − AᵀP_{j+1}G (R̃ + GᵀP_{j+1}G)⁻¹ GᵀP_{j+1}A,

and the saddle-point policies [u_j; w_j] = −(R̃ + GᵀP_{j+1}G)⁻¹GᵀP_{j+1}A x_j, i.e.
u_j = −K_j x_j and w_j = Kw_j x_j. The maximiser's stage problem is concave iff
γI − EᵀP_{j+1}E ≻ 0 (then the minimiser's is convex, since R ≻ 0): that is the existence
condition of the saddle point at every stage.

* :func:`finite_horizon_game` -- the M-step game by the backward recursion;
* :func:`stationary_game` -- the infinite-horizon game: the stabilising solution of the game
  algebraic Riccati equation (``scipy.linalg.solve_discrete_are`` with the indefinite weight
  diag(R, −γI));
* :func:`optimal_game_level` -- the smallest γ at which :func:`stationary_game` has a solution
  (bisection): the squared H∞ norm of the optimal state-feedback closed loop from w to
  [Q^½x; R^½u].

Solvers know nothing of time: matrices in, matrices out.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int, as_square, check_psd

__all__ = ["GameSolution", "finite_horizon_game", "stationary_game", "optimal_game_level", "check_stabilisable"]


@dataclass
class GameSolution:
    """The saddle point of the linear-quadratic game at level ``gamma``.

    gamma : the level (the paper's convention: the weight of ‖w‖², a squared gain).
    P : [P_0, ..., P_M] (finite horizon) or [P] (stationary); the value is x'P_0 x.
    K : the minimiser's gains, u_j = −K_j x_j ([K_0..K_{M-1}], or [K]).
    Kw : the maximiser's worst-case gains, w_j = Kw_j x_j ([Kw_0..Kw_{M-1}], or [Kw]).
    stationary : True for :func:`stationary_game`.
    """

    gamma: float
    P: list
    K: list
    Kw: list
    stationary: bool = False
    info: dict = field(default_factory=dict, repr=False)

    def value(self, x) -> float:
        """The game's value from x: xᵀP_0x."""
        P0 = self.P[0]
        x = as_array("x", x, (P0.shape[0],))
        return float(x @ P0 @ x)


# -- validation ---------------------------------------------------------------------------------------
def _problem(A, B, Q, R, E):
    A = as_square("A", A)
    n = A.shape[0]
    B = as_array("B", B)
    if B.ndim == 1:
        B = B.reshape(-1, 1)
    if B.ndim != 2 or B.shape[0] != n:
        raise OrrcValueError(f"B must have shape ({n}, m) to match A of shape {A.shape}; got shape {B.shape}")
    m = B.shape[1]
    Q = as_square("Q", Q, n)
    R = as_square("R", R, m)
    check_psd("Q", Q)
    check_psd("R", R, strict=True)
    if E is None:
        E = np.eye(n)
    else:
        E = as_array("E", E)
        if E.ndim == 1:
            E = E.reshape(-1, 1)
        if E.ndim != 2 or E.shape[0] != n:
            raise OrrcValueError(f"E must have shape ({n}, q) to match A of shape {A.shape}; got shape {E.shape}")
    return A, B, 0.5 * (Q + Q.T), 0.5 * (R + R.T), E


def _gamma(gamma) -> float:
    return as_float("gamma", gamma, minimum=0.0, strict_min=True)


def check_stabilisable(A, B, what: str = "(A, B)") -> None:
    """Raise :class:`~orrc.OrrcValueError` unless (A, B) is stabilisable (discrete time, PBH test:
    rank [A − λI, B] = n for every eigenvalue |λ| >= 1)."""
    A, B = np.asarray(A, float), np.asarray(B, float)
    n = A.shape[0]
    scale = max(1.0, float(np.abs(A).max()), float(np.abs(B).max()) if B.size else 0.0)
    for lam in np.linalg.eigvals(A):
        if abs(lam) >= 1.0 - 1e-12:
            s = np.linalg.svd(np.hstack([A - lam * np.eye(n), B]).astype(complex), compute_uv=False)
            if s[-1] <= 1e-10 * scale * n:
                raise OrrcValueError(
                    f"{what} is not stabilisable: the mode λ = {complex(lam):.6g} (|λ| = {abs(lam):.6g} >= 1) "
                    "cannot be moved by the input (PBH test: rank [A − λI, B] < n); no controller "
                    "keeps the closed loop bounded")


# -- one stage of the recursion ----------------------------------------------------------------------
def _stage(A, B, E, Q, R, gamma, P):
    """(P_j, K_j, Kw_j) from P_{j+1} = P, or None when γI − EᵀPE is not positive definite."""
    m, q = B.shape[1], E.shape[1]
    EtPE = E.T @ P @ E
    lam = np.linalg.eigvalsh(0.5 * (EtPE + EtPE.T))
    if gamma - lam[-1] <= 1e-12 * max(1.0, abs(gamma)):
        return None
    G = np.hstack([B, E])
    S = G.T @ P @ G
    S[:m, :m] += R
    S[m:, m:] -= gamma * np.eye(q)
    F = np.linalg.solve(S, G.T @ P @ A)
    Pj = Q + A.T @ P @ A - (A.T @ P @ G) @ F
    return 0.5 * (Pj + Pj.T), F[:m], -F[m:]


def _finite(A, B, E, Q, R, gamma, M, Pf):
    n = A.shape[0]
    P = [None] * (M + 1)
    K, Kw = [None] * M, [None] * M
    P[M] = np.zeros((n, n)) if Pf is None else Pf
    for j in range(M - 1, -1, -1):
        out = _stage(A, B, E, Q, R, gamma, P[j + 1])
        if out is None:
            return None, j
        P[j], K[j], Kw[j] = out
    return (P, K, Kw), None


def _bisect(feasible, lo: float, hi: float, tol: float) -> float:
    """The boundary of a monotone feasibility (infeasible at lo, feasible at hi): returns a
    feasible level within tol·hi of the boundary."""
    while hi - lo > tol * hi:
        mid = math.sqrt(lo * hi) if lo > 0 and hi / lo > 4 else 0.5 * (lo + hi)
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _upper(feasible, start: float) -> float:
    hi = max(start, 1e-12)
    for _ in range(200):
        if feasible(hi):
            return hi
        hi *= 2.0
    raise OrrcValueError("no finite game level found up to 2^200 times the LQ bound (the problem is degenerate)")


def finite_horizon_game(A, B, Q, R, gamma, M, Pf=None, E=None) -> GameSolution:
    """The M-step game, no terminal cost unless ``Pf`` (P_M = Pf or 0).

    Backward recursion P_j = Q + AᵀP_{j+1}A − AᵀP_{j+1}G (R̃ + GᵀP_{j+1}G)⁻¹ GᵀP_{j+1}A with
    G = [B E], R̃ = diag(R, −γI) (Başar and Bernhard 1995, Theorem 3.2). It needs
    γI − EᵀP_{j+1}E ≻ 0 at every j (the maximiser's problem concave): otherwise raises
    :class:`~orrc.OrrcValueError` naming gamma and the smallest admissible level (found by
    bisection: the recursion is monotone in γ). ``E`` (n, q): how w enters (default I).
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    gamma = _gamma(gamma)
    M = as_int("M", M, minimum=1)
    n = A.shape[0]
    if Pf is not None:
        Pf = as_square("Pf", Pf, n)
        check_psd("Pf", Pf)
    sol, j = _finite(A, B, E, Q, R, gamma, M, Pf)
    if sol is None:
        level = finite_game_level(A, B, Q, R, M, Pf=Pf, E=E)
        raise OrrcValueError(
            f"gamma = {gamma:.6g} is below the smallest admissible level {level:.6g} of this {M}-step game: "
            f"γI − EᵀP_{j + 1}E is not positive definite at stage j = {j} (the disturbance's problem is not "
            f"concave, its value is infinite); use gamma > {level:.6g}")
    P, K, Kw = sol
    return GameSolution(gamma, P, K, Kw, stationary=False)


def finite_game_level(A, B, Q, R, M, Pf=None, E=None, tol: float = 1e-9) -> float:
    """The infimum of the γ at which :func:`finite_horizon_game` has a saddle point (bisection).

    The lower end is λ_max(EᵀP_jE) over the LQ recursion (γ = ∞), which every admissible γ exceeds.
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    M = as_int("M", M, minimum=1)
    tol = as_float("tol", tol, minimum=0.0, strict_min=True)
    n = A.shape[0]
    Pf = None if Pf is None else as_square("Pf", Pf, n)

    def feasible(g):
        return _finite(A, B, E, Q, R, g, M, Pf)[0] is not None

    # the LQ recursion (w = 0) gives a lower bound: P_j(γ) ⪰ P_j(∞)
    P = np.zeros((n, n)) if Pf is None else Pf
    lo = float(np.linalg.eigvalsh(E.T @ P @ E)[-1])
    for _ in range(M - 1):
        BtP = B.T @ P
        P = Q + A.T @ P @ A - A.T @ P @ B @ np.linalg.solve(R + BtP @ B, BtP @ A)
        lo = max(lo, float(np.linalg.eigvalsh(E.T @ P @ E)[-1]))
    hi = _upper(feasible, 2.0 * lo if lo > 0 else 1.0)
    return _bisect(feasible, lo, hi, tol)


def _sda(A, G, H, maxiter: int = 80):
    """The stabilising solution of X = AᵀX(I + GX)⁻¹A + H by the structured doubling algorithm
    (Chu, Fan, Lin and Wang 2004; quadratic convergence, numpy only), or None when it does not
    converge. G = [B E] R̃⁻¹ [B E]ᵀ is indefinite for the game; the checks of :func:`_stationary`
    decide whether the result is the game's solution."""
    n = A.shape[0]
    I = np.eye(n)
    Ak, Gk, Hk = A.copy(), G.copy(), H.copy()
    with np.errstate(all="ignore"):
        for _ in range(maxiter):
            try:
                W = I + Gk @ Hk
                V1 = np.linalg.solve(W, Ak)
                V2 = np.linalg.solve(W, Gk)
            except np.linalg.LinAlgError:
                return None
            H_new = Hk + Ak.T @ Hk @ V1
            Gk = Gk + Ak @ V2 @ Ak.T
            Ak = Ak @ V1
            if not np.all(np.isfinite(H_new)):
                return None
            done = np.abs(H_new - Hk).max() <= 1e-14 * max(1.0, np.abs(H_new).max())
            Hk = 0.5 * (H_new + H_new.T)
            if done:
                return Hk
    return None


def _stationary(A, B, E, Q, R, gamma, method="scipy"):
    """(P, K, Kw) of the stabilising solution at γ, or a string saying why there is none.

    ``method="scipy"``: ``scipy.linalg.solve_discrete_are`` (used by :func:`stationary_game`);
    ``"sda"``: the structured doubling algorithm (used for the many solves of the bisection in
    :func:`optimal_game_level`: numpy only, much faster on small problems). Both results pass
    the same checks."""
    n, m = B.shape
    q = E.shape[1]
    G = np.hstack([B, E])
    Rt = np.zeros((m + q, m + q))
    Rt[:m, :m] = R
    Rt[m:, m:] = -gamma * np.eye(q)
    if method == "sda":
        P = _sda(A, G @ np.linalg.solve(Rt, G.T), Q)
        if P is None:
            return "the doubling iteration for the game Riccati equation did not converge"
    else:
        from scipy import linalg

        try:
            P = linalg.solve_discrete_are(A, G, Q, Rt)
        except (np.linalg.LinAlgError, ValueError) as exc:
            return f"the game Riccati equation has no stabilising solution ({exc})"
    if not np.all(np.isfinite(P)):
        return "the game Riccati equation has no finite solution"
    P = 0.5 * (P + P.T)
    scale = max(1.0, float(np.abs(P).max()))
    if np.linalg.eigvalsh(P)[0] < -1e-9 * scale:
        return "the Riccati solution is not positive semidefinite"
    EtPE = E.T @ P @ E
    if gamma - np.linalg.eigvalsh(0.5 * (EtPE + EtPE.T))[-1] <= 1e-10 * max(1.0, gamma):
        return "γI − EᵀPE is not positive definite"
    S = Rt + G.T @ P @ G
    F = np.linalg.solve(S, G.T @ P @ A)
    K, Kw = F[:m], -F[m:]
    rho_game = float(np.max(np.abs(np.linalg.eigvals(A - B @ K + E @ Kw))))
    rho = float(np.max(np.abs(np.linalg.eigvals(A - B @ K))))
    if rho_game >= 1.0 - 1e-10 or rho >= 1.0 - 1e-10:
        return f"the closed loop is not stable (spectral radius {max(rho, rho_game):.6g})"
    residual = Q + A.T @ P @ A - (A.T @ P @ G) @ F - P
    if np.abs(residual).max() > 1e-6 * scale:
        return f"the Riccati solution is inaccurate (residual {np.abs(residual).max():.3g})"
    return P, K, Kw


def stationary_game(A, B, Q, R, gamma, E=None) -> GameSolution:
    """The infinite-horizon game at level γ: the stabilising solution P of the game ARE

        P = Q + AᵀPA − AᵀPG (R̃ + GᵀPG)⁻¹ GᵀPA,   G = [B E], R̃ = diag(R, −γI)

    (``scipy.linalg.solve_discrete_are`` with the indefinite weight R̃; when its result fails the
    checks, as it can just above the optimal level, the structured doubling algorithm), checked: P ⪰ 0,
    γI − EᵀPE ≻ 0, and both A − BK (the H∞ controller against w = 0) and A − BK + E Kw (against
    the worst case) stable. Then u = −Kx guarantees Σ(xᵀQx + uᵀRu) < γ Σ‖w‖² + x_0ᵀPx_0 for every
    w (Başar and Bernhard 1995, Theorem 3.7). Raises :class:`~orrc.OrrcValueError` below the
    optimal level (naming it) and for an unstabilisable (A, B).
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    gamma = _gamma(gamma)
    check_stabilisable(A, B)
    out = _stationary(A, B, E, Q, R, gamma)
    if isinstance(out, str):  # close to the optimal level scipy's Schur method loses accuracy first
        alt = _stationary(A, B, E, Q, R, gamma, method="sda")
        out = out if isinstance(alt, str) else alt
    if isinstance(out, str):
        level = optimal_game_level(A, B, Q, R, E=E)
        raise OrrcValueError(
            f"gamma = {gamma:.6g} is not above the optimal level {level:.6g} of the stationary game ({out}); "
            f"no stabilising controller attains a level below it: use gamma > {level:.6g}")
    P, K, Kw = out
    return GameSolution(gamma, [P], [K], [Kw], stationary=True)


def optimal_game_level(A, B, Q, R, tol: float = 1e-9, E=None) -> float:
    """The smallest γ for which :func:`stationary_game` has a solution, by bisection to relative ``tol``
    (the returned level is feasible, within tol of the infimum).

    It equals the squared H∞ norm of the optimal state-feedback closed loop from w to
    [Q^½x; R^½u] (full-information H∞ control: a static state feedback is optimal among all
    causal controllers). Each step of the bisection solves the game ARE by structured doubling
    (numpy; the same checks as :func:`stationary_game`). The lower end of the bisection is λ_max(EᵀP_LQR E) (P_game ⪰ P_LQR and
    γ must exceed λ_max(EᵀP_game E)); the upper end is found by doubling.
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    tol = as_float("tol", tol, minimum=0.0, strict_min=True)
    check_stabilisable(A, B)
    P_lqr = _sda(A, B @ np.linalg.solve(R, B.T), Q)
    lo = 0.0 if P_lqr is None else max(0.0, float(np.linalg.eigvalsh(E.T @ P_lqr @ E)[-1]))

    def feasible(g):
        return not isinstance(_stationary(A, B, E, Q, R, g, method="sda"), str)

    hi = _upper(feasible, 2.0 * lo if lo > 0 else 1.0)
    return _bisect(feasible, lo, hi, tol)
