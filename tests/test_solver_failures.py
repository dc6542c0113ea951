"""Solver faults stay contained: the escalation policy of orrc.controllers.failures, one SolverWarning
per run, failed steps marked in the trajectory, and the checks refusing them.

The forced-failure run: the pendulum (M = 20) over T = 200 with every solver limited to one
iteration: on the default NLP path (SQP, then IPOPT) ``FORCED_FAILURE`` (sqpmethod.max_iter = 1,
ipopt.max_iter = 1), and with ``solver="ipopt"`` alone ``ipopt.max_iter = 1``. The semantics
are the same for both: the ladder's rungs are tried, the step falls back, the run stops or warns once.
"""
import warnings

import numpy as np
import pytest

import orrc
from conftest import FORCED_FAILURE
from orrc.controllers.failures import LAST_ITERATE, SHIFTED, FailureLadder
from orrc.solvers import Plan

T = 200

#: (solver, options that make it fail, the status of a failed cold step)
FORCED = {
    "nlp": ("nlp", FORCED_FAILURE, "SQP cold start: Maximum_Iterations_Exceeded; IPOPT cold start: "
                                   "Maximum_Iterations_Exceeded"),
    "ipopt": ("ipopt", {"ipopt.max_iter": 1}, "Maximum_Iterations_Exceeded"),
}


@pytest.fixture(scope="module")
def pendulum():
    ex = orrc.examples.inverted_pendulum()
    w = orrc.disturbances.uniform_ball(L=T + 20, n=2, radius=0.02, seed=0)
    return ex, w


def _forced(ex, M=20, path="nlp", **kw):
    solver, options, _ = FORCED[path]
    return orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, solver=solver,
                           solver_options=options, **kw)


