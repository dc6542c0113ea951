"""The default NLP solver (CasADi's sqpmethod + qrqp, orrc.solvers.nlp) reaches IPOPT's optimum.

How close two solvers' answers must be follows from their stopping criteria. Each stops at an
approximate KKT point: the residual F = (∇_z L, g, z_A − b_A) of the KKT system (stationarity of the
Lagrangian, the dynamics, the active bounds) is small (SQP: ∞-norms below 1e-8; IPOPT: its scaled
error below 1e-9). Near a nondegenerate local minimum (LICQ, strict complementarity, second-order
sufficiency; the same active set A for both) the KKT map is invertible with ‖K⁻¹‖₂ = κ, so two such
points differ by ‖Δ(z, λ)‖₂ ≤ κ (‖F_a‖₂ + ‖F_b‖₂) to first order (we allow a factor 2 for the
second-order terms), and their objectives, by a Taylor expansion of the Lagrangian L_b of one of them,
by |J_a − J_b| ≤ ‖∇L_b(z_b)‖₂ ‖Δz‖₂ + ½ ‖∇²L_b‖₂ ‖Δz‖₂² + ‖λ_b‖₂ ‖(g, z_A − b_A)_a − (g, z_A − b_A)_b‖₂.
The tests compute every quantity (κ, the residuals, the multipliers) from the transcription itself,
assert that each solver's residual is within its tolerance, and that the answers agree within the
bounds they imply (and to 1e-6 relative in J).
"""
import warnings

import casadi as ca
import numpy as np
import pytest

import orrc
from orrc.solvers.nlp import ACCEPT_RTOL, DEFAULT_SQP
from runs import pendulum_case, same_runs


def _kkt(rhc, x, W, P, plan, active=None):
    """The KKT residual F (stacked) of ``plan`` and, at it, the KKT matrix pieces; ``active``: the
    active bounds (indices, signs) to use (default: those of this plan)."""
    nlp = rhc._nlp
    prob = nlp.problem
    z, p = prob["x"], prob["p"]
    lg, lx = ca.SX.sym("lg", prob["g"].shape[0]), ca.SX.sym("lx", z.shape[0])
    L = prob["f"] + ca.dot(lg, prob["g"]) + ca.dot(lx, z)
    H, _ = ca.hessian(L, z)
    fn = ca.Function("kkt", [z, p, lg, lx], [ca.gradient(L, z), prob["g"], H, ca.jacobian(prob["g"], z), prob["f"]])
    zv = np.concatenate([plan.inputs.ravel(), plan.states[1:].ravel()])
    pv = np.concatenate([x, W.ravel(), P.ravel()])
    lam_x, lam_g = plan.extra["lam_x"], plan.extra["lam_g"]
    if active is None:
        on = np.flatnonzero((np.abs(lam_x) > 1e-7 * max(1.0, np.abs(lam_x).max()))
                            & ((np.abs(zv - nlp.lbz) < 1e-6) | (np.abs(zv - nlp.ubz) < 1e-6)))
        active = (on, np.where(np.abs(zv[on] - nlp.ubz[on]) < 1e-6, nlp.ubz[on], nlp.lbz[on]))
    on, bound = active
    lam_A = np.zeros_like(lam_x)
    lam_A[on] = lam_x[on]
    grad, g, Hv, Jv, f = (np.asarray(v) for v in fn(zv, pv, lam_g, lam_A))
    F = np.concatenate([grad.ravel(), g.ravel(), zv[on] - bound])
    return dict(F=F, z=zv, f=float(f.ravel()[0]), H=Hv, J=Jv, lam=np.concatenate([lam_g, lam_x[on]]),
                con=np.concatenate([g.ravel(), zv[on] - bound]), active=active, grad=grad.ravel(),
                dual_inf=np.abs(np.asarray(fn(zv, pv, lam_g, lam_x)[0])).max(), primal_inf=np.abs(g).max())


