"""orrc.certify: certified constants bound V_M (tightly), γ_c is the best on the Pareto curve,
and the worst-case attenuation agrees with independent computations."""
import math
import warnings

import numpy as np
import pytest
from scipy import linalg

import orrc
from orrc import certify, theory
from conftest import batch_optimum, random_lq_problem
import numerics
import paper


def random_problem(seed, n=None, m=None):
    return random_lq_problem(np.random.default_rng(seed), n, m, rho_range=(0.3, 1.3))


def condensed_value(A, B, Q, R, M, x, W):
    """V_M(x, W) by condensing the M-step problem into one linear solve (independent of H)."""
    return batch_optimum(A, B, Q, R, M, x, W)[1]


# -- exact LQ constants ----------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(5))
def test_certified_pair_bounds_V_M_and_is_tight(seed):
    sysm, cost = random_problem(seed)
    M = certify.smallest_certified_M(sysm, cost, 40)
    c = certify.lq_constants(sysm, cost, 6 if M is None else M + 2)   # admissible or not: a valid pair
    A, B, Q, R, n = sysm.A, sysm.B, cost.Q, cost.R, sysm.n
    rng = np.random.default_rng(100 + seed)
    for _ in range(30):
        x = rng.standard_normal(n) * rng.uniform(0, 3)
        W = rng.standard_normal((c.M, n)) * rng.uniform(0, 3)
        V = condensed_value(A, B, Q, R, c.M, x, W)
        assert V <= c.alpha_hi * (x @ x) + c.gamma_bar * np.sum(W * W) + 1e-9 * (1 + V)
        assert V >= c.alpha_lo * (x @ x) * (1 - 1e-12)          # Lemma 1, first part
    # tight: the top eigenvector of H - diag(ᾱ I, γ̄ I) attains the bound
    H = c.info["H"]
    D = np.diag(np.r_[np.full(n, c.alpha_hi), np.full(c.M * n, c.gamma_bar)])
    lam, vec = np.linalg.eigh(H - D)
    # on the curve λ_max(H - D) = 0; computed, it is off by the eigensolver's error for H - D plus
    # the effect of the rounding in the curve's own ᾱ (bounded the same way, by that of H)
    assert abs(lam[-1]) <= numerics.eigvalsh_error(H - D) + numerics.eigvalsh_error(H)
    z = vec[:, -1]
    x, W = z[:n], z[n:].reshape(c.M, n)
    V = condensed_value(A, B, Q, R, c.M, x, W)
    assert V == pytest.approx(c.alpha_hi * (x @ x) + c.gamma_bar * np.sum(W * W), rel=1e-6)
    assert c.alpha_lo == pytest.approx(np.linalg.eigvalsh(Q)[0]) and not c.estimate
    if M is None:
        assert not c.admissible and c.gamma_c == math.inf and "no admissible" in c.reason
        return
    # the remaining attributes are the theory's functions of the pair
    assert c.a == pytest.approx(theory.min_decay_rate(c.M, c.alpha_lo, c.alpha_hi), rel=1e-12)
    assert c.gamma_c == pytest.approx(theory.gamma_c(c.M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar), rel=1e-12)
    assert c.admissible and c.reason is None


