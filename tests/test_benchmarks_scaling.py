"""Smoke test of the scaling benchmarks (``benchmarks/scaling.py``, ``benchmarks/scaling_lq.py``) at tiny sizes.

Correctness, not timing: the closed loops of every tool are the same (judged by an independent numpy
rollout), the referee of the chain is orrc's model, the checks fail when an answer differs, and the page
draws each grid's times against its size.
"""
import numpy as np
import pytest

import orrc

from benchmarks import peer_models, run, scaling, scaling_lq, structure
from benchmarks.common import CheckFailed
from tools import sphinx_benchmarks as page


def _quick_scaling(**over):
    return scaling.run(**(run.QUICK["scaling"] | over))


def test_every_grid_point_is_the_same_closed_loop_and_has_an_exponent():
    rows = _quick_scaling()
    points = [r for r in rows if "size" in r.data]
    assert [(r.data["grid"].split(",")[0], r.data["size"], r.data["tool"]) for r in points] == \
        [("pendulum", 3, "bare"), ("pendulum", 4, "bare"), ("chain of masses", 2, "bare"),
         ("chain of masses", 4, "bare"), ("quadrotor", 12, "bare"), ("quadrotor", 12, "bare_own")]
    for r in points[:4] + points[5:]:   # the bare CasADi loop on orrc's NLP: the same closed loop
        assert abs(r.data["gap"]) <= scaling.SAME_RTOL and r.data["dx"] <= 1e-6
        assert r.data["t_orrc"] > 0 and r.data["t_peer"] > 0 and r.data["counts"] == {"sqp": 5}
    # the quadrotor: orrc takes the Gauss-Newton Hessian; the bare loop keeps CasADi's exact one (whose
    # eigenvalue convexification fails here: the row says so), and the bare loop with orrc's is the same loop
    assert all(r.data["hessian"] == "exact" for r in points[:4]) and points[5].data["hessian"] == "gauss-newton"
    assert "t_peer" in points[5].data and "failed" in points[4].data.get("skipped", "failed")
    slopes = [r for r in rows if "exponents" in r.data]
    assert len(slopes) == 2 and all(np.isfinite(r.data["exponents"]["orrc"]) for r in slopes)


def test_a_different_closed_loop_is_caught(monkeypatch):
    real = scaling.peers.BareCasadiLoop.__call__

    def off(self, x0, w, T, read_status=False):
        X, U = real(self, x0, w, T, read_status)
        return X, U + 1e-4

    monkeypatch.setattr(scaling.peers.BareCasadiLoop, "__call__", off)
    with pytest.raises(CheckFailed, match="not the same closed loop"):
        _quick_scaling(ks=())


def test_the_chain_referee_and_the_peers_model_are_orrcs_chain():
    rng = np.random.default_rng(1)
    for k in (1, 2, 5):
        prob = scaling.chain_problem(k, T=6, M=2, seed=3)
        ex = scaling.example(prob)
        U = rng.uniform(-2, 2, 6)
        X, J = scaling.chain_rollout(prob, U, np.asarray(prob["w"])[:6])
        x, J_orrc = np.asarray(prob["x0"]), 0.0
        step = peer_models.plant(prob)
        for t, u in enumerate(U):
            J_orrc += ex.cost(x, [u])
            assert np.allclose(step(x, [u], np.asarray(prob["w"][t])), ex.system.step(x, [u], prob["w"][t]),
                               rtol=0, atol=1e-14)
            x = ex.system.step(x, [u], prob["w"][t])
            assert np.allclose(X[t + 1], x, rtol=0, atol=1e-13)
        assert J == pytest.approx(J_orrc, rel=1e-13)
        # the CasADi model the peers build is the same function
        import casadi as ca
        xs, us, ws = ca.SX.sym("x", 2 * k), ca.SX.sym("u", 1), ca.SX.sym("w", 2 * k)
        f = ca.Function("f", [xs, us, ws], [peer_models.dynamics(prob, xs, us, ws)])
        x0, u0, w0 = rng.normal(size=2 * k), rng.normal(size=1), rng.normal(size=2 * k)
        assert np.allclose(np.asarray(f(x0, u0, w0)).ravel(), ex.system.step(x0, u0, w0), rtol=0, atol=1e-13)