def _agreement(rhc_sqp, rhc_ipopt, x, W, P=None):
    a, b = rhc_sqp.plan(x, W, P), rhc_ipopt.plan(x, W, P)
    P = np.broadcast_to(rhc_sqp.cost.default_params, (rhc_sqp.M, rhc_sqp.cost.n_params)) if P is None else P
    assert a.success and b.success and a.solver == "sqp" and b.solver == "ipopt"
    kb = _kkt(rhc_ipopt, x, W, P, b)
    ka = _kkt(rhc_sqp, x, W, P, a, active=kb["active"])
    # each solver stopped within its own tolerance (SQP: ∞-norms 1e-8, as sqpmethod measures them)
    assert ka["dual_inf"] <= DEFAULT_SQP["tol_du"] and ka["primal_inf"] <= DEFAULT_SQP["tol_pr"]
    # IPOPT stops at 1e-9 on its scaled problem (objective and multipliers scaled by up to ~100 here)
    assert kb["dual_inf"] <= 1e-7 and kb["primal_inf"] <= 1e-9
    on = kb["active"][0]
    Jc = kb["J"]
    E = np.zeros((len(on), len(kb["z"])))
    E[np.arange(len(on)), on] = 1.0
    C = np.vstack([Jc, E])
    K = np.block([[kb["H"], C.T], [C, np.zeros((len(C), len(C)))]])
    kappa = 1.0 / np.linalg.svd(K, compute_uv=False).min()
    dz_bound = 2 * kappa * (np.linalg.norm(ka["F"]) + np.linalg.norm(kb["F"]))
    dz = np.linalg.norm(ka["z"] - kb["z"])
    assert dz <= dz_bound
    dJ_bound = (np.linalg.norm(kb["F"][:len(kb["z"])]) * dz_bound + 0.5 * np.linalg.norm(kb["H"], 2) * dz_bound ** 2
                + np.linalg.norm(kb["lam"]) * np.linalg.norm(ka["con"] - kb["con"]))
    assert abs(ka["f"] - kb["f"]) <= dJ_bound
    # the stopping criteria imply agreement to 1e-6 relative, and it holds
    assert dJ_bound <= 1e-6 * abs(b.value) and abs(a.value - b.value) <= 1e-6 * abs(b.value)
    return dict(dz=dz, dz_bound=dz_bound, dJ=abs(a.value - b.value), dJ_bound=dJ_bound, kappa=kappa)


def _pair(system, cost, M, bounds):
    return (orrc.PreviewRHC(system, cost, M, input_bounds=bounds, solver="sqp"),
            orrc.PreviewRHC(system, cost, M, input_bounds=bounds, solver="ipopt"))


@pytest.mark.parametrize("theta0", [0.2, 0.5, 1.0])
def test_sqp_and_ipopt_reach_the_same_pendulum_optimum(theta0):
    """The benchmark's problem (M = 20, |u| <= 20, the sinusoidal preview): the same optimum."""
    ex = orrc.examples.inverted_pendulum()
    W = orrc.disturbances.sinusoid(21, 2, amplitude=0.02, period=15.0)[:20]
    _agreement(*_pair(ex.system, ex.cost, 20, ex.input_bounds), np.array([theta0, 0.0]), W)


@pytest.mark.parametrize("x0", [[1.5, 0.0], [-2.0, 1.0], [0.5, -2.5]])
def test_sqp_and_ipopt_reach_the_same_van_der_pol_optimum(x0):
    ex = orrc.examples.van_der_pol()
    W = orrc.disturbances.uniform_ball(15, 2, radius=0.05, seed=1)
    _agreement(*_pair(ex.system, ex.cost, 15, ex.input_bounds), np.array(x0), W)


def _nonconvex():
    """c_t(x, u) = p_t (1 − cos θ) + ω² + 0.1 u²: non-convex in θ, time-varying through p_t."""
    return orrc.Cost(lambda x, u, p: p[0] * (1 - ca.cos(x[0])) + x[1] ** 2 + 0.1 * u[0] ** 2,
                     n=2, m=1, n_params=1, default_params=[5.0], name="1 - cos")