def test_pareto_curve_is_admissible_tight_and_decreasing():
    sysm, cost = random_problem(7, n=2, m=1)
    c = certify.lq_constants(sysm, cost, 8, grid=60)
    H, n = c.info["H"], sysm.n
    gbs, ahs = c.pareto[:, 0], c.pareto[:, 1]
    assert np.all(np.diff(gbs) > 0) and np.all(np.diff(ahs) <= 1e-9 * ahs[:-1])
    x_block = np.arange(len(H)) < n                       # the diagonal entries ᾱ multiplies
    for gb, ah in c.pareto[::6]:
        D = np.diag(np.r_[np.full(n, ah), np.full(8 * n, gb)])
        lam, vec = np.linalg.eigh(D - H)
        # admissible: on the curve λ_min(D - H) = 0 exactly; computed, it is off by at most the
        # eigensolver's error (numerics.eigvalsh_error) plus that of the curve's own ᾱ, whose
        # effect on λ_min is bounded the same way by the Schur-complement route (‖H‖·N·eps)
        assert lam[0] >= -(numerics.eigvalsh_error(D - H) + numerics.eigvalsh_error(H))
        # independent: the smallest admissible ᾱ by bisection on the PSD test λ_min(D - H) >= 0.
        # Near the root λ_min moves with ᾱ at the rate ‖v_x‖² (v its eigenvector), which is tiny
        # where the curve is steep (γ̄ just above λ_max(H_ww): ‖v_x‖² ~ 1e-11 at the first point,
        # where D - H has entries ~5e5), so the eigensolver's error N·eps·‖D - H‖ puts the
        # bisection's root anywhere within numerics.sign_root_error of it (~1e2 there; 1e-14 to
        # 1e-9 relative at the other points), whatever BLAS kernel computes it. Plus the bracket.
        lo_, hi_ = 0.0, ah * 2 + 1
        for _ in range(60):
            mid = 0.5 * (lo_ + hi_)
            D[:n, :n] = mid * np.eye(n)
            lo_, hi_ = (lo_, mid) if np.linalg.eigvalsh(D - H)[0] >= 0 else (mid, hi_)
        D[:n, :n] = ah * np.eye(n)
        assert abs(ah - hi_) <= numerics.sign_root_error(D - H, vec[:, 0], x_block) + (hi_ - lo_)


@pytest.mark.parametrize("seed", [21, 22, 23, 24])
def test_certified_gamma_c_is_the_best_on_a_fine_pareto_grid(seed):
    sysm, cost = random_problem(seed)
    M = certify.smallest_certified_M(sysm, cost, 40)
    assert M is not None            # these seeds are certifiable
    for MM in (M, M + 5):
        c = certify.lq_constants(sysm, cost, MM)
        H, n = c.info["H"], sysm.n
        Hxx, Hxw, Hww = H[:n, :n], H[:n, n:], H[n:, n:]
        lmax = np.linalg.eigvalsh(Hww)[-1]
        best = math.inf
        for d in np.geomspace(1e-8, 1e8, 4000) * max(lmax, 1.0):
            gb = lmax + d
            ah = np.linalg.eigvalsh(Hxx + Hxw @ np.linalg.solve(gb * np.eye(len(Hww)) - Hww, Hxw.T))[-1]
            if ah ** 2 < c.alpha_lo ** 2 * (MM - 1):
                a = paper.a_min(MM, c.alpha_lo, ah)
                best = min(best, paper.gamma_c(MM, a, c.alpha_lo, ah, gb))
        assert c.gamma_c <= 1.02 * best
        # and it is attained: the chosen ᾱ is the curve's value at the chosen γ̄ (computed here).
        # Both routes solve with γ̄I - H_ww, whose condition number is at most (2‖H‖ + d)/d
        # (d = γ̄ - λ_max(H_ww)), then take λ_max: each is accurate to N·eps·(3 + 2‖H‖/d) relative
        ah = np.linalg.eigvalsh(Hxx + Hxw @ np.linalg.solve(c.gamma_bar * np.eye(len(Hww)) - Hww, Hxw.T))[-1]
        d = c.gamma_bar - np.linalg.eigvalsh(Hww)[-1]
        assert c.alpha_hi == pytest.approx(ah, rel=2 * len(H) * numerics.EPS * (3 + 2 * np.linalg.norm(H, 2) / d))