def test_the_quadrotor_referee_and_the_peers_model_are_orrcs_quadrotor():
    import casadi as ca
    rng = np.random.default_rng(2)
    prob = scaling.quadrotor_problem(T=6, M=2, seed=4)
    ex = scaling.example(prob)
    U = rng.uniform(-0.5, 0.5, (6, 4))
    W = np.asarray(prob["w"])[:6]
    X, J = scaling.quadrotor_rollout(prob, U, W)
    x, J_orrc = np.asarray(prob["x0"]), 0.0
    for t, u in enumerate(U):
        J_orrc += ex.cost(x, u)
        x = ex.system.step(x, u, W[t])
        assert np.allclose(X[t + 1], x, rtol=0, atol=1e-13)
    assert J == pytest.approx(J_orrc, rel=1e-13)
    xs, us, ws = ca.SX.sym("x", 12), ca.SX.sym("u", 4), ca.SX.sym("w", 12)
    f = ca.Function("f", [xs, us, ws], [peer_models.dynamics(prob, xs, us, ws)])
    x0, u0, w0 = 0.3 * rng.normal(size=12), rng.normal(size=4), rng.normal(size=12)
    assert np.allclose(np.asarray(f(x0, u0, w0)).ravel(), ex.system.step(x0, u0, w0), rtol=0, atol=1e-13)
    assert peer_models.n_states(prob) == 12 and peer_models.n_inputs(prob) == 4


def test_the_growth_exponent_is_the_power_of_a_power_law():
    sizes = np.array([10, 20, 50, 100, 200])
    assert scaling.exponent(sizes, 3e-6 * sizes ** 1.5) == pytest.approx(1.5, abs=1e-12)
    assert scaling.exponent(sizes, np.full(5, 2e-4)) == pytest.approx(0.0, abs=1e-12)


def test_the_lq_path_is_the_numpy_riccati_loop():
    rows = scaling_lq.run(**run.QUICK["scaling_lq"])
    points = [r for r in rows if "size" in r.data]
    assert [r.data["size"] for r in points] == [4, 6]
    assert all(r.data["dx"] <= scaling_lq.RTOL and r.data["dc"] <= scaling_lq.RTOL for r in points)


def test_the_lq_check_catches_a_different_law(monkeypatch):
    real = scaling_lq.riccati_gains

    def off(A, B, Q, R, M):
        gains = real(A, B, Q, R, M)
        K, AclT, GiBt, P = gains[0]
        return [(K * (1 + 1e-6), AclT, GiBt, P)] + gains[1:]

    monkeypatch.setattr(scaling_lq, "riccati_gains", off)
    with pytest.raises(CheckFailed, match="disagree"):
        scaling_lq.run(**run.QUICK["scaling_lq"])


def test_the_page_draws_time_against_size_for_each_grid():
    rows = [{"data": r.data, "orrc_seconds": r.data.get("t_orrc")} for r in _quick_scaling()]
    series = page.scaling_series(rows)
    assert list(series) == [r.data["grid"] for r in _quick_scaling() if "exponents" in r.data]
    name, tools, slopes = series[next(iter(series))]
    assert name == "M" and sorted(tools) == ["bare", "orrc"] and [s for s, _ in tools["orrc"]] == [3, 4]
    assert set(slopes) == {"orrc", "bare"}
    fig = page.figure("scaling", rows)
    lines = [ln for ax in fig.axes for ln in ax.get_lines()]
    assert len(fig.axes) == 2 and len(lines) == 4 and all(ax.get_xscale() == "log" for ax in fig.axes)
    assert any("exponent" in t.get_text() for ax in fig.axes for t in ax.get_legend().get_texts())


