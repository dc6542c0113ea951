"""Rounding-error bounds that the tests' tolerances are derived from (independent of orrc).

A tolerance in this suite either follows from one of these bounds, stated where it is used,
or compares quantities that are well conditioned by construction. Machine epsilon is
``EPS`` = 2^-52 ≈ 2.2e-16; ``N`` below is the order of the matrix.

* Symmetric eigenvalues. numpy's ``eigh``/``eigvalsh`` (LAPACK ``syevd``) are backward
  stable: the computed eigenvalues are the exact ones of A + E with ‖E‖₂ <= p(N)·EPS·‖A‖₂,
  p(N) a modest function of N (LAPACK Users' Guide, section 4.7). By Weyl's inequality every
  eigenvalue then moves by at most ‖E‖₂. We take p(N) = N, which covers the reduction to
  tridiagonal form and the tridiagonal solver with room to spare (the largest error seen over
  the OpenBLAS kernels Prescott ... SkylakeX is at most 7 % of this bound), and the bound
  does not depend on which BLAS kernel ran.
* A root found by testing the sign of an eigenvalue. If λ(s) is the eigenvalue tested and
  its slope at the root is λ'(s), an error ‖E‖₂ in λ moves the computed root by about
  ‖E‖₂ / |λ'(s)| (first order). For λ_min(D(s) - H) with D(s) = s·P + const and P a
  diagonal 0/1 projector, λ'(s) = ‖P v‖² (Hellmann-Feynman, v the unit eigenvector).
"""
import numpy as np

EPS = float(np.finfo(float).eps)


def eigvalsh_error(A) -> float:
    """N·EPS·‖A‖₂: a bound on the error of every eigenvalue ``np.linalg.eigvalsh(A)`` returns for
    a symmetric A (backward stability and Weyl's inequality, see the module docstring)."""
    A = np.asarray(A, dtype=float)
    return A.shape[0] * EPS * float(np.linalg.norm(A, 2))


def sign_root_error(A, v, P) -> float:
    """The uncertainty of a root s* found by testing the sign of an eigenvalue of A(s) = s·P + C:
    ``eigvalsh_error(A) / ‖P v‖²`` at the root (A = A(s*), v its unit eigenvector, P the
    0/1 diagonal projector as a boolean mask), to first order."""
    v = np.asarray(v, dtype=float)
    return eigvalsh_error(A) / float(v[P] @ v[P])


def frequency_response_error(A, grid: int = 400) -> float:
    """A bound on the relative rounding error of one computed value σ_max(C(e^{jω}I − A)⁻¹B + D)²
    (a squared H∞ norm found as the peak of a frequency response), over ω on a grid of [0, π].

    The solve is backward stable, so (e^{jω}I − A)⁻¹B has relative error <= N·EPS·κ₂(e^{jω}I − A)
    (first order); the product with C, the sum with D and the largest singular value add a few
    EPS, and squaring doubles the total: 2(N + 3)·EPS·max_ω κ₂(e^{jω}I − A)."""
    A = np.asarray(A, dtype=float)
    N = A.shape[0]
    z = np.exp(1j * np.linspace(0.0, np.pi, grid))[:, None, None]
    kappa = float(np.max(np.linalg.cond(z * np.eye(N) - A)))
    return 2 * (N + 3) * EPS * kappa


def level_bracket_holds(level, error, norm_sq, gamma, A_cl) -> bool:
    """The game level's bracket against an independent closed-loop norm: γ* ∈ [level − error, level]
    (orrc.solvers.game.optimal_game_level) and the H∞ controller built at γ >= level has a closed loop
    whose squared H∞ norm N satisfies γ* <= N <= γ (no controller beats γ*; the controller guarantees
    γ). So level − error <= N <= γ, up to the rounding δ of the computed N
    (:func:`frequency_response_error` of the closed loop's A_cl)."""
    delta = frequency_response_error(A_cl)
    return level - error - delta * norm_sq <= norm_sq <= gamma * (1 + delta)


def running_regret_error(costs, w, gamma) -> np.ndarray:
    """A bound on how far two ways of computing R^p_t(γ) = Σ_{s<t} c_s - γ Σ_{s<t} ‖w_s‖², t = 1..T,
    can differ (e.g. the cumulative sum of c_s - γ‖w_s‖², or the two cumulative sums subtracted).

    Recursive summation of t terms is off by at most (t - 1)·eps·Σ|terms| (first order), each
    ‖w_s‖² by n·eps·‖w_s‖² and each product or difference by eps. R cancels (it crosses 0 where
    γ is near the running ratio), so the error is relative to the sums, not to R: per way
    (t + n + 2)·eps·(Σ|c_s| + γ Σ‖w_s‖²), and twice that between two ways.
    """
    costs, w = np.asarray(costs, dtype=float), np.asarray(w, dtype=float)
    t = np.arange(1, len(costs) + 1)
    e = np.sum(w * w, axis=1)
    return 2 * (t + w.shape[1] + 2) * EPS * (np.cumsum(np.abs(costs)) + gamma * np.cumsum(e))


def assert_within(actual, desired, err) -> None:
    """|actual - desired| <= err elementwise (err an array of error bounds, e.g. from
    :func:`running_regret_error`), with the worst step in the message."""
    actual, desired = np.asarray(actual, dtype=float), np.asarray(desired, dtype=float)
    excess = np.abs(actual - desired) - np.asarray(err, dtype=float)
    k = int(np.argmax(excess))
    assert actual.shape == desired.shape and excess[k] <= 0, (
        f"at index {k}: |{actual.flat[k]!r} - {desired.flat[k]!r}| exceeds the bound {np.asarray(err).flat[k]:.3g}")
