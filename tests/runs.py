"""Closed loops the warm-step tests share (tests/test_sqp.py, test_jit.py, test_warm_step_cache.py): the
pendulum cases they run, and the comparison of two runs bit for bit."""
import casadi as ca
import numpy as np

import orrc

#: what two runs that must be the same are compared in (``same_runs``), besides the solver's report
RUN_FIELDS = ("x", "u", "costs", "values", "success", "iterations", "value_valid")


def same_runs(a, b, more=()) -> None:
    """Two trajectories are the same bit for bit in ``RUN_FIELDS`` and ``more`` (NaN where the other has NaN),
    and in the solver's report of every step (status, solver, fallback)."""
    for k in (*RUN_FIELDS, *more):
        assert np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True), f"the runs differ in {k}"
    assert (a.status, a.solver, a.fallback) == (b.status, b.solver, b.fallback), "the runs' records differ"


def pendulum_case(case: str):
    """(system, cost, PreviewRHC keywords, x0, w, costs) of a pendulum closed loop (M = 10, 80 rows of w):
    "accepted" (every step SQP's), "time-varying cost" (c_t = p_t (1 - cos θ) + ω² + 0.1 u², p_t previewed,
    non-convex), or the hard steps of a tight input bound far from the origin with SQP cut short: "ipopt
    rescues" (SQP then IPOPT) and "steps fail" (SQP alone, the fallback applied)."""
    ex = orrc.examples.inverted_pendulum()
    w = orrc.disturbances.uniform_ball(80, 2, radius=0.02, seed=0)
    kw, x0, cost, costs = dict(M=10, input_bounds=ex.input_bounds), np.array([0.5, 0.0]), ex.cost, None
    if case == "time-varying cost":
        cost = orrc.Cost(lambda x, u, p: p[0] * (1 - ca.cos(x[0])) + x[1] ** 2 + 0.1 * u[0] ** 2,
                         n=2, m=1, n_params=1, default_params=[20.0])
        costs = orrc.CostSequence(cost, 20 * (1 + 0.5 * np.sin(np.arange(50) / 7.0))[:, None])
        x0 = np.array([2.5, 0.0])
    elif case != "accepted":
        rescue = case == "ipopt rescues"
        kw = dict(M=10, input_bounds=(-1, 1), max_failures=None, solver="nlp" if rescue else "sqp",
                  solver_options={"sqpmethod.max_iter": 2 if rescue else 3})
        x0, w = np.array([2.0, 0.0]), (10 if rescue else 30) * w
    return ex.system, cost, kw, x0, w, costs