def test_no_admissible_pair_gives_inf_with_a_reason():
    ex = orrc.examples.scalar_unstable()
    M_ok = certify.smallest_certified_M(ex.system, ex.cost)
    below = certify.lq_constants(ex.system, ex.cost, M_ok - 1)
    assert below.gamma_c == math.inf and not below.admissible
    assert f"M={M_ok - 1}" in below.reason and f"smallest certified M is {M_ok}" in below.reason
    # still an admissible pair for Lemma 1 (which holds for every M >= 2)
    H, n = below.info["H"], ex.system.n
    D = np.diag(np.r_[np.full(n, below.alpha_hi), np.full((M_ok - 1) * n, below.gamma_bar)])
    assert np.linalg.eigvalsh(D - H)[0] >= -(numerics.eigvalsh_error(D - H) + numerics.eigvalsh_error(H))
    assert certify.lq_constants(ex.system, ex.cost, M_ok).admissible
    singular = certify.lq_constants(ex.system, orrc.QuadraticCost(np.zeros((1, 1)), np.eye(1)), 5)
    assert singular.gamma_c == math.inf and "singular" in singular.reason


def test_lq_constants_errors():
    ex = orrc.examples.scalar_unstable()
    with pytest.raises(ValueError, match="M must be an integer >= 2"):
        certify.lq_constants(ex.system, ex.cost, 1)
    with pytest.raises(ValueError, match="LinearSystem"):
        certify.lq_constants(orrc.examples.van_der_pol().system, ex.cost, 5)
    with pytest.raises(ValueError, match="QuadraticCost"):
        certify.lq_constants(ex.system, "cost", 5)
    with pytest.raises(ValueError, match="grid"):
        certify.lq_constants(ex.system, ex.cost, 5, grid=3)
    c = certify.lq_constants(ex.system, ex.cost, 20)
    with pytest.raises(ValueError, match="gamma_bar must exceed"):
        c.alpha_hi_at(c.info["lambda_max_Hww"] * 0.5)


def test_alpha_hi_floor_is_lq_constants_alpha_hi_inf():
    """λ_max(P_0(M)) from one recursion equals what lq_constants reports at each M, bit for bit,
    and smallest_certified_M is the first M with that floor below α_lo √(M-1)."""
    sysm, cost = random_problem(11, n=3, m=2)
    Ms = [9, 2, 5, 3]                                  # any order, aligned with the result
    floors = certify.alpha_hi_floor(sysm, cost, Ms)
    assert isinstance(floors, np.ndarray) and floors.shape == (len(Ms),)
    for M, f in zip(Ms, floors):
        assert f == certify.lq_constants(sysm, cost, M, grid=20).info["alpha_hi_inf"]
    assert np.array_equal(certify.alpha_hi_floor(sysm, cost, range(2, 10))[[7, 0, 3, 1]], floors)
    assert certify.alpha_hi_floor(sysm, cost, [1])[0] == pytest.approx(np.linalg.eigvalsh(cost.Q)[-1])
    ex = orrc.examples.scalar_unstable()
    M_ok = certify.smallest_certified_M(ex.system, ex.cost)
    fl = certify.alpha_hi_floor(ex.system, ex.cost, range(2, M_ok + 1))
    ok = fl < ex.cost.alpha_lo * np.sqrt(np.arange(1, M_ok))
    assert ok[-1] and not ok[:-1].any()
    for bad in ([0], [2, -1], [2.5], [True], 5, "23", []):
        with pytest.raises(ValueError, match="Ms"):
            certify.alpha_hi_floor(sysm, cost, bad)
    with pytest.raises(ValueError, match="QuadraticCost"):
        certify.alpha_hi_floor(sysm, "cost", [2])


