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
  (bisection): the squared H∞ norm of the optimal (strictly causal) state-feedback closed loop
  from w to [Q^½x; R^½u], with an error bound.

Decisions follow the problem's conditioning, not fixed thresholds: a computed Riccati solution
counts only when an a-posteriori bound (``orrc.solvers._game_bounds``: the residual, ‖L⁻¹‖ of the
closed loop's Stein operator, ‖(R̃ + GᵀPG)⁻¹‖) proves that an exact stabilising solution with
γI − EᵀPE ≻ 0 lies nearby. So the level found by the bisection is feasible on every BLAS kernel,
and two kernels' levels differ by less than the error bound returned with it.

Solvers know nothing of time: matrices in, matrices out.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int, as_square, check_psd, check_size, eigvalsh_tol
from . import _game_bounds as bounds
from ._game_bounds import EPS
from .lq import riccati_steps_size

__all__ = ["GameSolution", "finite_horizon_game", "stationary_game", "optimal_game_level", "check_stabilisable"]


@dataclass
class GameSolution:
    """The saddle point of the linear-quadratic game at level ``gamma``.

    Attributes
    ----------
    gamma : the level (the paper's convention: the weight of ‖w‖², a squared gain).
    P : [P_0, ..., P_M] (finite horizon) or [P] (stationary); the value is x'P_0 x.
    K : the minimiser's gains, u_j = −K_j x_j ([K_0..K_{M-1}], or [K]).
    Kw : the maximiser's worst-case gains, w_j = Kw_j x_j ([Kw_0..Kw_{M-1}], or [Kw]).
    stationary : True for :func:`stationary_game`.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import game
    >>> level = game.optimal_game_level(A, B, Q, R)
    >>> solution = game.stationary_game(A, B, Q, R, 1.1 * level)
    >>> solution.stationary, len(solution.P), solution.K[0].shape
    (True, 1, (1, 2))
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
    # the checks themselves (eigenvalues of Q and R, the stabilisability test) are O(n³)
    check_size(f"a game of n={n} states (m={m})", nbytes=8.0 * 10 * (n + m) ** 2, ops=60.0 * (n + m) ** 3,
               hint="the game Riccati equations are O(n³) each")
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
    rank [A − λI, B] = n for every eigenvalue |λ| >= 1).

    Parameters
    ----------
    A, B : the system matrices.
    what : the pair's name in the message.

    Returns
    -------
    None
        when (A, B) is stabilisable.

    Raises
    ------
    orrc.OrrcValueError
        When a mode with |λ| >= 1 cannot be moved by the input.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc.solvers import game
    >>> try:
    ...     game.check_stabilisable(np.diag([2.0, 0.5]), np.array([[0.0], [1.0]]))
    ... except orrc.OrrcValueError as err:
    ...     print(str(err)[:30])
    (A, B) is not stabilisable: th
    """
    A = as_square("A", A)
    n = A.shape[0]
    B = as_array("B", B, (n, None))
    scale = max(1.0, float(np.abs(A).max()), float(np.abs(B).max()) if B.size else 0.0)
    for lam in np.linalg.eigvals(A):
        if abs(lam) >= 1.0 - 1e-12:
            s = np.linalg.svd(np.hstack([A - lam * np.eye(n), B]).astype(complex), compute_uv=False)
            if s[-1] <= 1e-10 * scale * n:
                raise OrrcValueError(
                    f"{what} is not stabilisable: the mode λ = {complex(lam):.6g} (|λ| = {abs(lam):.6g} >= 1) "
                    "cannot be moved by the input (PBH test: rank [A − λI, B] < n); no controller "
                    "keeps the closed loop bounded")


def _are_size(what: str, A, B, E, solves: int) -> None:
    """:func:`orrc._validate.check_size` for ``solves`` certified game AREs: each a (2n + m + q)-
    dimensional pencil (Schur or structured doubling, O(N³) with a few dozen N x N work arrays) and its certificate."""
    n, m, q = A.shape[0], B.shape[1], E.shape[1]
    N = 2 * n + m + q
    check_size(f"{what} on a game of n={n} states (m={m}, q={q})", nbytes=8.0 * 40 * N * N,
               ops=solves * 200.0 * N ** 3, hint="the game Riccati equations are O(n³) each")


# -- one stage of the recursion ----------------------------------------------------------------------
def _stage(A, B, E, Q, R, gamma, P):
    """(P_j, K_j, Kw_j) from P_{j+1} = P, or None when γI − EᵀPE is not positive definite."""
    m, q = B.shape[1], E.shape[1]
    EtPE = E.T @ P @ E
    lam = np.linalg.eigvalsh(0.5 * (EtPE + EtPE.T))
    # the margin γ − λ_max(EᵀPE) must exceed its rounding error: forming EᵀPE (inner dimension n)
    # and its eigenvalues (q·eps·‖EᵀPE‖), at most (n + q)·eps·‖E‖²‖P‖ (Frobenius norms bound the 2-norms)
    if gamma - lam[-1] <= (E.shape[0] + q) * EPS * float(np.sum(E * E)) * float(np.linalg.norm(P)):
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

    Parameters
    ----------
    A, B, Q, R : the linear-quadratic problem.
    gamma : the level γ.
    M : the horizon.
    Pf : (n, n) an optional terminal weight.
    E : (n, k) the disturbance's input matrix (default I).

    Returns
    -------
    GameSolution
        P_0..P_M and the players' gains K_j, Kw_j.

    Raises
    ------
    orrc.OrrcValueError
        When γ is at or below the smallest admissible level, or the matrices are malformed.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import game
    >>> level = game.optimal_game_level(A, B, Q, R)
    >>> solution = game.finite_horizon_game(A, B, Q, R, 1.1 * level, M=5)
    >>> len(solution.P), len(solution.K)
    (6, 5)
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    gamma = _gamma(gamma)
    M = as_int("M", M, minimum=1)
    n = A.shape[0]
    riccati_steps_size(f"the {M}-step game's backward recursion at M={M} (n={n}, m={B.shape[1]}, "
                       f"q={E.shape[1]})", M, n, B.shape[1] + E.shape[1])
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
    # the bisection: about log2(range/tol) <= 100 recursions of M steps
    riccati_steps_size(f"finite_game_level's bisection over the {M}-step game at M={M} (n={n}, m={B.shape[1]}, "
                       f"q={E.shape[1]})", 100 * M, n, B.shape[1] + E.shape[1])
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


def _stationary(A, B, E, Q, R, gamma, method="scipy") -> bounds.Certificate:
    """The stabilising solution at γ, computed and certified (:func:`orrc.solvers._game_bounds.certify`):
    ``verdict`` "feasible" (then ``P``, ``K``, ``Kw``), "infeasible" or "undecided", with a reason.

    ``method="scipy"``: ``scipy.linalg.solve_discrete_are`` (used by :func:`stationary_game`);
    ``"sda"``: the structured doubling algorithm (used for the many solves of the bisection in
    :func:`optimal_game_level`: numpy only, much faster on small problems). Both results pass
    the same certificate."""
    n, m = B.shape
    q = E.shape[1]
    G = np.hstack([B, E])
    Rt = np.zeros((m + q, m + q))
    Rt[:m, :m] = R
    Rt[m:, m:] = -gamma * np.eye(q)
    if method == "sda":
        P, converged = bounds.sda(A, G @ np.linalg.solve(Rt, G.T), Q)
        if P is None:
            return bounds.Certificate("undecided", "the doubling iteration for the game Riccati equation broke down")
        if not converged:
            cert = bounds.certify(A, B, E, Q, R, gamma, P)
            if cert.verdict == "undecided":
                cert.reason = f"the doubling iteration did not converge: {cert.reason}"
            return cert
    else:
        from scipy import linalg

        try:
            P = linalg.solve_discrete_are(A, G, Q, Rt)
        except (np.linalg.LinAlgError, ValueError) as exc:
            return bounds.Certificate("undecided", f"the game Riccati equation has no stabilising solution ({exc})")
    if not np.all(np.isfinite(P)):
        return bounds.Certificate("undecided", "the game Riccati equation has no finite solution")
    return bounds.certify(A, B, E, Q, R, gamma, P)


def stationary_game(A, B, Q, R, gamma, E=None) -> GameSolution:
    """The infinite-horizon game at level γ: the stabilising solution P of the game ARE

        P = Q + AᵀPA − AᵀPG (R̃ + GᵀPG)⁻¹ GᵀPA,   G = [B E], R̃ = diag(R, −γI)

    (``scipy.linalg.solve_discrete_are`` with the indefinite weight R̃; when its result is not
    certified, as happens just above the optimal level, the structured doubling algorithm), certified
    (:func:`orrc.solvers._game_bounds.certify`: from the residual and the conditioning, an exact
    stabilising solution lies within ``info["error"]`` of P, and it has P ⪰ 0, γI − EᵀPE ≻ 0, and
    both A − BK (the H∞ controller against w = 0) and A − BK + E Kw (against the worst case)
    stable). Then u = −Kx guarantees Σ(xᵀQx + uᵀRu) < γ Σ‖w‖² + x_0ᵀPx_0 for every w (Başar and
    Bernhard 1995, Theorem 3.7). Raises :class:`~orrc.OrrcValueError` below the optimal level
    (naming it) and for an unstabilisable (A, B).

    Parameters
    ----------
    A, B, Q, R : the linear-quadratic problem.
    gamma : the level γ, above :func:`optimal_game_level`.
    E : (n, k) the disturbance's input matrix (default I).

    Returns
    -------
    GameSolution
        the stabilising P, the gains K, Kw (``stationary`` True).

    Raises
    ------
    orrc.OrrcValueError
        When γ is at or below the optimal level, (A, B) is not stabilisable, or the solution cannot
        be certified.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import game
    >>> level = game.optimal_game_level(A, B, Q, R)
    >>> game.stationary_game(A, B, Q, R, 1.1 * level).K[0].round(4)
    array([[11.8338,  7.7309]])
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    gamma = _gamma(gamma)
    _are_size("stationary_game", A, B, E, solves=4)
    check_stabilisable(A, B)
    cert = _stationary(A, B, E, Q, R, gamma)
    if cert.verdict != "feasible":  # close to the optimal level scipy's Schur method loses accuracy first
        alt = _stationary(A, B, E, Q, R, gamma, method="sda")
        if alt.verdict == "feasible" or (alt.verdict == "infeasible" and cert.verdict == "undecided"):
            cert = alt
    if cert.verdict != "feasible":
        level, error = optimal_game_level(A, B, Q, R, E=E, with_error=True)
        if gamma <= level:
            raise OrrcValueError(
                f"gamma = {gamma:.9g} is not above the optimal level {level:.9g} (within {error:.2g}) of the "
                f"stationary game ({cert.reason}); no stabilising state-feedback controller (u_t from x_0..x_t) "
                f"attains a level below it: "
                f"use gamma > {level:.9g}")
        raise OrrcValueError(
            f"gamma = {gamma:.9g} is too close to the optimal level {level:.9g} of the stationary game for the "
            f"Riccati solution to be certified ({cert.reason}): use a gamma further above it, e.g. "
            f"{level * (1 + 1e-5):.9g}")
    return GameSolution(gamma, [cert.P], [cert.K], [cert.Kw], stationary=True,
                        info={"error": cert.error, "residual": cert.residual, "margin": cert.margin})


def optimal_game_level(A, B, Q, R, tol: float = 1e-9, E=None, with_error: bool = False):
    """The smallest γ for which :func:`stationary_game` has a solution, by bisection to relative ``tol``.

    It equals the squared H∞ norm of the optimal state-feedback closed loop from w to
    [Q^½x; R^½u]: the best level among the strictly causal controllers that measure the state,
    u_t a function of x_0..x_t (and of the past inputs), never of w_t; among those a static state
    feedback u = −Kx is optimal (Başar and Bernhard 1995, Theorem 3.7). It is not the
    full-information level: in discrete time a controller that also sees w_t when it chooses u_t
    can do better (with preview, :class:`orrc.HInfinity` plays this game on the state augmented
    with the previewed w's). Each step of the bisection solves the game ARE by structured doubling
    (numpy) and decides with the certificate of :func:`stationary_game`, so the returned level γ̂
    is certified feasible: γ* <= γ̂, whatever BLAS kernel ran.

    The error bound (``with_error=True`` returns ``(level, error)``): γ̂ − error <= γ* <= γ̂, the lower
    end being the larger of the non-causal level max_ω λ(ω) (a lower bound, equal to γ* when the
    optimal level is set by the closed loop reaching the unit circle) less its rounding error, and
    the highest level of the bisection whose infeasibility was certified (when it is set by
    γI − EᵀPE becoming singular). It is about tol·γ̂ plus the band above γ* in which double
    precision cannot certify the Riccati solution (the closed loop's distance to the unit circle,
    or γI − EᵀPE, too small for the residual): ~1e-10 relative on the suite's problems.

    The bisection starts from the non-causal level and λ_max(EᵀP_LQR E) (P_game ⪰ P_LQR and γ must
    exceed λ_max(EᵀP_game E)); the upper end is found by doubling.

    Parameters
    ----------
    A, B, Q, R : the linear-quadratic problem.
    tol : the bisection's relative tolerance.
    E : (n, k) the disturbance's input matrix (default I).
    with_error : also return the level's error bound.

    Returns
    -------
    float or tuple
        γ* (certified feasible), or (γ*, error bound) with ``with_error``.

    Raises
    ------
    orrc.OrrcValueError
        When (A, B) is not stabilisable or the matrices are malformed.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import game
    >>> level = game.optimal_game_level(A, B, Q, R)
    >>> print(round(level, 3))
    48.881
    """
    A, B, Q, R, E = _problem(A, B, Q, R, E)
    tol = as_float("tol", tol, minimum=0.0, strict_min=True)
    if not isinstance(with_error, (bool, np.bool_)):
        raise OrrcValueError(f"with_error must be True or False; got {with_error!r}")
    _are_size("optimal_game_level's bisection", A, B, E, solves=100)
    check_stabilisable(A, B)
    nc, nc_error = bounds.noncausal_level(A, B, E, Q, R)
    lower = max(0.0, nc - nc_error)
    P_lqr, _ = bounds.sda(A, B @ np.linalg.solve(R, B.T), Q)
    lo = lower if P_lqr is None else max(lower, float(np.linalg.eigvalsh(E.T @ P_lqr @ E)[-1]) - eigvalsh_tol(P_lqr))
    refuted = []

    def feasible(g):
        cert = _stationary(A, B, E, Q, R, g, method="sda")
        if cert.verdict == "infeasible":
            refuted.append(g)
        return cert.verdict == "feasible"

    hi = _upper(feasible, 2.0 * lo if lo > 0 else 1.0)
    level = _bisect(feasible, lo, hi, tol)
    if not with_error:
        return level
    return level, level - max([lower, *refuted])
