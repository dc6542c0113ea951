"""The finite-horizon regret-optimal controller by its structure: a causal factor of S, Arveson's
distance formula and Parrott's completion, one block row at a time (no semidefinite program).

The regret-optimal problem of :mod:`orrc.controllers.regret_optimal` is

    minimise ‖S^½(Φ − Φ*)‖₂  over strictly block-lower-triangular Φ        (the regret operator)

(:mod:`orrc.solvers.condensed`: v = Φ w, block (t, s) of Φ nonzero only for s < t). Goel and Hassibi
(2021) and Sabag, Goel, Lale and Hassibi (2021) reduce it to a Nehari-type problem on a factorised
operator; in finite dimensions that problem is solved exactly by:

1. **A causal factor of S.** With J the exchange matrix and L the Cholesky factor of JSJ, the matrix
   Δ = J Lᵀ J is lower triangular with ΔᵀΔ = S, so ‖S^½ X‖ = ‖Δ X‖ for every X, and Δ, Δ⁻¹ map
   strictly block-lower-triangular matrices onto each other. With Ψ = ΔΦ and Z = ΔΦ* the problem is
   the distance from Z to the strictly block-lower-triangular matrices: min_Ψ ‖Z − Ψ‖₂.
2. **Its value: Arveson's distance formula** (the finite nest algebra; Arveson 1975, Davidson 1988),

       γ* = max_k ‖Z[block rows 0..k, block columns k..T−1]‖₂,

   the largest of the "staircase" blocks that no causal Ψ can change. The regret-optimal worst-case
   regret is γ*².
3. **An optimal Ψ: Parrott's theorem, block row by block row.** E = Z − Ψ is built row block t = 1,
   ..., T−1 at a time: its known part is E[rows < t] (final) and Z[row t, columns >= t]; its free
   part X = E[row t, columns < t]. With A = E[rows < t, cols < t], B = Z[rows < t, cols >= t] and
   D = Z[row t, cols >= t], Parrott's theorem (Davis, Kahan and Weinberger 1982) says
   min_X ‖[[A, B], [X, D]]‖ = max(‖[A B]‖, ‖[B; D]‖) <= γ*, attained for γ > ‖B‖ by the central choice

       X = −D Bᵀ (γ² I − B Bᵀ)⁻¹ A,

   computed with a Cholesky factor of γ²I − BBᵀ (positive definite exactly when γ > ‖B‖: the
   feasibility test of the level γ). The level used is γ = γ*(1 + 1e-10); after the last row
   ‖E‖ <= γ, so the worst-case regret of Φ = Δ⁻¹(Z − E) is γ*² to 2e-10 relative.

Cost: the condensed operators (O(T² (n + m)²) memory), one Cholesky factor of S, T spectral norms of
the staircase blocks, and T−1 Cholesky solves of size at most T m: about (T m)³ (T n)/2 operations in
all (T = 200, n = 2, m = 1: a few seconds), against the SDP's growth like (T(m + n))⁶.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .._validate import OrrcValueError

__all__ = ["causal_factor", "arveson_distance", "parrott_completion", "regret_optimal_operator", "LEVEL_SLACK"]

#: the level of the completion above Arveson's distance γ*: γ = γ*(1 + LEVEL_SLACK)
LEVEL_SLACK = 1e-10


def causal_factor(S: np.ndarray) -> np.ndarray:
    """Δ lower triangular with ΔᵀΔ = S (S symmetric positive definite): Δ = J Lᵀ J, L = chol(J S J).

    Parameters
    ----------
    S : (k, k) symmetric positive definite.

    Returns
    -------
    numpy.ndarray
        (k, k) Δ, lower triangular, ΔᵀΔ = S.

    Raises
    ------
    orrc.OrrcValueError
        When S is not symmetric positive definite.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> Delta = regret.causal_factor(c.S)
    >>> bool(np.allclose(Delta.T @ Delta, c.S)), bool(np.allclose(Delta, np.tril(Delta)))
    (True, True)
    """
    try:
        L = np.linalg.cholesky(S[::-1, ::-1])
    except np.linalg.LinAlgError as exc:
        raise OrrcValueError("the regret-optimal problem's Hessian S is not positive definite (R must be "
                             "positive definite)") from exc
    return L.T[::-1, ::-1].copy()


def arveson_distance(Z: np.ndarray, T: int, m: int, n: int) -> float:
    """γ* = max_k ‖Z[block rows 0..k, block columns k..T−1]‖₂: the distance from Z (T m, T n) to the
    strictly block-lower-triangular matrices (module docstring, step 2).

    Parameters
    ----------
    Z : (T m, T n) the operator.
    T, m, n : its block structure.

    Returns
    -------
    float
        γ*, the distance to the strictly causal operators.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> Z = regret.causal_factor(c.S) @ c.Phi_star
    >>> print(round(regret.arveson_distance(Z, 10, 1, 2), 4))
    2.4852
    """
    return max(np.linalg.norm(Z[:(k + 1) * m, k * n:], 2) for k in range(T))


def parrott_completion(Z: np.ndarray, T: int, m: int, n: int, gamma: float) -> np.ndarray:
    """E with E = Z on and above the block diagonal and ‖E‖₂ <= gamma, its strictly lower blocks filled
    by Parrott's central choice one block row at a time (module docstring, step 3); needs gamma above
    Arveson's distance of Z (else an :class:`~orrc.OrrcValueError`: a Cholesky factor that fails, or a
    completion whose norm exceeds gamma).

    Parameters
    ----------
    Z : (T m, T n) the operator.
    T, m, n : its block structure.
    gamma : the norm bound, above Arveson's distance.

    Returns
    -------
    numpy.ndarray
        (T m, T n) E, with ‖E‖₂ <= gamma.

    Raises
    ------
    orrc.OrrcValueError
        When gamma is not above Arveson's distance of Z.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> Z = regret.causal_factor(c.S) @ c.Phi_star
    >>> gamma = 1.01 * regret.arveson_distance(Z, 10, 1, 2)
    >>> E = regret.parrott_completion(Z, 10, 1, 2, gamma)
    >>> bool(np.linalg.norm(E, 2) <= gamma * (1 + 1e-9))
    True
    """
    E = Z.copy()
    g2 = gamma * gamma
    for t in range(1, T):
        r, c = t * m, t * n
        A, B, D = E[:r, :c], Z[:r, c:], Z[r:r + m, c:]
        G = g2 * np.eye(r) - B @ B.T
        try:
            factor = sla.cho_factor(G, lower=True, check_finite=False)
        except np.linalg.LinAlgError as exc:
            raise OrrcValueError(f"the level γ = {gamma:.6g} is below the norm of the fixed block above row {t}: "
                                 "no causal completion at this level") from exc
        E[r:r + m, :c] = -(D @ B.T) @ sla.cho_solve(factor, A, check_finite=False)
    norm = np.linalg.norm(E, 2)
    if not norm <= gamma * (1.0 + 1e-8):  # a staircase block [B; D] above the level: infeasible at gamma
        raise OrrcValueError(f"the level γ = {gamma:.6g} is below Arveson's distance (the completion has norm "
                             f"{norm:.6g}): no causal completion at this level")
    return E


def regret_optimal_operator(S: np.ndarray, Phi_star: np.ndarray, T: int, m: int, n: int):
    """(Φ, γ*²): a strictly block-lower-triangular Φ (T m, T n) whose regret operator S^½(Φ − Φ*) has
    norm γ*(1 + LEVEL_SLACK), and the optimal worst-case regret γ*² (module docstring).

    Parameters
    ----------
    S : (T m, T m) the regret weight.
    Phi_star : (T m, T n) the clairvoyant operator Φ*.
    T, m, n : the block structure.

    Returns
    -------
    tuple
        Φ (T m, T n), strictly block-lower-triangular, and the optimal worst-case regret γ*².

    Raises
    ------
    orrc.OrrcValueError
        When S is not positive definite or the sizes do not match.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> A, B, Q, R = di.system.A, di.system.B, di.cost.Q, di.cost.R
    >>> from orrc.solvers import condensed, regret
    >>> c = condensed.condensed(A, B, Q, R, T=10)
    >>> Phi, value = regret.regret_optimal_operator(c.S, c.Phi_star, 10, 1, 2)
    >>> Phi.shape, round(float(value), 4)
    ((10, 20), 6.1764)
    """
    Delta = causal_factor(S)
    Z = Delta @ Phi_star
    gamma_star = arveson_distance(Z, T, m, n)
    E = parrott_completion(Z, T, m, n, gamma_star * (1.0 + LEVEL_SLACK))
    mask = np.kron(np.tril(np.ones((T, T)), k=-1), np.ones((m, n)))
    Psi = mask * (Z - E)   # Z − E vanishes on and above the block diagonal (up to rounding)
    Phi = sla.solve_triangular(Delta, Psi, lower=True, check_finite=False)
    return mask * Phi, gamma_star ** 2