def test_constants_b_is_lemma2_b():
    ex = orrc.examples.scalar_unstable()
    M_ok = certify.smallest_certified_M(ex.system, ex.cost)
    c = certify.lq_constants(ex.system, ex.cost, M_ok + 2)
    assert c.b == theory.decay_b(c.alpha_lo, c.alpha_hi, c.gamma_bar)
    assert c.gamma_c == theory.gamma_c(c.M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    with pytest.raises(AttributeError):
        c.b = 1.0
    below = certify.lq_constants(ex.system, ex.cost, M_ok - 1)
    assert below.b == math.inf and below.gamma_c == math.inf


# -- sampled estimates -----------------------------------------------------------------------------
def test_sampled_constants_are_lower_bounds_on_the_exact_ones():
    sysm, cost = random_problem(3, n=2, m=1)
    M = 6
    exact = certify.lq_constants(sysm, cost, M)
    est = certify.sampled_constants(sysm, cost, M, n_samples=25, x_radius=2.0, w_radius=1.0, seed=0)
    H, n = exact.info["H"], sysm.n
    assert est.estimate and "not a certificate" in est.method
    assert est.info["alpha_hi_x"] <= np.linalg.eigvalsh(H[:n, :n])[-1] * (1 + 1e-9)
    assert est.info["gamma_bar_w"] <= np.linalg.eigvalsh(H[n:, n:])[-1] * (1 + 1e-9)
    # the sampled pair bounds every sampled V_M; the exact curve lies above the sampled one
    s, e, V = est.info["sigma"], est.info["energy"], est.info["V"]
    assert np.all(V <= est.alpha_hi * s + est.gamma_bar * e + 1e-9 * (1 + V))
    lmax = exact.info["lambda_max_Hww"]
    for gb, ah in est.pareto[::10]:
        if gb > lmax:
            assert exact.alpha_hi_at(gb) >= ah * (1 - 1e-9)


def test_sampled_constants_on_a_nonlinear_problem():
    ex = orrc.examples.van_der_pol()
    est = certify.sampled_constants(ex.system, ex.cost, 5, n_samples=6, x_radius=0.5,
                                    input_bounds=ex.input_bounds, seed=1)
    assert est.estimate and est.M == 5 and est.info["n_solved"] + est.info["failures"] == 18
    s, e, V = est.info["sigma"], est.info["energy"], est.info["V"]
    assert np.all(V <= est.alpha_hi * s + est.gamma_bar * e + 1e-9 * (1 + V))
    assert est.alpha_hi >= est.info["alpha_hi_x"] and est.gamma_bar >= est.info["gamma_bar_w"]
    if not est.admissible:
        assert "threshold" in est.reason
    with pytest.raises(ValueError, match="x_radius"):
        certify.sampled_constants(ex.system, ex.cost, 5, x_radius=0.0)


# -- worst-case attenuation ------------------------------------------------------------------------
def impulse_gram(system, controller, T):
    """GᵀG with Σ_t c_t = vec Wᵀ (GᵀG) vec W, built from unit-impulse simulations (independent of orrc.certify)."""
    n = system.n
    N = T * n
    Xs, Us = [], []
    for i in range(N):
        w = np.zeros((T, n))
        w.flat[i] = 1.0
        tr = orrc.simulate(system, controller, np.zeros(n), w, T)
        Xs.append(tr.x[:T])
        Us.append(tr.u)
    X = np.stack(Xs, axis=-1)   # (T, n, N): x_t = X[t] vec W
    U = np.stack(Us, axis=-1)
    Q, R = controller.cost.Q, controller.cost.R
    return sum(X[t].T @ Q @ X[t] + U[t].T @ R @ U[t] for t in range(T))


@pytest.mark.parametrize("seed,kind", [(0, "preview"), (1, "preview"), (2, "lqr"), (3, "preview")])
def test_worst_case_attenuation_against_impulse_responses(seed, kind):
    sysm, cost = random_problem(40 + seed)
    ctrl = orrc.PreviewRHC(sysm, cost, 4) if kind == "preview" else orrc.LQR(sysm, cost)
    T = 8
    res = certify.worst_case_attenuation(sysm, ctrl, T)
    gram = impulse_gram(sysm, ctrl, T)
    lam, vec = linalg.eigh(gram)
    assert res.gamma == pytest.approx(lam[-1], rel=1e-9)
    assert res.w.shape == (T, sysm.n) and np.sum(res.w ** 2) == pytest.approx(1.0)
    # the same top eigenvector up to sign: by Davis-Kahan each computation is within an angle
    # θ <= err/gap of the true one (err = numerics.eigvalsh_error, gap = λ_1 - λ_2 > 0, checked),
    # so 1 - |cos| <= (2θ)²/2, plus the rounding of the dot product (N·eps)
    gap = lam[-1] - lam[-2]
    assert gap > 1e3 * numerics.eigvalsh_error(gram)
    theta = 2 * numerics.eigvalsh_error(gram) / gap
    assert abs(vec[:, -1] @ res.w.ravel()) == pytest.approx(1.0, abs=theta ** 2 / 2 + len(gram) * numerics.EPS)
    # the adversary made explicit: simulating it gives R^p_T(γ*) = 0, any other w gives <= 0
    tr = orrc.simulate(sysm, ctrl, np.zeros(sysm.n), res.w, T)
    assert orrc.attenuation_regret(tr, res.gamma) == pytest.approx(0.0, abs=1e-9 * res.gamma)
    rng = np.random.default_rng(seed)
    for _ in range(5):
        w = rng.standard_normal((T, sysm.n))
        tr = orrc.simulate(sysm, ctrl, np.zeros(sysm.n), w, T)
        assert orrc.attenuation_regret(tr, res.gamma) <= 1e-9 * res.gamma * np.sum(w * w)


def test_large_T_uses_the_iterative_solver_and_agrees_with_dense():
    ex = orrc.examples.two_mass_spring()
    ctrl = orrc.PreviewRHC(ex.system, ex.cost, 6)
    res = certify.worst_case_attenuation(ex.system, ctrl, 60)      # G is 300 x 240: ARPACK path
    s = linalg.svdvals(res.G)
    assert res.gamma == pytest.approx(s[0] ** 2, rel=1e-10)
    tr = orrc.simulate(ex.system, ctrl, np.zeros(4), res.w, 60)
    assert orrc.attenuation_regret(tr, res.gamma) == pytest.approx(0.0, abs=1e-8 * res.gamma)


def frequency_sweep_peak(A, B, C, D, points=2000):
    """max over a frequency grid of σ_max(C(e^{jω}I - A)⁻¹B + D)², a lower bound on the H∞ norm²."""
    best = 0.0
    I = np.eye(len(A))
    for om in np.linspace(0, np.pi, points):
        Gz = C @ np.linalg.solve(np.exp(1j * om) * I - A, B) + D
        best = max(best, linalg.svdvals(Gz)[0] ** 2)
    return best


# python-control's H∞ bisection stops when its bracket is within HINF_TOL relative of the norm,
# so γ = norm² is within (1 + tol)² - 1 ≈ 2·tol; doubled for the rounding in its test for
# imaginary-axis eigenvalues (measured: up to 1.2e-9 relative in γ over the OpenBLAS kernels).
HINF_TOL = 1e-9
HINF_REL = 4 * HINF_TOL


def test_lqr_finite_T_increases_to_the_hinf_limit():
    ex = orrc.examples.double_integrator()
    lqr = orrc.LQR(ex.system, ex.cost)
    values = [certify.worst_case_attenuation(ex.system, lqr, T).gamma for T in (10, 40, 160, 400)]
    limit = certify.worst_case_attenuation_limit(ex.system, lqr, tol=HINF_TOL)
    assert np.all(np.diff(values) > 0)
    assert values[-1] <= limit.gamma * (1 + HINF_REL)
    assert values[-1] >= 0.99 * limit.gamma
    # independent: the closed loop built here, its frequency response on a grid
    A, B, K = ex.system.A, ex.system.B, lqr.K
    Qh, Rh = linalg.sqrtm(ex.cost.Q).real, linalg.sqrtm(ex.cost.R).real
    peak = frequency_sweep_peak(A - B @ K, np.eye(2), np.vstack([Qh, -Rh @ K]), np.zeros((3, 2)))
    assert peak <= limit.gamma * (1 + HINF_REL) and peak >= limit.gamma * (1 - 1e-3)
    assert limit.start == "stationary"
    assert certify.worst_case_attenuation_limit(ex.system, lqr, start="cold").gamma == limit.gamma


def test_preview_limit_stationary_and_cold_start():
    ex = orrc.examples.scalar_unstable()
    ctrl = orrc.PreviewRHC(ex.system, ex.cost, 3)
    stat = certify.worst_case_attenuation_limit(ex.system, ctrl, tol=HINF_TOL)
    cold = certify.worst_case_attenuation_limit(ex.system, ctrl, start="cold")
    A, B, C, D = (np.asarray(m) for m in (stat.closed_loop.A, stat.closed_loop.B,
                                          stat.closed_loop.C, stat.closed_loop.D))
    peak = frequency_sweep_peak(A, B, C, D)
    assert peak <= stat.gamma * (1 + HINF_REL) and peak >= stat.gamma * (1 - 1e-4)
    res = [certify.worst_case_attenuation(ex.system, ctrl, T) for T in (5, 20, 80, 200)]
    values = [r.gamma for r in res]
    # non-decreasing in T up to rounding: γ = σ_max(G)², and the SVD is backward stable, so σ_max
    # is off by max(G.shape)·eps·σ_max at most and γ by twice that, relative
    err = np.array([2 * max(r.G.shape) * numerics.EPS * r.gamma for r in res])
    assert np.all(np.diff(values) >= -(err[1:] + err[:-1]))
    # the finite-T values (x_0 = 0, preview from t = 0) converge to the cold-start level,
    # which exceeds the stationary H∞ level: the worst w sits at the start
    assert values[-1] == pytest.approx(cold.gamma, rel=1e-7)
    assert cold.gamma > stat.gamma * 1.05
    w = certify.worst_case_attenuation(ex.system, ctrl, 80).w
    assert np.sum(w[:10] ** 2) > 0.9


def test_a_loop_on_the_stability_boundary_to_working_precision_has_no_finite_limit():
    """x⁺ = (1 - δ)x + w with zero input: γ_∞ = 1/δ² (the gain at ω = 0). python-control's H∞
    routine cannot resolve 1 - ρ <= 1e-8 (it returns inf, or 5e23 for 1e16); below that the loop
    is reported as not stable, and near it the lost accuracy is warned about."""
    cost = orrc.QuadraticCost([[1.0]], [[1.0]])

    def limit(delta):
        return certify.worst_case_attenuation_limit(orrc.LinearSystem([[1 - delta]], [[1.0]]),
                                                    orrc.ZeroInput(1, cost))
    for delta in (3e-9, 1e-8):
        lim = limit(delta)
        assert lim.gamma == math.inf and "stability boundary" in lim.reason
    with pytest.warns(orrc.SolverWarning, match="resolved only to about"):
        lim = limit(1e-6)
    assert lim.gamma == pytest.approx(1e12, rel=2 * (1e-8 / 1e-6) ** 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lim = limit(1e-2)
    assert lim.gamma == pytest.approx(1e4, rel=4e-9)          # 2·tol (tol = 1e-9 on the norm), doubled


def test_unstable_loop_has_no_finite_limit_and_errors():
    ex = orrc.examples.scalar_unstable()
    zero = orrc.ZeroInput(1, ex.cost)
    lim = certify.worst_case_attenuation_limit(ex.system, zero)
    assert lim.gamma == math.inf and "not stable" in lim.reason
    g = [certify.worst_case_attenuation(ex.system, zero, T).gamma for T in (5, 10)]
    assert g[1] > 100 * g[0]
    with pytest.raises(ValueError, match="QuadraticCost"):
        certify.worst_case_attenuation(ex.system, orrc.ZeroInput(1), 5)
    bounded = orrc.PreviewRHC(ex.system, ex.cost, 3, input_bounds=(-1, 1))
    with pytest.raises(ValueError, match="linear controller"):
        certify.worst_case_attenuation(ex.system, bounded, 5)
    with pytest.raises(ValueError, match="T must be"):
        certify.worst_case_attenuation(ex.system, zero, 0)
    with pytest.raises(ValueError, match="start"):
        certify.worst_case_attenuation_limit(ex.system, zero, start="warm")
    with pytest.raises(ValueError, match="LinearSystem"):
        certify.worst_case_attenuation(orrc.examples.van_der_pol().system, zero, 5)
