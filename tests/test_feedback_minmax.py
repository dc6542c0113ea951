"""Feedback min-max RHC (MinMaxRHC(policy="feedback"), the scenario tree of W's vertices) against
independent computations:

* a dynamic program on a fine grid of states, inputs and disturbances (interior points of W
  included) for a scalar system: V_k(x) = min_u [c(x, u) + max_w V_{k-1}(a x + b u + w)];
* brute-force enumeration of causal policies on a tiny case (scalar, M = 3): every policy of a grid
  (u_0, u_1 after w_0 = w-, u_1 after w_0 = w+, interpolated in between) with its worst case over a
  grid of (w_0, w_1) that includes interior points, then refined;
* the ordering max-min <= feedback <= open-loop, equality of the two min-max policies at M = 2,
  a polytope W, the receding horizon (only the root input is applied), and the tree's size guard.
"""
import itertools
import math

import numpy as np
import pytest

import orrc
from orrc.solvers.scenario_tree import TREE_NODE_LIMIT, ScenarioTree, tree_nodes
from conftest import random_lq_problem


def _scalar(a=1.2, b=1.0, q=1.0, r=1.0):
    return orrc.LinearSystem([[a]], [[b]]), orrc.QuadraticCost([[q]], [[r]])


def _grid_dp(a, b, q, r, w_lo, w_hi, M, xq, L=6.0, nx=1201, nu=801, nw=41):
    """V^fb_M at the states xq by a dynamic program on grids (linear interpolation of V_{k-1})."""
    xs = np.linspace(-L, L, nx)
    ws = np.linspace(w_lo, w_hi, nw)
    V = q * xs ** 2                                   # V_1 (u = 0 at the last stage)

    def step(V, x):
        span = (abs(a) * np.max(np.abs(x)) + 1.0) / abs(b)
        us = np.linspace(-span, span, nu)
        du = us[1] - us[0]

        def values(u):                                 # u (k, p): the stage's worst case for every input
            nxt = a * x[:, None, None] + b * u[:, :, None] + ws[None, None, :]
            return q * x[:, None] ** 2 + r * u ** 2 + np.interp(nxt, xs, V).max(axis=2)

        coarse = values(np.broadcast_to(us, (len(x), nu)))
        best = us[np.argmin(coarse, axis=1)]
        fine = best[:, None] + np.linspace(-2 * du, 2 * du, 401)[None, :]   # the kink needs a fine u grid
        return values(fine).min(axis=1)

    for _ in range(M - 2):
        V = np.concatenate([step(V, xs[i:i + 200]) for i in range(0, nx, 200)])
    return step(V, np.asarray(xq, float)) if M > 1 else q * np.asarray(xq) ** 2


@pytest.mark.parametrize("M", [2, 3, 4])
def test_value_equals_grid_dynamic_program(M):
    a, b, q, r = 1.2, 1.0, 1.0, 0.5
    sysm, cost = _scalar(a, b, q, r)
    W = orrc.Box(-0.3, 0.2)                            # asymmetric: the law is affine, not linear
    xq = np.array([-1.0, 0.0, 0.4, 1.3])
    tree = ScenarioTree(sysm, cost, M, W)
    exact = np.array([tree.solve(np.array([x])).value for x in xq])
    grid = _grid_dp(a, b, q, r, -0.3, 0.2, M, xq)
    # the grid's error: interpolation of a convex V (over-estimates by <= dx² V''/8 per stage) and the u grid
    assert np.all(np.abs(grid - exact) <= 2e-3 * exact + 1e-4), (grid, exact)
    assert np.all(grid >= exact - 1e-6)               # the grid's policies are feasible: never below


def _enumerate_1d(f, lo, hi, rounds=13):
    """min of a convex function of one variable by enumeration: a grid, then finer grids around the best
    (f maps an array of points to their values)."""
    c, h = 0.5 * (lo + hi), 0.5 * (hi - lo)
    for _ in range(rounds):
        pts = c + np.linspace(-h, h, 41)
        c, h = pts[int(np.argmin(f(pts)))], h / 8
    return c, float(f(np.array([c]))[0])