@pytest.mark.parametrize("x0", [[2.5, 0.0], [np.pi - 0.3, 0.0], [3.0, 0.0], [-1.0, 3.0]])
def test_sqp_and_ipopt_reach_the_same_optimum_of_a_nonconvex_time_varying_cost(x0):
    """From states where the Hessian of the Lagrangian is indefinite (|θ| > π/2: the cost's curvature
    cos θ < 0). At (3, 0) SQP without convexification stops at a worse stationary point (800.0 against
    IPOPT's 758.1) that no check can tell from a local optimum; with it, SQP finds IPOPT's."""
    ex = orrc.examples.inverted_pendulum()
    M = 20
    P = (20 * (1 + 0.5 * np.sin(np.arange(M) / 7.0)))[:, None]
    W = orrc.disturbances.uniform_ball(M, 2, radius=0.02, seed=0)
    _agreement(*_pair(ex.system, _nonconvex(), M, ex.input_bounds), np.array(x0), W, P)


def test_an_sqp_answer_worse_than_its_initial_guess_is_rejected_and_ipopt_takes_the_step():
    """From (θ, ω) = (2, 2) SQP converges, and says so, to a stationary point costing 821.1, while the
    cold start's own inputs (zero torque) cost 803.2: the acceptance check rejects it, and on the default
    path IPOPT solves the step (800.6). Without the Hessian's convexification SQP lands on the same point."""
    ex = orrc.examples.inverted_pendulum()
    M, x, W, P = 20, np.array([2.0, 2.0]), np.zeros((20, 2)), np.full((20, 1), 20.0)
    for opts in ({}, {"sqpmethod.convexify_strategy": "none"}):
        alone = orrc.PreviewRHC(ex.system, _nonconvex(), M, input_bounds=ex.input_bounds, solver="sqp",
                                solver_options=opts)
        with pytest.warns(orrc.SolverWarning, match="rejected: objective 821.1"):
            plan = alone.plan(x, W, P)
        assert not plan.success and plan.status.startswith("rejected: objective") and "803.2" in plan.status
        assert plan.value > plan.extra["guess_cost"] * (1 + ACCEPT_RTOL)
        ladder = orrc.PreviewRHC(ex.system, _nonconvex(), M, input_bounds=ex.input_bounds, solver_options=opts)
        rescued = ladder.plan(x, W, P)
        assert rescued.success and rescued.solver == "ipopt" and rescued.value < plan.extra["guess_cost"]
        assert rescued.status.startswith("IPOPT cold start: Solve_Succeeded (after SQP cold start: rejected")
        assert rescued.value == pytest.approx(800.598, abs=1e-3)


def _pendulum_answer():
    """An SQP answer of the pendulum at M = 5 from (0.3, 0): (the NLP, its plan, z, p)."""
    ex = orrc.examples.inverted_pendulum()
    nlp = orrc.PreviewRHC(ex.system, ex.cost, 5, input_bounds=ex.input_bounds, solver="sqp")._nlp
    x, W = np.array([0.3, 0.0]), np.zeros((5, 2))
    P = np.broadcast_to(ex.cost.default_params, (5, ex.cost.n_params))
    plan = nlp.solve(x, W, P)
    return nlp, plan, np.concatenate([plan.inputs.ravel(), plan.states[1:].ravel()]), \
        np.concatenate([x, W.ravel(), P.ravel()])


def test_bound_multipliers_on_the_wrong_side_are_rejected():
    """The complementarity check, on a fabricated answer: a multiplier pushing against an inactive
    bound (or an absent one) is no KKT point, whatever sqpmethod's stationarity test says."""
    nlp, plan, z, p = _pendulum_answer()
    assert plan.success and plan.extra["complementarity"] <= 1e-12
    res = [z, np.array([plan.value]), np.zeros(10), plan.extra["lam_x"].copy(), plan.extra["lam_g"], None]
    assert nlp._rejection(res, z, plan.value, p, plan.inputs, {}) is None
    res[3][4] = 1.0  # u_4 is inside (-20, 20): a multiplier on its upper bound is wrong
    assert "not complementary" in nlp._rejection(res, z, plan.value, p, plan.inputs, {})
    res[3][4], res[3][7] = 0.0, -1.0  # a state has no bounds at all: Σ λ·gap is infinite
    assert "not complementary" in nlp._rejection(res, z, plan.value, p, plan.inputs, {})


