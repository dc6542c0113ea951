"""The named examples (``orrc.examples``): the scalar system x+ = A x + B u + w takes its
coefficients as ``A`` and ``B`` (one meaning per symbol: in the book ``a`` is the decay rate
and ``b`` Lemma 2's constant); the old keywords ``a`` and ``b`` still work, with a warning."""
import warnings

import numpy as np
import pytest

import orrc
from orrc import examples as exs


def test_the_scalar_system_has_coefficients_A_and_B():
    ex = exs.scalar_unstable(A=1.5, B=0.5)
    assert np.array_equal(ex.system.A, [[1.5]]) and np.array_equal(ex.system.B, [[0.5]]), \
        "A and B are the entries of the linear system x+ = A x + B u + w"
    default = exs.scalar_unstable()
    assert default.system.A[0, 0] == 2.0 and default.system.B[0, 0] == 1.0, \
        "the default system is x+ = 2 x + u + w"
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # the new keywords warn about nothing
        exs.scalar_unstable(A=1.2)


@pytest.mark.parametrize("old, new", [("a", "A"), ("b", "B")])
def test_the_old_keywords_still_work_with_a_deprecation_warning(old, new):
    with pytest.warns(DeprecationWarning, match=f"keyword {new}"):
        ex = exs.scalar_unstable(**{old: 3.0})
    assert ex.system.A[0, 0] == (3.0 if old == "a" else 2.0), "a= sets the coefficient A"
    assert ex.system.B[0, 0] == (3.0 if old == "b" else 1.0), "b= sets the coefficient B"


@pytest.mark.parametrize("old, new", [("a", "A"), ("b", "B")])
def test_an_old_and_a_new_keyword_together_are_refused(old, new):
    with pytest.raises(orrc.OrrcValueError, match=f"{new}=0.5.*{old}=3.0"):
        exs.scalar_unstable(**{new: 0.5, old: 3.0})


def test_the_old_keywords_are_checked_like_the_new_ones():
    with pytest.warns(DeprecationWarning), pytest.raises(orrc.OrrcValueError, match="B must be non-zero"):
        exs.scalar_unstable(b=0.0)


# ---- the chain of masses with nonlinear springs (the scalable example) ----

def _linear_chain(k, dt, stiffness, damping):
    """The linear chain in numpy, semi-implicit Euler: v+ = v + dt (K p − c v + e_k u), p+ = p + dt v+."""
    K = -2 * stiffness * np.eye(k) + stiffness * (np.eye(k, k=1) + np.eye(k, k=-1))
    K[k - 1, k - 1] = -stiffness   # no spring after the last mass
    I, Z = np.eye(k), np.zeros((k, k))
    Av = np.hstack([dt * K, (1 - dt * damping) * I])     # v+ in terms of (p, v)
    Ap = np.hstack([I, Z]) + dt * Av                      # p+ = p + dt v+
    bv = np.zeros((k, 1))
    bv[-1] = dt
    return np.vstack([Ap, Av]), np.vstack([dt * bv, bv])


def _energy(x, k, stiffness, cubic):
    p, v = x[:k], x[k:]
    d = np.diff(np.concatenate([[0.0], p]))
    return 0.5 * v @ v + np.sum(stiffness * d ** 2 / 2 + cubic * d ** 4 / 4)


@pytest.mark.parametrize("k", [1, 2, 5])
def test_the_chain_linearised_at_the_origin_is_the_linear_chain(k):
    ex = exs.mass_chain(k=k, dt=0.05, stiffness=2.0, cubic=3.0, damping=0.2)
    A, B = ex.system.linearize()
    A_ref, B_ref = _linear_chain(k, 0.05, 2.0, 0.2)
    assert ex.system.n == 2 * k and ex.system.m == 1
    assert np.allclose(A, A_ref, rtol=0, atol=1e-14) and np.allclose(B, B_ref, rtol=0, atol=1e-14)
    # away from the origin the cubic term changes the Jacobian: the springs are nonlinear
    A1, _ = ex.system.linearize(x=ex.x0)
    assert np.abs(A1 - A).max() > 1e-3


