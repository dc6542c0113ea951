"""The warm SQP step of PreviewRHC is built once per controller, NLP and thread (PreviewRHC.fast_nlp), and
the plant's buffer once per warm step (orrc._fast_loops.nlp_loop), not per run: nothing of one run may
leak into the next. Each run on a reused controller (other x0, w, T, cost sequence; after reset(), a
plan() with other cost parameters, set_theta; copied or pickled; in another thread) is bit for bit the
run of a fresh controller."""
from __future__ import annotations

import copy
import pickle
import threading
import warnings

import casadi as ca
import numpy as np
import pytest

import orrc
from runs import same_runs

EX = orrc.examples.inverted_pendulum()
M = 10
# a previewed, time-varying cost: c_t = p_t (1 - cos φ) + ω² + 0.1 u²
TV_COST = orrc.Cost(lambda x, u, p: p[0] * (1 - ca.cos(x[0])) + x[1] ** 2 + 0.1 * u[0] ** 2,
                    n=2, m=1, n_params=1, default_params=[10.0])


def pendulum(x, u, w):
    """The example's pendulum, at module level (a controller on it pickles)."""
    return ca.vertcat(x[0] + 0.05 * x[1], x[1] + 0.05 * (9.81 * ca.sin(x[0]) - 0.1 * x[1] + u[0])) + w


def _controller(cost=EX.cost, **kw):
    kw = dict(input_bounds=EX.input_bounds) | kw
    return orrc.PreviewRHC(EX.system, cost, M, **kw)


def _same_runs(a, b):
    same_runs(a, b, more=("w", "w_all", "sigma"))


def _run(rhc, x0, w, T, costs=None, system=EX.system):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", orrc.SolverWarning)
        return orrc.simulate(system, rhc, x0, w, T, costs=costs)


# (x0, disturbance scale, T, cost sequence or None): short and long runs, a hard one with failed steps
RUNS = [(np.array([0.5, 0.0]), 1.0, 30, None),
        (np.array([-0.8, 0.3]), 3.0, 7, None),
        (np.array([2.5, 0.0]), 1.0, 25, "sequence"),
        (np.array([0.1, -0.2]), 0.5, 1, None),
        (np.array([1.0, 0.0]), 2.0, 40, "sequence")]


def _runs(make):
    """Each run of RUNS on the controller make(i) gives for run i."""
    w = orrc.disturbances.uniform_ball(80, 2, radius=0.02, seed=1)
    seq = orrc.CostSequence(TV_COST, 10 * (1 + 0.5 * np.sin(np.arange(60) / 5.0))[:, None])
    return [_run(make(i), x0, scale * w, T, seq if costs else None) for i, (x0, scale, T, costs) in enumerate(RUNS)]


def test_runs_on_one_controller_are_runs_on_fresh_controllers():
    reused = _controller(TV_COST)
    _ = [_same_runs(a, b) for a, b in zip(_runs(lambda i: reused), _runs(lambda i: _controller(TV_COST)))]
    assert reused.fast_nlp() is reused.fast_nlp(), "the warm step is built once per controller"


def test_runs_with_failed_steps_on_one_controller_are_runs_on_fresh_controllers():
    """SQP cut short under a tight bound: failed steps, fallbacks and the ladder's state between runs."""
    kw = dict(input_bounds=(-1, 1), max_failures=None, solver="sqp", solver_options={"sqpmethod.max_iter": 3})
    reused = _controller(**kw)
    w = 30 * orrc.disturbances.uniform_ball(80, 2, radius=0.02, seed=0)
    failures = []
    for x0, T in ((np.array([2.0, 0.0]), 40), (np.array([0.3, 0.0]), 20), (np.array([3.0, 0.0]), 15)):
        a, b = _run(reused, x0, w, T), _run(_controller(**kw), x0, w, T)
        _same_runs(a, b)
        failures.append(a.n_failures)
    assert failures[0] > 0, failures