def test_warm_start_from_the_shifted_plan_needs_no_more_iterations_than_a_cold_start():
    """Along a closed loop, each warm-started SQP solve (the controller's) against a cold solve of the
    same step: never more iterations in total, and the same optimum."""
    ex = orrc.examples.inverted_pendulum()
    T, M = 40, 20
    w = orrc.disturbances.uniform_ball(T + M, 2, radius=0.02, seed=0)
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    warm = orrc.simulate(ex.system, rhc, ex.x0, w, T)
    assert warm.solver_counts == {"sqp": T} and warm.n_failures == 0
    cold = [rhc.plan(warm.x[t], warm.w_all[t:t + M]) for t in range(T)]
    assert warm.iterations.sum() <= sum(p.iterations for p in cold)
    np.testing.assert_allclose(warm.values, [p.value for p in cold], rtol=1e-7)


@pytest.mark.parametrize("case", ["accepted", "ipopt rescues", "steps fail", "time-varying cost"])
def test_the_warm_sqp_loop_is_the_controllers_own_closed_loop(case):
    """orrc.simulate takes the common step of PreviewRHC (SQP from the shifted plan, accepted) in a loop of
    its own (orrc._fast_loops.nlp_loop) and every other step through control(): the run is bit for bit the
    one control() makes at every step, also where SQP fails and IPOPT or the fallback takes the step."""
    system, cost, kw, x0, w, costs = pendulum_case(case)
    runs = []
    for general in (False, True):
        rhc = orrc.PreviewRHC(system, cost, **kw)
        if general:
            rhc.control = rhc.control   # replaced on the object: every step through control()
        assert (rhc.fast_nlp() is None) == general
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", orrc.SolverWarning)
            runs.append(orrc.simulate(system, rhc, x0, w, 40, costs=costs))
    same_runs(*runs)
    fast = runs[0]
    if case in ("accepted", "time-varying cost"):
        assert fast.n_failures == 0 and fast.solver_counts == {"sqp": 40}
    elif case == "ipopt rescues":
        assert fast.n_failures == 0 and 0 < fast.solver_counts.get("ipopt", 0) < 40, fast.solver_counts
    else:
        assert 0 < fast.n_failures < 40, fast.n_failures


def test_a_controller_that_stops_inside_the_warm_sqp_loop_hands_back_the_same_run():
    """A step that fails inside the warm SQP loop goes to the failure ladder; with max_failures=1 the
    controller stops there, and the run handed back with the SolverError is the one control() makes."""
    ex = orrc.examples.inverted_pendulum()
    w = 30 * orrc.disturbances.uniform_ball(80, 2, radius=0.02, seed=0)
    stopped = []
    for general in (False, True):
        rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=(-1, 1), max_failures=1, solver="sqp",
                              solver_options={"sqpmethod.max_iter": 3})
        if general:
            rhc.control = rhc.control
        with pytest.raises(orrc.SolverError) as err:
            orrc.simulate(ex.system, rhc, np.array([3.0, 0.0]), w, 40)
        stopped.append(err.value)
    assert stopped[0].step == stopped[1].step > 1, "the controller stops at the same step, after warm steps"
    same_runs(stopped[0].trajectory, stopped[1].trajectory)


@pytest.mark.parametrize("read", ["every second step", "every step (error_on_fail off)",
                                  "every step (counters not accumulating)"])
