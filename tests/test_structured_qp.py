"""SQP's QP solver chosen by the horizon: HPIPM (a Riccati recursion, the NLP's variables in stage order) from
``HPIPM_FROM`` on, qrqp below it or where the options name a QP solver; the same answers either way."""
import numpy as np
import pytest

import orrc
from orrc.solvers.nlp_solvers import HPIPM_FROM

QRQP = {"sqpmethod.qpsol": "qrqp",
        "sqpmethod.qpsol_options": {"print_iter": False, "print_header": False, "print_info": False}}


def _pendulum(M, **kw):
    ex = orrc.examples.inverted_pendulum()
    return ex, orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, **kw)


def test_the_qp_solver_is_chosen_by_the_horizon_unless_the_options_name_one():
    below, at = _pendulum(HPIPM_FROM - 1)[1]._nlp, _pendulum(HPIPM_FROM)[1]._nlp
    assert below.solver_options["sqp"]["qpsol"] == "qrqp" and not below.stage_order
    assert at.solver_options["sqp"]["qpsol"] == "hpipm" and at.stage_order
    assert at.solver_options["sqp"]["qpsol_options"]["N"] == HPIPM_FROM
    assert at.solver_options["sqp"]["qpsol_options"]["hpipm"] == {"mode": "speed"}   # chosen here: its speed mode
    named = _pendulum(HPIPM_FROM, solver_options=QRQP)[1]._nlp
    assert named.solver_options["sqp"]["qpsol"] == "qrqp" and not named.stage_order
    asked = _pendulum(5, solver_options={"sqpmethod.qpsol": "hpipm"})[1]._nlp   # HPIPM asked for at any size
    assert asked.stage_order and asked.solver_options["sqp"]["qpsol_options"]["nx"] == [0] + [2] * 5


def test_hpipm_and_qrqp_give_the_same_plan_and_closed_loop():
    M, T = HPIPM_FROM, 25
    ex, rhc = _pendulum(M)
    _, ref = _pendulum(M, solver_options=QRQP)
    w = orrc.disturbances.uniform_ball(T + M, 2, radius=0.02, seed=0)
    p, q = rhc.plan(ex.x0, w[:M]), ref.plan(ex.x0, w[:M])
    assert p.success and p.solver == "sqp" and q.success
    assert p.value == pytest.approx(q.value, rel=1e-8)
    assert np.allclose(p.inputs, q.inputs, rtol=0, atol=1e-6) and np.allclose(p.states, q.states, rtol=0, atol=1e-6)
    # the stage-ordered answer is the plan: its states are the rollout of its inputs
    x = ex.x0
    for j in range(M):
        x = ex.system.step(x, p.inputs[j], w[j])
        assert np.allclose(p.states[j + 1], x, rtol=0, atol=1e-7)
    warm = rhc.plan(p.states[1], w[1:M + 1], warm_start=p)   # the solve path with a shifted guess
    assert warm.success and warm.value == pytest.approx(ref.plan(p.states[1], w[1:M + 1]).value, rel=1e-8)
    a, b = orrc.simulate(ex.system, rhc, ex.x0, w, T), orrc.simulate(ex.system, ref, ex.x0, w, T)
    assert a.solver_counts == {"sqp": T} and b.solver_counts == {"sqp": T}
    assert a.costs.sum() == pytest.approx(b.costs.sum(), rel=1e-8) and np.allclose(a.x, b.x, rtol=0, atol=1e-7)


def test_stage_order_keeps_the_state_bounds_and_the_acceptance_checks():
    ex = orrc.examples.mass_chain(k=2)
    M, bounds = HPIPM_FROM, (np.array([-0.45, -np.inf, -1, -1]), np.array([0.45, np.inf, 1, 1]))
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, state_bounds=bounds)
    ref = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, state_bounds=bounds,
                          solver_options=QRQP)
    assert rhc._nlp.stage_order and not ref._nlp.stage_order
    x0 = np.array([0.4, 0.4, 0.0, 0.0])
    W = np.zeros((M, 4))
    p, q = rhc.plan(x0, W), ref.plan(x0, W)
    assert p.success and p.solver == "sqp" and p.value == pytest.approx(q.value, rel=1e-7)
    assert p.states[1:, 0].max() <= 0.45 + 1e-8, "the state bound holds in stage order"
    # an answer worse than the guess's rollout is rejected in stage order as in the other order
    nlp, P = rhc._nlp, np.tile(ex.cost.default_params, (M, 1))
    good = nlp.solve(x0, W, P, solver="sqp")
    z = np.empty(M * 5)
    z[nlp.iu], z[nlp.ix] = good.inputs.reshape(-1), good.states[1:].reshape(-1)
    p_vec = np.concatenate([x0, W.reshape(-1), P.reshape(-1)])
    res = [z, np.array([good.value]), np.zeros(M * 4), good.extra["lam_x"], good.extra["lam_g"]]
    extra = {}
    assert nlp._rejection(res, z, good.value, p_vec, good.inputs, extra) is None
    reason = nlp._rejection(res, z, good.value + 10.0, p_vec, good.inputs, extra)
    assert reason is not None and "above the cost" in reason


def test_the_compiled_solver_in_stage_order_gives_the_interpreted_closed_loop():
    M, T = HPIPM_FROM, 15
    ex, rhc = _pendulum(M)
    _, interp = _pendulum(M)
    w = orrc.disturbances.uniform_ball(T + M, 2, radius=0.02, seed=1)
    if not rhc.compile(wait=True):
        pytest.skip(f"no compiled copy on this machine: {rhc.compile_error()}")
    a, b = orrc.simulate(ex.system, rhc, ex.x0, w, T), orrc.simulate(ex.system, interp, ex.x0, w, T)
    assert interp._nlp.compiled("sqp") is None, "the reference stays interpreted"
    assert a.solver_counts == {"sqp": T} and np.array_equal(a.x, b.x) and np.array_equal(a.u, b.u)


def test_an_hpipm_answer_not_complementary_is_polished_by_qrqp_and_kept_to_the_check():
    from orrc.solvers.acceptance import ACCEPT_ATOL, ACCEPT_RTOL
    from orrc.solvers.nlp import ShootingNLP

    ex = orrc.examples.mass_chain(k=1)
    M = HPIPM_FROM
    P = np.broadcast_to(ex.cost.default_params, (M, ex.cost.n_params))
    nlp = ShootingNLP(ex.system, ex.cost, M, ex.input_bounds)
    ref = ShootingNLP(ex.system, ex.cost, M, ex.input_bounds, solvers=("ipopt",))
    x = np.array([0.1, 0.0])   # near rest: a small optimal cost, below HPIPM's complementarity over 1e-8
    plan = nlp.solve(x, np.zeros((M, 2)), P)
    assert plan.success and plan.solver == "sqp" and "qrqp" in plan.extra["polished"]
    # the check is the same: the polished multipliers pass it
    assert plan.extra["complementarity"] <= ACCEPT_RTOL * abs(plan.value) + ACCEPT_ATOL
    assert plan.value == pytest.approx(ref.solve(x, np.zeros((M, 2)), P).value, rel=1e-7)
    xs = x
    for j in range(M):   # the polished answer is a plan: its states are the rollout of its inputs
        xs = ex.system.step(xs, plan.inputs[j], np.zeros(2))
        assert np.allclose(plan.states[j + 1], xs, rtol=0, atol=1e-8)