def test_a_run_after_reset_and_after_plans_with_other_parameters_is_the_same_run():
    rhc = _controller(TV_COST)
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.02, seed=2)
    first = _run(rhc, EX.x0, w, 30)
    rhc.reset()
    _same_runs(first, _run(rhc, EX.x0, w, 30))
    # a direct plan() with other cost parameters and a warm start leaves its values in the solver's buffers
    plan = rhc.plan(EX.x0, w[:M], cost_params=np.full((M, 1), 55.0))
    rhc.plan(EX.x0 + 0.1, w[1:M + 1], cost_params=np.full((M, 1), 3.0), warm_start=plan)
    _same_runs(first, _run(rhc, EX.x0, w, 30))
    rhc.reset()
    _same_runs(first, _run(rhc, EX.x0, w, 30))


def test_a_run_after_set_theta_is_the_run_of_a_controller_built_with_that_theta():
    model = orrc.ParametricSystem(
        lambda x, u, w, th: ca.vertcat(x[0] + 0.05 * x[1], x[1] + 0.05 * (th[0] * ca.sin(x[0]) - 0.1 * x[1] + u[0]))
        + w, 2, 1, 1)
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.02, seed=3)
    rhc = orrc.PreviewRHC(model, EX.cost, M, input_bounds=EX.input_bounds, theta=[9.81])
    _run(rhc, EX.x0, w, 20)
    for theta in ([7.0], [12.0]):
        rhc.set_theta(theta)
        fresh = orrc.PreviewRHC(model, EX.cost, M, input_bounds=EX.input_bounds, theta=theta)
        _same_runs(_run(rhc, EX.x0, w, 20), _run(fresh, EX.x0, w, 20))


def _pickled(obj):
    with ca.global_pickle_context():   # (CasADi's SX expressions pickle in a context)
        data = pickle.dumps(obj)
    with ca.global_unpickle_context():
        return pickle.loads(data)


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_a_copied_or_pickled_controller_carries_no_buffers_and_runs_the_same(how):
    rhc = orrc.PreviewRHC(orrc.NonlinearSystem(pendulum, 2, 1), EX.cost, M, input_bounds=EX.input_bounds)
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.02, seed=4)
    first = _run(rhc, EX.x0, w, 25)
    assert "_casadi_buffers" in rhc.__dict__
    other = {"copy": copy.copy, "deepcopy": copy.deepcopy, "pickle": _pickled}[how](rhc)
    assert "_casadi_buffers" not in other.__dict__, "the warm step is working memory, not carried"
    _same_runs(first, _run(other, EX.x0, w, 25))
    assert other.fast_nlp() is not rhc.fast_nlp()
    _same_runs(first, _run(rhc, EX.x0, w, 25))


def test_runs_in_other_threads_use_their_own_warm_step_and_are_the_same_run():
    """A warm step holds a thread's solver buffers: each thread has its own. Runs on one controller from
    other threads (one after the other: the controller's failure ladder is the state of one run) are the
    same run; runs at the same time on copies of a controller (which share its NLP) too."""
    rhc = _controller()
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.02, seed=5)
    first = _run(rhc, EX.x0, w, 25)
    results, warms = {}, {}
    together = threading.Barrier(3)   # the copies' threads all alive at once (a thread id is reused after)

    def job(name, controller):
        if name.startswith("copy"):
            together.wait(timeout=60)
        warms[name] = controller.fast_nlp()
        results[name] = _run(controller, EX.x0, w, 25)
        if name.startswith("copy"):
            together.wait(timeout=60)

    for name in ("a", "b"):
        thread = threading.Thread(target=job, args=(name, rhc))
        thread.start()
        thread.join()
    copies = [copy.copy(rhc) for _ in range(3)]
    for c in copies:   # the same NLP (its buffers per thread), a failure ladder each
        c._ladder = copy.deepcopy(rhc._ladder)
    threads = [threading.Thread(target=job, args=(f"copy {i}", c)) for i, c in enumerate(copies)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(results) == 5
    for run in results.values():
        _same_runs(first, run)
    assert warms["copy 0"] is not warms["copy 1"] and rhc.fast_nlp() not in warms.values()
    assert warms["copy 0"].call is not warms["copy 1"].call, "each thread solves on its own buffers"