def test_the_recorded_iteration_counts_are_the_solvers_whichever_way_they_are_read(read):
    """The warm loop reads the solver's statistics at every second accepted step and splits n_call_QP
    between the two solves (one QP per SQP iteration; orrc.solvers.warm_sqp), once it has seen that the
    buffer's counters accumulate; with error_on_fail off, or counters that do not accumulate, it reads
    them at every step. Each way, with failed steps among the accepted ones, the run (iteration counts and
    statuses included) is the one control() makes, which reads the statistics of every solve."""
    ex = orrc.examples.inverted_pendulum()
    w = 30 * orrc.disturbances.uniform_ball(80, 2, radius=0.02, seed=0)
    opts = {"sqpmethod.max_iter": 3}
    if read.startswith("every step (error"):
        opts["sqpmethod.error_on_fail"] = False
    runs = []
    for general in (False, True):
        rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=(-1, 1), max_failures=None, solver="sqp",
                              solver_options=opts)
        buffer = rhc._nlp._call("sqp")
        if general:
            rhc.control = rhc.control
        elif read.endswith("not accumulating)"):
            buffer.counts_accumulate = False   # as a CasADi whose buffer resets its counters would be found
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", orrc.SolverWarning)
            runs.append(orrc.simulate(ex.system, rhc, np.array([2.0, 0.0]), w, 40))
        if not general:
            assert buffer.counts_accumulate is {"every second step": True, "every step (error_on_fail off)": None,
                                                "every step (counters not accumulating)": False}[read]
    same_runs(*runs)
    fast = runs[0]
    assert 0 < fast.n_failures < 30 and fast.iterations[fast.success].min() >= 1, fast.n_failures


def test_an_unsuccessful_sqp_solve_reads_the_same_with_error_on_fail():
    """orrc's SQP solver raises on an unsuccessful solve (error_on_fail, so that the closed loop knows a
    success without the statistics); ShootingNLP.solve reports such a solve as it did without the option:
    its status, iterations and last iterate."""
    ex = orrc.examples.inverted_pendulum()
    x, W = np.array([1.0, 0.0]), np.zeros((10, 2))
    P = np.broadcast_to(ex.cost.default_params, (10, ex.cost.n_params))
    plans = []
    for raises in (True, False):
        rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds, solver="sqp",
                              solver_options={"sqpmethod.max_iter": 1, "sqpmethod.error_on_fail": raises})
        assert rhc._nlp.solver_options["sqp"]["error_on_fail"] is raises
        plans.append(rhc._nlp.solve(x, W, P))
    a, b = plans
    assert not a.success and a.status == b.status == "Maximum_Iterations_Exceeded" and a.iterations == 1
    assert np.array_equal(a.inputs, b.inputs) and a.value == b.value and np.isfinite(a.value)


def test_the_compiled_verdict_is_the_acceptance_checks_own():
    """The warm loop accepts an answer on the verdict of the compiled acceptance function; it is that of
    rejection() on the same quantities, with J and z finite (a non-finite z is caught: CasADi would
    simplify the x * 0 of a naive finiteness test to 0)."""
    nlp, plan, z, p = _pendulum_answer()
    check = nlp._call("acceptance-copy")
    cases = []
    for change in ("none", "wrong-side multiplier", "multiplier on no bound", "worse than the guess", "NaN state"):
        zc, lam_x, value = z.copy(), plan.extra["lam_x"].copy(), plan.value
        if change == "wrong-side multiplier":
            lam_x[4] = 1.0
        elif change == "multiplier on no bound":
            lam_x[7] = -1.0
        elif change == "worse than the guess":
            value = 10 * plan.value + 1.0
        elif change == "NaN state":
            zc[-1] = np.nan
        res = [zc, np.array([value]), np.zeros(10), lam_x, plan.extra["lam_g"], None]
        reason = nlp._rejection(res, zc, value, p, plan.inputs, {})
        q = check.res[0]
        assert q[6] == float(reason is None and np.isfinite(value) and q[5] == 1.0), change
        assert q[5] == float(change != "NaN state"), change
        cases.append(q[6])
    assert cases == [1.0, 0.0, 0.0, 0.0, 0.0]
