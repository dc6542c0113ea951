"""SQP's Hessian: the exact Hessian of the Lagrangian or the Gauss-Newton one (the objective's alone), chosen by the
variables per stage for a quadratic stage cost or forced; both reach the same KKT point, the same closed loop, and
their answers pass the same acceptance checks."""
import casadi as ca
import numpy as np
import pytest

import orrc
from orrc.solvers.nlp import ShootingNLP
from orrc.solvers.nlp_solvers import EXACT, GAUSS_NEWTON, GAUSS_NEWTON_FROM

GN = {"sqpmethod.hessian_approximation": GAUSS_NEWTON}
EX = {"sqpmethod.hessian_approximation": EXACT}


def _chain(k, M, **kw):
    ex = orrc.examples.mass_chain(k=k)
    return ex, orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, **kw)


def test_the_hessian_is_chosen_by_the_variables_per_stage_for_a_quadratic_cost():
    small, large = orrc.examples.mass_chain(k=2), orrc.examples.mass_chain(k=GAUSS_NEWTON_FROM // 2)
    assert small.system.n + 1 < GAUSS_NEWTON_FROM <= large.system.n + 1
    a = ShootingNLP(small.system, small.cost, 4, small.input_bounds)
    b = ShootingNLP(large.system, large.cost, 4, large.input_bounds)
    assert a.hessian == EXACT and "hess_lag" not in a.solver_options["sqp"]
    assert b.hessian == GAUSS_NEWTON and "hess_lag" in b.solver_options["sqp"]
    # the cost's Hessian is positive semi-definite: not convexified; the exact one is
    assert "convexify_strategy" not in b.solver_options["sqp"]
    assert a.solver_options["sqp"]["convexify_strategy"] == "eigen-clip"
    # the quadrotor (n + m = 16) takes it too
    quad = orrc.examples.quadrotor()
    assert ShootingNLP(quad.system, quad.cost, 3, quad.input_bounds).hessian == GAUSS_NEWTON


def test_the_choice_is_forced_by_the_keyword_or_the_options():
    ex = orrc.examples.mass_chain(k=1)
    assert ShootingNLP(ex.system, ex.cost, 4, ex.input_bounds, hessian=GAUSS_NEWTON).hessian == GAUSS_NEWTON
    assert ShootingNLP(ex.system, ex.cost, 4, ex.input_bounds, solver_options=GN).hessian == GAUSS_NEWTON
    big = orrc.examples.mass_chain(k=GAUSS_NEWTON_FROM)
    assert ShootingNLP(big.system, big.cost, 3, big.input_bounds, hessian=EXACT).hessian == EXACT
    forced = ShootingNLP(big.system, big.cost, 3, big.input_bounds, solver_options=EX)
    assert forced.hessian == EXACT and forced.solver_options["sqp"]["hessian_approximation"] == "exact"
    # CasADi's own approximation stays CasADi's
    lbfgs = ShootingNLP(ex.system, ex.cost, 4, ex.input_bounds,
                        solver_options={"sqpmethod.hessian_approximation": "limited-memory"})
    assert lbfgs.hessian is None and lbfgs.solver_options["sqp"]["hessian_approximation"] == "limited-memory"


def test_a_non_quadratic_cost_keeps_the_exact_hessian_unless_forced_and_is_then_convexified():
    ex = orrc.examples.mass_chain(k=GAUSS_NEWTON_FROM)
    cost = orrc.Cost(lambda x, u: ca.sumsqr(x) + 0.1 * ca.sumsqr(u) + 0.01 * ca.sumsqr(x) ** 2, ex.system.n,
                     ex.system.m)
    assert ShootingNLP(ex.system, cost, 3, ex.input_bounds).hessian == EXACT
    forced = ShootingNLP(ex.system, cost, 3, ex.input_bounds, hessian=GAUSS_NEWTON)
    assert forced.hessian == GAUSS_NEWTON and forced.solver_options["sqp"]["convexify_strategy"] == "eigen-clip"


@pytest.mark.parametrize("kwargs, match", [
    (dict(hessian="newton"), r"hessian must be one of \('auto', 'exact', 'gauss-newton'\); got 'newton'"),
    (dict(hessian=GAUSS_NEWTON, solver_options=EX), "hessian='gauss-newton' contradicts solver_options"),
    (dict(hessian=GAUSS_NEWTON, solver_options={"sqpmethod.hessian_approximation": "limited-memory"}),
     "hessian='gauss-newton' contradicts"),
])
def test_a_bad_hessian_is_refused_naming_the_argument(kwargs, match):
    ex = orrc.examples.mass_chain(k=1)
    with pytest.raises(orrc.OrrcValueError, match=match):
        ShootingNLP(ex.system, ex.cost, 4, ex.input_bounds, **kwargs)


def test_both_hessians_reach_the_same_kkt_point_and_pass_the_acceptance_checks():
    ex = orrc.examples.mass_chain(k=2)
    M = 12
    W = orrc.disturbances.uniform_ball(M, 4, radius=0.01, seed=1)
    gn = ShootingNLP(ex.system, ex.cost, M, ex.input_bounds, hessian=GAUSS_NEWTON)
    exact = ShootingNLP(ex.system, ex.cost, M, ex.input_bounds, hessian=EXACT)
    ipopt = ShootingNLP(ex.system, ex.cost, M, ex.input_bounds, solvers=("ipopt",))
    P = np.broadcast_to(ex.cost.default_params, (M, ex.cost.n_params))
    a, b, c = (nlp.solve(ex.x0, W, P) for nlp in (gn, exact, ipopt))
    assert a.success and b.success and c.success and a.solver == "sqp"
    # the acceptance checks ran on the Gauss-Newton answer (their quantities are recorded)
    assert {"complementarity", "guess_cost"} <= set(a.extra)
    assert a.value == pytest.approx(b.value, rel=1e-8) and a.value == pytest.approx(c.value, rel=1e-7)
    assert np.allclose(a.inputs, b.inputs, rtol=0, atol=1e-6) and np.allclose(a.states, b.states, rtol=0, atol=1e-6)
    # the dynamics' curvature is dropped: Gauss-Newton takes more, cheaper iterations to the same point
    assert a.iterations >= b.iterations


def test_both_hessians_give_the_same_closed_loop():
    T, M = 25, 12
    ex, gn = _chain(2, M, solver_options=GN)
    _, exact = _chain(2, M, solver_options=EX)
    w = orrc.disturbances.uniform_ball(T + M, 4, radius=0.01, seed=0)
    a, b = orrc.simulate(ex.system, gn, ex.x0, w, T), orrc.simulate(ex.system, exact, ex.x0, w, T)
    assert a.solver_counts == {"sqp": T} and b.solver_counts == {"sqp": T}
    assert a.costs.sum() == pytest.approx(b.costs.sum(), rel=1e-7) and np.allclose(a.x, b.x, rtol=0, atol=1e-6)


def test_the_quadrotor_is_solved_by_gauss_newton_sqp_at_every_step():
    ex = orrc.examples.quadrotor()
    T, M = 15, 10
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    assert rhc.nlp.hessian == GAUSS_NEWTON
    traj = orrc.simulate(ex.system, rhc, ex.x0, np.zeros((T + M, 12)), T)
    assert traj.solver_counts == {"sqp": T}
    assert np.linalg.norm(traj.x[-1][:3]) < np.linalg.norm(ex.x0[:3]), "the quadrotor moves toward the hover point"


def test_the_compiled_gauss_newton_solver_gives_the_interpreted_answers():
    ex, rhc = _chain(1, 6, solver_options=GN)
    _, ref = _chain(1, 6, solver_options=GN)
    if not rhc.compile(wait=True):
        pytest.skip(f"no compiled copy here: {rhc.nlp.compile_error('sqp')}")
    w = orrc.disturbances.uniform_ball(20 + 6, 2, radius=0.01, seed=2)
    a, b = orrc.simulate(ex.system, rhc, ex.x0, w, 20), orrc.simulate(ex.system, ref, ex.x0, w, 20)
    assert a.solver_counts == b.solver_counts == {"sqp": 20}
    assert np.array_equal(a.u, b.u) and np.array_equal(a.iterations, b.iterations)