def test_value_equals_brute_force_policy_enumeration():
    """M = 3, scalar: a causal policy is u_0, then u_1 after w_0 (one per branch), then u_2 = 0. Given u_0 the
    branches are independent, so enumerating u_0 and, in each branch, u_1 (grids refined around the best)
    enumerates the policies; their worst case is taken over a grid of W that includes interior points."""
    a, b, q, r = 1.5, 1.0, 1.0, 1.0
    sysm, cost = _scalar(a, b, q, r)
    w = 0.4
    W = orrc.Box(-w, w)
    x0 = 0.7
    plan = ScenarioTree(sysm, cost, 3, W).solve(np.array([x0]))
    wg = np.linspace(-w, w, 9)                         # interior points included

    def branch(x1, u1):                                # stage 1 and 2 costs, worst w_1 (u1 an array)
        u1 = np.asarray(u1, float)[:, None]
        return np.max(q * x1 ** 2 + r * u1 ** 2 + q * (a * x1 + b * u1 + wg) ** 2, axis=1)

    def best_branch(x1):
        return _enumerate_1d(lambda u1: branch(x1, u1), -5.0, 5.0)

    def policy_value(u0s):                             # the worst w_0 over the grid, each branch at its best u_1
        return np.array([q * x0 ** 2 + r * u0 ** 2 + max(best_branch(a * x0 + b * u0 + w0)[1] for w0 in wg)
                         for u0 in u0s])

    u0, V_enum = _enumerate_1d(policy_value, -5.0, 5.0, rounds=10)
    V = plan.value
    assert V <= V_enum * (1 + 1e-9)                   # no enumerated policy beats the tree
    assert V_enum <= V * (1 + 1e-7)                   # and the best one reaches it
    assert plan.inputs[0, 0] == pytest.approx(u0, abs=1e-5)
    # the tree's policy, interpolated between its two branches, has its worst case at the vertices
    u = plan.extra["node_inputs"].ravel()
    u1 = u[1] + (u[2] - u[1]) * (wg + w) / (2 * w)
    x1 = a * x0 + b * u[0] + wg
    worst = max(q * x0 ** 2 + r * u[0] ** 2 + branch(x1[i], [u1[i]])[0] for i in range(len(wg)))
    assert worst == pytest.approx(V, rel=1e-9)


def test_ordering_and_the_two_policies_at_M2():
    for seed in range(4):
        rng = np.random.default_rng(seed)
        sysm, cost = random_lq_problem(rng, n=2, m=1, rho_range=(0.6, 1.3))
        W = orrc.Box(-rng.uniform(0.1, 0.5, 2), rng.uniform(0.1, 0.5, 2))
        x = rng.standard_normal(2)
        for M in (2, 3, 4):
            fb = orrc.MinMaxRHC(sysm, cost, M, W, policy="feedback").plan(x)
            ol = orrc.MinMaxRHC(sysm, cost, M, W, method="exact").plan(x)
            pre = orrc.PreviewRHC(sysm, cost, M)
            maxmin = max(pre.plan(x, np.array(s)).value
                         for s in itertools.product(W.vertices(), repeat=M))
            assert fb.certified and fb.gap <= 1e-7 * fb.value
            assert maxmin <= fb.value * (1 + 1e-8)
            assert fb.value <= ol.value * (1 + 1e-8)
            if M == 2:          # the last input is the same for both: open-loop = feedback
                assert fb.value == pytest.approx(ol.value, rel=1e-7)
                np.testing.assert_allclose(fb.inputs[0], ol.inputs[0], rtol=1e-5, atol=1e-7)


def test_feedback_is_strictly_better_at_M3_on_the_scalar_example():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    fb = orrc.MinMaxRHC(ex.system, ex.cost, 6, W, policy="feedback").plan(np.zeros(1)).value
    ol = orrc.MinMaxRHC(ex.system, ex.cost, 6, W).plan(np.zeros(1)).value
    assert fb < 0.5 * ol


