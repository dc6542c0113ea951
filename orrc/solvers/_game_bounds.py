"""What a computation proves about the stationary game's level (the helpers of :mod:`orrc.solvers.game`):
a computed solution of the game's algebraic Riccati equation, and how far it can be trusted (an
upper bound on the optimal level γ*), and the non-causal level (a lower bound).

The equation (the game's, :mod:`orrc.solvers.game`; with R̃ ≻ 0 it is the LQ one):

    F(P) = Q + AᵀPA − AᵀPG (R̃ + GᵀPG)⁻¹ GᵀPA − P = 0,   S = R̃ + GᵀPG,   A_c = A − G S⁻¹GᵀPA.

* :func:`sda` -- the structured doubling algorithm (a solver, numpy only);
* :func:`stein_bound` -- Y = Σ_j (A_cᵀ)^j A_c^j, the solution of Y − A_cᵀYA_c = I: a Lyapunov
  certificate that A_c is stable, and ‖Y‖₂ = ‖L⁻¹‖ for the Stein operator L(Δ) = A_cᵀΔA_c − Δ
  (the derivative of F) on symmetric matrices in the spectral norm (L⁻¹ is a positive map and
  −‖X‖I ⪯ X ⪯ ‖X‖I);
* :func:`certify` -- from a computed P̂, the radius ε of a ball around P̂ that holds an exact
  stabilising solution P, and what that proves about γI − EᵀPE, P ⪰ 0 and the closed loops;
* :func:`noncausal_level` -- max_ω of the level of the best non-causal controller at frequency ω,
  a lower bound on γ* (from the inertia of the game's Popov function), with its rounding error.

The certificate (an a-posteriori bound, Newton-Kantorovich style). From the definitions,
F(P̂ + Δ) = F(P̂) + L(Δ) − A_cᵀX(Δ)A_c with X(Δ) = ΔG (S + GᵀΔG)⁻¹ GᵀΔ (S and A_c at P̂), so an
exact solution P̂ + Δ is a fixed point of Δ ↦ L⁻¹(A_cᵀX(Δ)A_c − F(P̂)). Let β = ‖Y‖₂, r a bound on
‖F(P̂)‖₂ (:func:`_residual`), σ = ‖S⁻¹‖₂, g = ‖G‖₂, a = ‖A_c‖₂, ε = 2βr and j = 2σg²ε. On the ball
‖Δ‖₂ <= ε with g²σε <= 1/2: ‖(S + GᵀΔG)⁻¹‖ <= 2σ, so ‖X(Δ)‖ <= jε, and
‖L⁻¹(A_cᵀXA_c)‖ = ‖Σ_{i>=1}(A_cᵀ)^iXA_c^i‖ <= (β − 1)‖X‖; the map sends the ball into itself
when (β − 1)j <= 1/2 (then βr + (β − 1)jε <= ε), and by Brouwer's fixed-point theorem an exact
solution P lies within ε of P̂. Its closed loop is exactly (I − J)A_c, J = G(S + GᵀΔG)⁻¹GᵀΔ,
‖J‖ <= j, and ((I − J)A_c)ᵀY(I − J)A_c − Y = −I + A_cᵀMA_c with ‖M‖ <= β(2j + j²) and
A_cᵀA_c ⪯ min(a², β − 1)I (A_cᵀA_c ⪯ A_cᵀYA_c = Y − I): the Lyapunov inequality proves it stable
when β(2j + j²)·min(a², β − 1) < 1, and P is then *the* stabilising solution (it is unique).
Everything is computed from P̂; the thresholds follow from the residual and the conditioning
(β, σ), not from fixed constants, so the same decision is reached whatever BLAS kernel computed
P̂. (Bounds to first order in the rounding of β, σ, g, a themselves, which the factor 2 in ε covers.)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import eigvalsh_tol

EPS = float(np.finfo(float).eps)


def _norm2(X) -> float:
    return float(np.linalg.norm(X, 2))


def _residual(A, G, Q, Rt, P, S, F) -> float:
    """A bound on ‖F(P̂)‖₂, the residual of the computed P̂, whatever the rounding of its evaluation.

    It is evaluated in the closed-loop form F_K(P̂) = Q + (A − GK)ᵀP̂(A − GK) + KᵀR̃K − P̂ at the
    computed gain K (the identity F_K(P) = F(P) + (K − K*)ᵀS(K − K*), K* = S⁻¹GᵀPA, makes the gain's
    error enter at second order only; ‖K − K*‖ <= ‖S⁻¹‖‖SK − GᵀP̂A‖ is added squared, times ‖S‖),
    in extended precision (``numpy.longdouble``: numpy's own loops, no BLAS, so the same on every
    kernel). Each product of the evaluation is off by at most k·eps_ld·‖X‖‖Y‖ (k its inner
    dimension, at most n + m + q; first order) and five terms are summed, so 2k·eps_ld·(‖Q‖ +
    ‖A − GK‖²‖P̂‖ + ‖K‖²‖R̃‖ + ‖P̂‖) bounds the evaluation's own error: negligible with an 80-bit long
    double (eps_ld ≈ 1.1e-19), the double-precision floor where long double is double."""
    ld = np.longdouble
    eps_ld = float(np.finfo(ld).eps)
    Al, Gl, Pl, Fl = (np.asarray(X, dtype=ld) for X in (A, G, P, F))
    Acl = Al - Gl @ Fl
    res = np.asarray(Q, dtype=ld) + Acl.T @ Pl @ Acl + Fl.T @ np.asarray(Rt, dtype=ld) @ Fl - Pl
    res = np.asarray(0.5 * (res + res.T), dtype=float)
    gain = np.asarray(np.asarray(S, dtype=ld) @ Fl - Gl.T @ Pl @ Al, dtype=float)
    k = A.shape[0] + G.shape[1]
    nP, nS = _norm2(P), _norm2(S)
    floor = 2 * k * eps_ld * (_norm2(Q) + _norm2(A - G @ F) ** 2 * nP + _norm2(F) ** 2 * _norm2(Rt) + nP)
    return _norm2(res) + nS * (_norm2(np.linalg.inv(S)) * _norm2(gain)) ** 2 + floor


def sda(A, G, H, maxiter: int = 80):
    """The stabilising solution of X = AᵀX(I + GX)⁻¹A + H by the structured doubling algorithm
    (Chu, Fan, Lin and Wang 2004; numpy only), as ``(X, converged)``; ``(None, False)`` when an
    iterate is singular or not finite. G = [B E] R̃⁻¹ [B E]ᵀ is indefinite for the game.

    Stopping rule: the doubling converges quadratically (the error after k steps is of order
    ρ^(2^k), ρ the spectral radius of the closed loop), so the step's update reaches the rounding
    level of the iterate within one or two steps of the true error doing so: stop when
    max|X_{k+1} − X_k| <= n·eps·max|X_{k+1}| (each entry of the update AₖᵀXₖV is an n-term inner
    product, rounded to about n·eps relative). The result is not trusted on that ground:
    :func:`certify` decides from its residual. After ``maxiter`` steps (ρ^(2^80) is below any
    float for ρ < 1 − 1e-20) the last iterate is returned with ``converged=False``."""
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
                return None, False
            H_new = Hk + Ak.T @ Hk @ V1
            Gk = Gk + Ak @ V2 @ Ak.T
            Ak = Ak @ V1
            if not np.all(np.isfinite(H_new)):
                return None, False
            done = np.abs(H_new - Hk).max() <= n * EPS * np.abs(H_new).max()
            Hk = 0.5 * (H_new + H_new.T)
            if done:
                return Hk, True
    return Hk, False


def stein_bound(Ac, maxiter: int = 64):
    """Y = Σ_{j>=0} (A_cᵀ)^j A_c^j (the solution of Y − A_cᵀYA_c = I) by doubling, or None when the
    sum does not converge (A_c is not stable to working precision).

    Y_{k+1} = Y_k + A_kᵀY_kA_k, A_{k+1} = A_k² sums 2^k terms after k steps; the remainder is
    A_kᵀ Y A_k, at most ‖A_k‖²‖Y‖, so the sum stops when ‖A_k‖_F² <= eps (the remainder below the
    rounding of Y; ‖·‖_F bounds ‖·‖₂). 64 steps cover ρ up to 1 − 1e-17."""
    n = Ac.shape[0]
    Y, Ak = np.eye(n), np.array(Ac, dtype=float)
    with np.errstate(all="ignore"):
        for _ in range(maxiter):
            Y = Y + Ak.T @ Y @ Ak
            Ak = Ak @ Ak
            if not np.all(np.isfinite(Y)) or not np.all(np.isfinite(Ak)):
                return None
            if float(np.sum(Ak * Ak)) <= EPS:
                return 0.5 * (Y + Y.T)
    return None


@dataclass
class Certificate:
    """What a computed P̂ proves (see the module docstring).

    verdict : "feasible" (an exact stabilising solution P with γI − EᵀPE ≻ 0, P ⪰ 0 and both closed
        loops stable lies within ``error`` of P̂), "infeasible" (the exact stabilising solution lies
        within ``error`` and violates γI − EᵀPE ≻ 0 or P ⪰ 0: no admissible solution exists), or
        "undecided" (the residual is too large for the conditioning, or the computed closed loop is
        not stable).
    reason : why, in words (for error messages).
    error : ε, the radius of the ball around P̂ that holds P (inf when undecided).
    residual : ‖F(P̂)‖₂ plus its rounding floor.
    margin : γ − λ_max(EᵀP̂E) (the maximiser's concavity) and ``margin_error`` its uncertainty.
    """

    verdict: str
    reason: str
    error: float = np.inf
    residual: float = np.inf
    margin: float = np.nan
    margin_error: float = np.inf
    P: np.ndarray | None = None
    K: np.ndarray | None = None
    Kw: np.ndarray | None = None


def certify(A, B, E, Q, R, gamma, P) -> Certificate:
    """Decide from a computed solution P̂ of the game ARE at level γ whether the stationary game has
    an admissible saddle point (:class:`Certificate`). ``R`` ≻ 0 is the minimiser's weight; the
    maximiser's is −γI. Every threshold is an error bound derived in the module docstring."""
    n, m = B.shape
    q = E.shape[1]
    G = np.hstack([B, E])
    P = 0.5 * (P + P.T)
    Rt = np.zeros((m + q, m + q))
    Rt[:m, :m] = R
    Rt[m:, m:] = -gamma * np.eye(q)
    S = Rt + G.T @ P @ G
    try:
        Sinv = np.linalg.inv(S)
    except np.linalg.LinAlgError:
        return Certificate("undecided", "R̃ + GᵀPG is singular at the computed solution")
    GtPA = G.T @ P @ A
    F = Sinv @ GtPA
    Ac = A - G @ F
    r = _residual(A, G, Q, Rt, P, S, F)
    Y = stein_bound(Ac)
    if Y is None:
        return Certificate("undecided", "the computed closed loop A − BK + E·Kw is not stable", residual=r)
    beta, sigma, g, a = _norm2(Y), _norm2(Sinv), _norm2(G), _norm2(Ac)
    eps_P = 2.0 * beta * r
    j = 2.0 * sigma * g * g * eps_P             # ‖G(S + GᵀΔG)⁻¹GᵀΔ‖ on the ball
    if (beta - 1.0) * j > 0.5 or g * g * sigma * eps_P > 0.5:
        return Certificate("undecided", f"the residual {r:.3g} is too large for the conditioning "
                           f"(‖L⁻¹‖ = {beta:.3g}, ‖S⁻¹‖ = {sigma:.3g}) to locate the exact solution",
                           residual=r)
    if min(a * a, beta - 1.0) * beta * (2.0 * j + j * j) >= 1.0:
        return Certificate("undecided", f"the closed loop's spectral radius {np.abs(np.linalg.eigvals(Ac)).max():.12g} "
                           "is within the error of the computed solution of 1", error=eps_P, residual=r)
    EtPE = E.T @ P @ E
    EtPE = 0.5 * (EtPE + EtPE.T)
    margin = gamma - float(np.linalg.eigvalsh(EtPE)[-1])
    # ‖Eᵀ(P − P̂)E‖ <= ‖E‖²ε, plus the rounding of forming EᵀP̂E (n·eps·‖E‖²‖P̂‖) and of its eigenvalues
    E2 = _norm2(E) ** 2
    margin_error = E2 * eps_P + n * EPS * E2 * _norm2(P) + eigvalsh_tol(EtPE)
    lam_P = float(np.linalg.eigvalsh(P)[0])
    P_error = eps_P + eigvalsh_tol(P)
    out = dict(error=eps_P, residual=r, margin=margin, margin_error=margin_error)
    if margin < -margin_error:
        return Certificate("infeasible", "γI − EᵀPE is not positive definite", **out)
    if lam_P < -P_error:
        return Certificate("infeasible", "the Riccati solution is not positive semidefinite", **out)
    if margin <= margin_error:
        return Certificate("undecided", f"γI − EᵀPE is positive definite only to within its error "
                           f"({margin:.3g} against {margin_error:.3g})", **out)
    K, Kw = F[:m], -F[m:]
    Au = A - B @ K
    Yu = stein_bound(Au)
    # the controller's own loop: K moves by at most ‖S⁻¹(…)GᵀΔA_c‖ <= 2σgaε, A − BK by ‖B‖ times that
    du = _norm2(B) * 2.0 * sigma * g * a * eps_P
    if Yu is None or _norm2(Yu) * (2.0 * _norm2(Au) * du + du * du) >= 1.0:
        return Certificate("undecided", "the controller's closed loop A − BK is not certified stable", **out)
    return Certificate("feasible", "certified", P=P, K=K, Kw=Kw, **out)


def noncausal_level(A, B, E, Q, R, grid: int = 256):
    """(level, error): max over ω of λ(ω) = λ_max(Φ_ww − Φ_uwᴴ Φ_uu⁻¹ Φ_uw + γI), a lower bound on the
    optimal level of the stationary game, with the rounding error of its computation.

    Φ(ω) = R̃ + H(ω)ᴴQH(ω), H(ω) = (e^{jω}I − A)⁻¹[B E], is the Popov function of the game. When
    the game at γ has its admissible stabilising solution P, Φ(ω) = W(ω)ᴴ S W(ω) on the unit circle
    with S = R̃ + GᵀPG and W(ω) = I + S⁻¹GᵀPA(e^{jω}I − A)⁻¹G, invertible since A_c is stable
    (W⁻¹ = I − S⁻¹GᵀPA(e^{jω}I − A_c)⁻¹G), so Φ(ω) has the inertia of S (Sylvester): m positive
    and q negative eigenvalues. Φ_uu = R + H_uᴴQH_u ≻ 0, so the Schur complement, λ(ω)I − γI at
    most, is negative definite: γ > λ(ω) for every ω. λ(ω) is the level of the best non-causal
    controller at frequency ω (u may use all of w); the optimal level equals its maximum when it is
    set by the closed loop reaching the unit circle (then Φ becomes singular at some ω), and lies
    above it when it is set by γI − EᵀPE becoming singular.

    The maximum: a grid on [0, π] refined by a bounded scalar search around the three best points
    (any ω gives a valid lower bound). At the best ω the level is recomputed without the normal
    equations: with Q = CᵀC, Z_u = [C H_u; R^½], Z_w = [C H_w; 0], λ(ω) = max_{‖v‖=1} min_u
    ‖Z_u u + Z_w v‖² = σ_max((I − Π_u)Z_w)² (Π_u the projector on the range of Z_u, from a QR
    factorisation). Its error, to first order: the solve for H is backward stable, so H has
    relative error <= n·eps·κ₂(e^{jω}I − A) and the residual ‖Z_u û + Z_w v̂‖ (û the best u for the
    maximising v̂) moves by at most ‖C‖‖δH‖(1 + ‖û‖); the QR factorisation and the SVD add
    (n + m + q)·eps·‖[Z_u Z_w]‖(1 + ‖û‖) (backward stable). With δ their sum, λ is known to
    2√λ·δ + δ².
    """
    from scipy import optimize

    n, m = B.shape
    q = E.shape[1]
    G = np.hstack([B, E]).astype(complex)
    I = np.eye(n)

    def lam(om):
        om = np.atleast_1d(om)
        with np.errstate(all="ignore"):
            try:
                H = np.linalg.solve(np.exp(1j * om)[:, None, None] * I - A, np.broadcast_to(G, (om.size, n, m + q)))
                Phi = np.conj(np.swapaxes(H, 1, 2)) @ Q @ H
                Phi[:, :m, :m] += R
                Xu, Xuw, Xw = Phi[:, :m, :m], Phi[:, :m, m:], Phi[:, m:, m:]
                Sch = Xw - np.conj(np.swapaxes(Xuw, 1, 2)) @ np.linalg.solve(Xu, Xuw)
                out = np.linalg.eigvalsh(0.5 * (Sch + np.conj(np.swapaxes(Sch, 1, 2))))[:, -1]
            except np.linalg.LinAlgError:   # e^{jω} an eigenvalue of A (at a grid point): skip it
                return np.array([lam(o)[0] for o in om]) if om.size > 1 else np.array([-np.inf])
        return np.where(np.isfinite(out), out, -np.inf)

    om = np.linspace(0.0, np.pi, grid)
    vals = lam(om)
    best_om, best = float(om[int(np.argmax(vals))]), float(vals.max())
    for i in np.argsort(vals)[-3:]:
        res = optimize.minimize_scalar(lambda o: -float(lam(o)[0]), bounds=(om[max(i - 1, 0)], om[min(i + 1, grid - 1)]),
                                       method="bounded", options={"xatol": 1e-10})
        if -float(res.fun) > best:
            best_om, best = float(res.x), -float(res.fun)
    if not np.isfinite(best):
        return 0.0, 0.0
    # the level at best_om by projection, and its error
    lq, Vq = np.linalg.eigh(Q)
    C = np.sqrt(np.clip(lq, 0.0, None))[:, None] * Vq.T
    M = np.exp(1j * best_om) * I - A
    H = np.linalg.solve(M, G)
    Zu = np.vstack([C @ H[:, :m], np.linalg.cholesky(R).T])
    Zw = np.vstack([C @ H[:, m:], np.zeros((m, q))])
    Qz, Rz = np.linalg.qr(Zu, mode="complete")
    QZw = np.conj(Qz.T) @ Zw                 # rows m: are (I − Π_u)Z_w in the orthogonal complement's basis
    _, sv, Vh = np.linalg.svd(QZw[m:])
    level = float(sv[0]) ** 2
    u = -np.linalg.solve(Rz[:m], QZw[:m] @ np.conj(Vh[0]))
    grow = 1.0 + float(np.linalg.norm(u))
    delta = (float(np.linalg.norm(C, 2)) * n * EPS * float(np.linalg.cond(M)) * float(np.linalg.norm(H, 2))
             + (n + m + q) * EPS * float(np.linalg.norm(np.hstack([Zu, Zw]), 2))) * grow
    return level, 2.0 * math.sqrt(level) * delta + delta * delta