def _run(*args, **kwargs):
    """simulate(...) and every warning it emitted (each emission counted: the "always" filter)."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        traj = orrc.simulate(*args, **kwargs)
    return traj, [r for r in rec if issubclass(r.category, orrc.SolverWarning)], rec


@pytest.mark.parametrize("path", sorted(FORCED))
def test_forced_failure_run_stops_with_a_solver_error_naming_the_step_and_what_to_try(pendulum, path):
    ex, w = pendulum
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        with pytest.raises(orrc.SolverError) as info:
            orrc.simulate(ex.system, _forced(ex, path=path), ex.x0, w, T)
    err = info.value
    assert isinstance(err, RuntimeError)
    assert err.step == 2 and err.statuses == [FORCED[path][2]] * 3  # the default max_failures = 3
    msg = str(err)
    for words in ("t=2", "3 consecutive", "t=0..2", "Maximum_Iterations_Exceeded", "ipopt.max_iter",
                  "sqpmethod.max_iter", "max_failures=None"):
        assert words in msg
    if path == "nlp":  # the message names the rungs each step tried
        assert "each step tried SQP cold start, then IPOPT cold start" in msg
    assert not [r for r in rec if issubclass(r.category, orrc.SolverWarning)]  # the error is the report
    part = err.trajectory  # the run up to the step before, its failed steps marked
    assert isinstance(part, orrc.Trajectory) and part.T == 2 and part.x.shape == (3, 2)
    assert part.n_failures == 2 and not part.success.any()
    assert np.isnan(part.values).all() and not part.value_valid.any()
    assert part.fallback == [LAST_ITERATE, LAST_ITERATE]


@pytest.mark.parametrize("path", sorted(FORCED))
def test_forced_failure_run_without_a_stop_ends_with_exactly_one_solver_warning(pendulum, path):
    ex, w = pendulum
    good = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 20, input_bounds=ex.input_bounds),
                         ex.x0, w, T)
    assert good.n_failures == 0 and good.value_valid.all()
    traj, solver_warnings, _ = _run(ex.system, _forced(ex, path=path, max_failures=None), ex.x0, w, T)
    assert len(solver_warnings) == 1  # not one per step, and a SolverWarning, not a RuntimeWarning
    msg = str(solver_warnings[0].message)
    assert f"{T} of {T} steps" in msg and f"t = 0-{T - 1}" in msg and "Maximum_Iterations_Exceeded" in msg
    assert f"{LAST_ITERATE} ({T} steps)" in msg
    assert traj.n_failures == T and not traj.success.any()
    assert np.isnan(traj.values).all() and not traj.value_valid.any()
    assert traj.fallback == [LAST_ITERATE] * T
    assert traj.solver == ["ipopt"] * T  # the last solver tried: its iterate is what was applied
    # no compounding: every step starts cold from the measured state (there is no successful plan to
    # warm-start from), so no failed plan is replayed open loop (before the fix: cost 642,615, |θ| 34 rad)
    assert np.abs(traj.x[:, 0]).max() < 1.0 and traj.costs.sum() < 2 * good.costs.sum()


def test_forced_failure_warning_under_pytests_own_filters(pendulum):
    ex, w = pendulum
    with pytest.warns(orrc.SolverWarning, match=r"the solve failed at 30 of 30 steps") as rec:
        orrc.simulate(ex.system, _forced(ex, max_failures=None), ex.x0, w, 30)
    assert len([r for r in rec if issubclass(r.category, orrc.SolverWarning)]) == 1


class _Failing:
    """Make the NLP solves of ``rhc`` report failure at chosen steps (``steps``), for every rung
    (``rung=None``) or only for the warm-started one (``rung="warm"``); records the guesses."""

    def __init__(self, rhc, steps, rung=None, solvers=("sqp", "ipopt")):
        self.rhc, self.steps, self.rung, self.solvers = rhc, set(steps), rung, solvers
        self.t, self.guesses, self.plans = None, {}, {}
        real_solve, real_control = rhc._nlp.solve, rhc.control

        def solve(x, W, P, guess_U=None, guess_X=None, solver=None, theta=None):
            plan = real_solve(x, W, P, guess_U, guess_X, solver=solver, theta=theta)
            self.guesses.setdefault(self.t, []).append(None if guess_U is None else guess_U.copy())
            warm = guess_U is not None
            if self.t in self.steps and (self.rung is None or warm) and plan.solver in self.solvers:
                plan.success, plan.status = False, "forced failure"
            elif plan.success:
                self.plans[self.t] = plan
            return plan

        def control(obs):
            self.t = obs.t
            return real_control(obs)

        rhc._nlp.solve, rhc.control = solve, control


def test_an_isolated_failure_is_ridden_out_on_the_previous_plan_shifted(pendulum):
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    spy = _Failing(rhc, steps=[5])
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 20)
    assert traj.failed_steps.tolist() == [5] and traj.fallback[5] == SHIFTED
    assert traj.status[5] == ("SQP warm start: forced failure; SQP cold start: forced failure; "
                              "IPOPT warm start: forced failure")
    np.testing.assert_array_equal(traj.u[5], spy.plans[4].inputs[1])  # the plan of t=4, one step on
    # the next warm start is the last SUCCESSFUL plan (t=4) shifted by two, not the failed iterate
    np.testing.assert_array_equal(spy.guesses[6][0][:8], spy.plans[4].inputs[2:])
    assert len(solver_warnings) == 1
    msg = str(solver_warnings[0].message)
    assert "1 of 20 steps (t = 5;" in msg and f"{SHIFTED} (1 step)" in msg
    assert np.isnan(traj.values[5]) and traj.value_valid.sum() == 19


def test_a_cold_retry_rescues_a_bad_warm_start_and_is_no_failure(pendulum):
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    spy = _Failing(rhc, steps=[3, 4, 5, 6], rung="warm")
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 12)
    assert traj.n_failures == 0 and not solver_warnings
    assert [g is None for g in spy.guesses[4]] == [False, True]  # warm start tried, then the cold retry
    assert traj.status[4] == "SQP cold start: Solve_Succeeded (after SQP warm start: forced failure)"
    assert traj.value_valid.all() and traj.solver[4] == "sqp"


def test_when_sqp_fails_ipopt_takes_the_step_and_the_trajectory_says_so(pendulum):
    """The IPOPT rung of the default NLP path: SQP forced to fail at some steps (every SQP rung), IPOPT
    solves them; no step fails, and Trajectory.solver / status name the solver of each step."""
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    _Failing(rhc, steps=[0, 4, 5], solvers=("sqp",))
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 12)
    assert traj.n_failures == 0 and not solver_warnings and traj.value_valid.all()
    assert [t for t, s in enumerate(traj.solver) if s == "ipopt"] == [0, 4, 5]
    assert traj.solver_counts == {"sqp": 9, "ipopt": 3}
    assert traj.status[0] == "IPOPT cold start: Solve_Succeeded (after SQP cold start: forced failure)"
    assert traj.status[4] == ("IPOPT warm start: Solve_Succeeded (after SQP warm start: forced failure; "
                              "SQP cold start: forced failure)")
    ipopt = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds,
                                                     solver="ipopt"), ex.x0, w, 12)
    # the same run as IPOPT alone, up to both solvers' tolerances (1e-8 SQP, 1e-9 IPOPT: see test_sqp.py)
    np.testing.assert_allclose(traj.u, ipopt.u, rtol=0, atol=1e-6)


def test_sqp_limited_to_one_iteration_falls_back_to_ipopt_and_reports_it(pendulum):
    """The real thing, not a spy: sqpmethod.max_iter = 1 leaves most steps unconverged; IPOPT takes them."""
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 20, input_bounds=ex.input_bounds,
                          solver_options={"sqpmethod.max_iter": 1})
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 40)
    assert traj.n_failures == 0 and not solver_warnings
    counts = traj.solver_counts
    assert set(counts) <= {"sqp", "ipopt"} and counts["ipopt"] >= 30
    for t, s in enumerate(traj.solver):
        if s == "ipopt":
            assert traj.status[t].startswith("IPOPT") and "SQP cold start: Maximum_Iterations_Exceeded" in traj.status[t]


def test_consecutive_failures_up_to_max_failures_stop_the_run(pendulum):
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds, max_failures=2)
    _Failing(rhc, steps=[3, 4])
    with pytest.raises(orrc.SolverError, match=r"stopped at step t=4.*t=3\.\.4; max_failures=2") as info:
        orrc.simulate(ex.system, rhc, ex.x0, w, 20)
    assert info.value.step == 4 and info.value.statuses == [
        "SQP warm start: forced failure; SQP cold start: forced failure; IPOPT warm start: forced failure"] * 2
    assert info.value.trajectory.success.tolist() == [True, True, True, False]


def test_failures_that_do_not_persist_do_not_stop_the_run(pendulum):
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds, max_failures=2)
    _Failing(rhc, steps=[3, 5, 7])
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 12)
    assert traj.failed_steps.tolist() == [3, 5, 7] and len(solver_warnings) == 1
    assert "3 of 12 steps (t = 3, 5, 7;" in str(solver_warnings[0].message)


def test_the_shifted_plan_lasts_M_minus_1_steps_then_the_last_iterate_is_applied(pendulum):
    ex, w = pendulum
    M = 4
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, max_failures=None)
    spy = _Failing(rhc, steps=range(2, 9))
    traj, solver_warnings, _ = _run(ex.system, rhc, ex.x0, w, 10)
    assert traj.fallback[2:5] == [SHIFTED] * (M - 1) and traj.fallback[5:9] == [LAST_ITERATE] * 4
    for k in (1, 2, 3):  # u_{1+k} is input k of the plan of t = 1
        np.testing.assert_array_equal(traj.u[1 + k], spy.plans[1].inputs[k])
    msg = str(solver_warnings[0].message)
    assert f"{SHIFTED} (3 steps)" in msg and f"{LAST_ITERATE} (4 steps)" in msg


def test_the_ladder_is_the_same_whichever_solver_failed():
    """FailureLadder knows rungs, not solvers: a second solver is one more rung (here two fakes)."""
    def plan(ok, tag, M=3):
        return Plan(inputs=np.full((M, 1), tag), states=np.full((M + 1, 1), tag), value=tag,
                    success=ok, status="ok" if ok else f"{tag} failed", solver=str(tag), iterations=2)

    ladder = FailureLadder(M=3, max_failures=2, name="toy")
    first = ladder.step(0, [("sqp", lambda: plan(False, 1.0)), ("ipopt", lambda: plan(True, 2.0))])
    assert first.success and first.solver == "2.0" and first.iterations == 4
    assert first.extra["attempts"] == [("sqp", "1.0 failed"), ("ipopt", "ok")]
    second = ladder.step(1, [("sqp", lambda: plan(False, 3.0)), ("ipopt", lambda: plan(False, 4.0))])
    assert not second.success and second.fallback == SHIFTED and np.isnan(second.value)
    assert second.status == "sqp: 3.0 failed; ipopt: 4.0 failed"
    np.testing.assert_array_equal(second.inputs[:, 0], [2.0, 2.0, 2.0])  # the plan of t=0, shifted by one
    with pytest.raises(orrc.SolverError, match="toy stopped at step t=2") as info:
        ladder.step(2, [("sqp", lambda: plan(False, 5.0))])
    assert info.value.statuses == ["sqp: 3.0 failed; ipopt: 4.0 failed", "5.0 failed"]
    ladder.reset()
    assert ladder.step(3, [("sqp", lambda: plan(False, 6.0))]).fallback == LAST_ITERATE  # nothing to shift


def test_clairvoyant_reports_one_failed_solve_as_one_failure(pendulum):
    ex, w = pendulum
    clair = orrc.Clairvoyant(ex.system, ex.cost, 30, input_bounds=ex.input_bounds, solver_options=FORCED_FAILURE)
    traj, solver_warnings, _ = _run(ex.system, clair, ex.x0, w, 30)
    assert traj.n_failures == 1 and traj.failed_steps.tolist() == [0] and traj.success[1:].all()
    assert len(solver_warnings) == 1 and "1 of 30 steps (t = 0;" in str(solver_warnings[0].message)
    rhc = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds),
                        ex.x0, w, 30)
    with pytest.raises(orrc.OrrcValueError, match="reference trajectory's solve failed"):
        orrc.dynamic_regret(rhc, traj)


def test_checks_refuse_a_trajectory_with_failed_steps(pendulum):
    ex, w = pendulum
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    _Failing(rhc, steps=[4])
    traj, _, _ = _run(ex.system, rhc, ex.x0, w, 12)
    for check in (lambda: orrc.checks.lemma1_margins(traj, 10, 1.0, 50.0, 5.0),
                  lambda: orrc.checks.value_bound_margins(traj, 10, 50.0, 5.0),
                  lambda: orrc.checks.lemma2_margins(traj, 10, 10, 0.99, 1.0, 2.0, 5.0)):
        with pytest.raises(orrc.OrrcValueError, match=r"traj has 1 steps without a valid V_M \(t = \[4\]"):
            check()


def test_plan_with_a_warm_start_that_fails_holds_the_shifted_warm_start_and_warns_once(pendulum):
    ex, _ = pendulum
    good = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds).plan(ex.x0, np.zeros((10, 2)))
    rhc = _forced(ex, M=10)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        plan = rhc.plan(ex.x0, np.zeros((10, 2)), warm_start=good)
    assert [r.category for r in rec] == [orrc.SolverWarning] and "the warm start, shifted" in str(rec[0].message)
    assert plan.status == ("SQP warm start: Maximum_Iterations_Exceeded; SQP cold start: Maximum_Iterations_Exceeded; "
                           "IPOPT warm start: Maximum_Iterations_Exceeded")
    np.testing.assert_array_equal(plan.inputs[:-1], good.inputs[1:])


def test_simulate_summarises_the_failures_a_custom_controller_reports():
    class Flaky(orrc.Controller):
        name = "flaky"
        cost = orrc.QuadraticCost([[1.0]], [[1.0]])

        def control(self, obs):
            bad = obs.t % 3 == 1
            return orrc.Decision(u=np.zeros(1), value=1.0, success=not bad, status="nope" if bad else "optimal",
                                 fallback="hold zero" if bad else None)

    traj, solver_warnings, _ = _run(orrc.LinearSystem([[0.5]], [[1.0]]), Flaky(), [1.0], np.zeros((9, 1)), 9)
    assert traj.failed_steps.tolist() == [1, 4, 7]
    assert np.isnan(traj.values[[1, 4, 7]]).all() and traj.value_valid.sum() == 6  # its 1.0 is not a V_M there
    assert len(solver_warnings) == 1 and "hold zero (3 steps)" in str(solver_warnings[0].message)