def test_polytope_w():
    sysm, cost = _scalar()
    box = orrc.MinMaxRHC(sysm, cost, 4, orrc.Box(-0.3, 0.3), policy="feedback").plan(np.array([0.5]))
    # an interior point as an extra "vertex" changes nothing; the vertices alone give the box's value
    poly = orrc.MinMaxRHC(sysm, cost, 4, orrc.Polytope([[-0.3], [0.1], [0.3]]), policy="feedback")
    assert poly.plan(np.array([0.5])).value == pytest.approx(box.value, rel=1e-7)
    # a triangle in R^2 against the grid over its vertices' convex hull is covered by the DP test; here its
    # value lies between the box through its vertices and zero disturbance
    rng = np.random.default_rng(3)
    s2, c2 = random_lq_problem(rng, n=2, m=1, rho_range=(0.6, 1.2))
    tri = orrc.Polytope([[0.3, 0.0], [-0.2, 0.2], [-0.1, -0.25]])
    bbox = orrc.Box([-0.2, -0.25], [0.3, 0.2])
    x = np.array([0.4, -0.2])
    v_tri = orrc.MinMaxRHC(s2, c2, 3, tri, policy="feedback").plan(x).value
    v_box = orrc.MinMaxRHC(s2, c2, 3, bbox, policy="feedback").plan(x).value
    v_nom = orrc.PreviewRHC(s2, c2, 3).plan(x, np.zeros((3, 2))).value
    assert v_nom < v_tri < v_box
    assert tri.contains(tri.sample(20, 0)) and not tri.contains(np.array([0.3, 0.2]))


def test_receding_horizon_applies_the_root_input():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    ctl = orrc.MinMaxRHC(ex.system, ex.cost, 4, W, policy="feedback")
    w = W.sample(12, 4)
    tr = orrc.simulate(ex.system, ctl, np.array([1.0]), w, 12)
    assert tr.success.all()
    again = orrc.MinMaxRHC(ex.system, ex.cost, 4, W, policy="feedback")
    for t in (0, 5, 11):
        np.testing.assert_allclose(tr.u[t], again.plan(tr.x[t]).inputs[0], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(tr.values, [again.plan(x).value for x in tr.x[:-1]], rtol=1e-7)


def test_input_bounds_raise_the_value():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    free = orrc.MinMaxRHC(ex.system, ex.cost, 4, W, policy="feedback").plan(np.array([2.0]))
    bounded = orrc.MinMaxRHC(ex.system, ex.cost, 4, W, policy="feedback",
                             input_bounds=(-1.0, 1.0)).plan(np.array([2.0]))
    assert bounded.success and np.all(np.abs(bounded.extra["node_inputs"]) <= 1.0 + 1e-9)
    assert bounded.value > free.value * (1 + 1e-3)


def test_tree_size_guard_names_M_vertices_and_limit():
    ex = orrc.examples.scalar_unstable()
    with pytest.raises(orrc.OrrcValueError, match=rf"M=30 with 2 vertices.*limit is {TREE_NODE_LIMIT}"):
        orrc.MinMaxRHC(ex.system, ex.cost, 30, orrc.Box(-0.3, 0.3), policy="feedback")
    assert tree_nodes(2, 30) == 2 ** 30 - 1 and math.isinf(tree_nodes(10 ** 6, 10 ** 4))


def test_feedback_refuses_what_it_cannot_solve_exactly():
    pend = orrc.examples.inverted_pendulum()
    with pytest.raises(orrc.OrrcValueError, match="policy='feedback' needs a LinearSystem"):
        orrc.MinMaxRHC(pend.system, pend.cost, 3, orrc.Box(-0.1, 0.1, 2), policy="feedback")
    ex = orrc.examples.scalar_unstable()
    with pytest.raises(orrc.OrrcValueError, match="polytope W"):
        orrc.MinMaxRHC(ex.system, ex.cost, 3, orrc.Ball(0.3, 1), policy="feedback")
    with pytest.raises(orrc.OrrcValueError, match="method must be 'auto' or 'exact'"):
        orrc.MinMaxRHC(ex.system, ex.cost, 3, orrc.Box(-0.3, 0.3), policy="feedback", method="exchange")
    with pytest.raises(orrc.OrrcValueError, match="policy must be one of"):
        orrc.MinMaxRHC(ex.system, ex.cost, 3, orrc.Box(-0.3, 0.3), policy="closed")
    with pytest.raises(orrc.OrrcValueError, match="use policy='feedback'"):
        orrc.MinMaxRHC(ex.system, ex.cost, 3, orrc.Polytope([[-0.3], [0.3]]))