def test_the_qp_solvers_give_the_same_closed_loop_and_a_different_one_is_caught(monkeypatch):
    rows = structure.run(**run.QUICK["structure"])
    assert [r.data["M"] for r in rows] == [3, 4]
    assert all(abs(r.data["gap"]) <= structure.SAME_RTOL and r.data["t_hpipm"] > 0 for r in rows)
    real = structure.closed_loops

    def off(M, T, reps, solvers=("qrqp", "hpipm")):
        out = real(M, T, reps, solvers)
        traj, t = out["hpipm"]
        traj.x[1:] += 1e-5
        return out

    monkeypatch.setattr(structure, "closed_loops", off)
    with pytest.raises(CheckFailed, match="is not qrqp's"):
        structure.run(**run.QUICK["structure"])


def test_the_page_lists_each_missed_target_with_its_ratio_and_what_was_measured():
    rows = [{"case": "M=200: orrc vs acados SQP", "ratio": "1.30× acados", "target": "< 1× (CPU)", "ok": False,
             "check": "orrc's steps by solver: sqp 100"},
            {"case": "M=10: orrc vs acados SQP", "ratio": "0.50× acados", "target": "< 1× (CPU)", "ok": True}]
    lines = page.missed(rows)
    assert len([ln for ln in lines if ln.startswith("- ")]) == 1
    assert "M=200" in lines[2] and "1.30×" in lines[2] and "sqp 100" in lines[2] and "M=10" not in "".join(lines)
    assert page.missed(rows[1:]) == []


def test_a_missed_scaling_target_shows_the_bare_loop_at_the_same_point():
    data = dict(grid="chain", size=24, tool="acados", t_peer=2e-3)
    rows = [{"case": "n=24: orrc vs acados SQP", "ratio": "4.00× acados", "target": "< 1× (CPU)", "ok": False,
             "check": "", "data": data},
            {"case": "n=24: orrc vs bare CasADi loop", "ratio": "1.05×", "ok": True, "peer": "7.6 ms",
             "data": dict(grid="chain", size=24, tool="bare", t_peer=7.6e-3)}]
    assert "bare CasADi loop on the same NLP at this point: 7.6 ms, 3.80× acados SQP" in page.missed(rows)[2]
    rows[1]["data"] = dict(grid="chain", size=24, tool="bare", skipped="its SQP solve failed")
    assert "the bare CasADi loop at this point: its SQP solve failed" in page.missed(rows)[2]


def test_a_missed_scaling_target_shows_the_floor_with_orrcs_hessian_and_why_the_nlp_was_not_compiled():
    point = dict(grid="quadrotor", size=12)
    rows = [{"case": "n=12: orrc vs acados SQP", "ratio": "2.00× acados", "target": "< 1× (CPU)", "ok": False,
             "check": "", "data": dict(point, tool="acados", t_peer=2e-3, compiled=False,
                                      compile_error="5000000 characters of C code, more than CODE_LIMIT")},
            {"case": "n=12: orrc vs bare CasADi loop", "ok": None, "peer": "skipped",
             "data": dict(point, tool="bare", skipped="its SQP solve failed")},
            {"case": "n=12: orrc vs bare loop, orrc's Hessian", "ok": None, "peer": "3.6 ms",
             "data": dict(point, tool="bare_own", t_peer=3.6e-3)}]
    line = page.missed(rows)[2]
    assert line.startswith("- quadrotor: n=12: orrc vs acados SQP")   # the grid tells it from the chain's n=12
    assert "the bare CasADi loop at this point: its SQP solve failed" in line
    assert "the bare loop with orrc's Hessian: 3.6 ms, 1.80× acados SQP" in line
    assert "orrc's NLP interpreted (5000000 characters of C code, more than CODE\\_LIMIT)" in line
    rows[0]["data"]["compiled"] = True
    assert "interpreted" not in page.missed(rows)[2]