def test_the_chain_with_no_cubic_term_is_linear_everywhere():
    ex = exs.mass_chain(k=3, cubic=0.0)
    rng = np.random.default_rng(0)
    A, B = _linear_chain(3, 0.1, 1.0, 0.1)
    for _ in range(5):
        x, u, w = rng.normal(size=6), rng.normal(size=1), rng.normal(size=6)
        assert np.allclose(ex.system.step(x, u, w), A @ x + B @ u + w, rtol=0, atol=1e-13)


@pytest.mark.parametrize("k", [1, 3, 12])
def test_the_chain_loses_energy_without_input(k):
    ex = exs.mass_chain(k=k)
    x, E0 = ex.x0.copy(), _energy(ex.x0, k, 1.0, 1.0)
    E = [E0]
    for _ in range(400):
        x = ex.system.step(x, [0.0], np.zeros(2 * k))
        E.append(_energy(x, k, 1.0, 1.0))
    assert E[-1] < 0.5 * E0, "damping dissipates the energy"
    assert max(E) < 1.05 * E0, "no energy is created (up to the integrator's bounded oscillation)"
    undamped = exs.mass_chain(k=k, damping=0.0)
    x = undamped.x0.copy()
    for _ in range(400):
        x = undamped.system.step(x, [0.0], np.zeros(2 * k))
    assert _energy(x, k, 1.0, 1.0) > 0.8 * E0, "without damping the energy stays"


def test_the_chain_force_acts_on_the_last_mass():
    ex = exs.mass_chain(k=4)
    x = np.zeros(8)
    x1 = ex.system.step(x, [1.0], np.zeros(8))
    assert np.allclose(x1[4:], [0, 0, 0, 0.1]) and np.allclose(x1[:4], [0, 0, 0, 0.01])


@pytest.mark.parametrize("kwargs, match", [
    (dict(k=0), "k must be an integer >= 1; got 0"),
    (dict(k=2.0), "k must be an integer; got"),
    (dict(k=10 ** 6), "k must be an integer <= 10000"),
    (dict(dt=0.0), "dt must be > 0"),
    (dict(stiffness=-1.0), "stiffness must be >= 0"),
    (dict(cubic=float("nan")), "cubic must be finite"),
    (dict(damping=-0.1), "damping must be >= 0"),
    (dict(u_max=0.0), "u_max must be > 0"),
])
def test_the_chain_refuses_bad_input_naming_the_argument(kwargs, match):
    with pytest.raises(orrc.OrrcValueError, match=match):
        exs.mass_chain(**kwargs)


def test_the_chain_is_controlled_to_rest_by_the_nonlinear_rhc():
    ex = exs.mass_chain(k=2)
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 15, input_bounds=ex.input_bounds)
    traj = orrc.simulate(ex.system, rhc, ex.x0, np.zeros((60 + 15, 4)), 60)
    assert traj.n_failures == 0
    free = ex.x0.copy()
    for _ in range(60):
        free = ex.system.step(free, [0.0], np.zeros(4))
    assert np.linalg.norm(traj.x[-1]) < 0.5 * np.linalg.norm(free), "control brings the chain to rest faster"


def test_an_sqp_solve_that_stops_without_a_status_is_a_failed_solve_and_ipopt_takes_the_step():
    # on the chain of 10 masses at M = 20, CasADi's SQP stops inside its convexification of the Hessian and
    # leaves no status (reading its statistics raises): the solve is reported failed, not raised, and the
    # controller's ladder solves the step by IPOPT
    ex = exs.mass_chain(k=10)
    M = 20
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    W, P = np.zeros((M, 20)), np.tile(ex.cost.default_params, (M, 1))
    sqp = rhc._nlp.solve(ex.x0, W, P, solver="sqp")
    assert sqp.success or "without a status" in sqp.status
    plan = rhc.plan(ex.x0, W)
    assert plan.success and np.isfinite(plan.value)
    ip = rhc._nlp.solve(ex.x0, W, P, solver="ipopt")
    assert plan.value == pytest.approx(ip.value, rel=1e-6)


def test_the_quadrotor_hovers_at_the_origin_with_zero_input():
    ex = exs.quadrotor()
    assert ex.system.n == 12 and ex.system.m == 4
    assert np.array_equal(ex.system.step(np.zeros(12), np.zeros(4), np.zeros(12)), np.zeros(12))
    # displaced, at rest and level, it stays where it is: the hover holds at any position
    x = np.zeros(12)
    x[:3] = [1.0, -2.0, 0.5]
    assert np.allclose(ex.system.step(x, np.zeros(4), np.zeros(12)), x, rtol=0, atol=1e-15)
    # more thrust lifts it; a level quadrotor does not drift sideways
    up = ex.system.step(np.zeros(12), [1.0, 0, 0, 0], np.zeros(12))
    assert up[5] == pytest.approx(0.05 * 1.0) and np.all(up[[3, 4]] == 0)


def test_the_quadrotor_linearised_at_hover_is_four_chains_of_integrators():
    dt, g, mass, J = 0.04, 9.0, 2.0, np.array([0.03, 0.05, 0.07])
    ex = exs.quadrotor(dt=dt, mass=mass, inertia=J, gravity=g)
    A, B = ex.system.linearize()
    Ac, Bc = np.zeros((12, 12)), np.zeros((12, 4))
    Ac[0:3, 3:6] = np.eye(3)             # ṗ = v
    Ac[3, 7], Ac[4, 6] = g, -g           # pitch tilts the thrust toward +x, roll toward -y
    Ac[6:9, 9:12] = np.eye(3)            # η̇ = ω at level attitude
    Bc[5, 0] = 1 / mass                  # the thrust's deviation lifts
    Bc[9:12, 1:4] = np.diag(1 / J)       # the torques turn
    assert np.allclose(A, np.eye(12) + dt * Ac, rtol=0, atol=1e-14)
    assert np.allclose(B, dt * Bc, rtol=0, atol=1e-14)
    # tilted and turning, the Jacobian is another: the model is nonlinear
    x = np.zeros(12)
    x[6:12] = [0.3, -0.2, 0.5, 1.0, -0.5, 0.2]
    A1, B1 = ex.system.linearize(x=x, u=np.array([1.0, 0, 0, 0]))
    assert np.abs(A1 - A).max() > 1e-2 and np.abs(B1 - B).max() > 1e-3


@pytest.mark.parametrize("kwargs, match", [
    (dict(dt=0.0), "dt must be > 0"),
    (dict(mass=-1.0), "mass must be > 0"),
    (dict(inertia=(0.1, 0.0, 0.1)), r"inertia must be three finite moments of inertia > 0 .* got \(0.1, 0.0, 0.1\)"),
    (dict(inertia=("a", "b", "c")), "inertia must be three finite moments"),
    (dict(inertia=0.1), "inertia must be three finite moments of inertia > 0"),
    (dict(inertia=(0.1, 0.1)), "inertia must be three"),
    (dict(gravity=float("nan")), "gravity must be finite"),
    (dict(thrust_max=0.0), "thrust_max must be > 0"),
    (dict(thrust_max=20.0), r"thrust_max must be below mass·gravity = 9.81 .*got 20"),
    (dict(torque_max=-0.1), "torque_max must be > 0"),
])
def test_the_quadrotor_refuses_bad_input_naming_the_argument(kwargs, match):
    with pytest.raises(orrc.OrrcValueError, match=match):
        exs.quadrotor(**kwargs)
