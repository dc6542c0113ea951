"""Smoke test of the performance benchmarks (``make bench``) at tiny sizes.

Correctness, not timing: each benchmark still runs, its computations agree
(the pendulum: orrc's SQP, its IPOPT and python-control's ``solve_ocp`` reach the same
optimum, judged by an independent rollout of the cost; the closed loops: SQP's run is
IPOPT's; the LQ path: ``orrc.simulate`` and the bare numpy loop produce the same
trajectory; the min-max problem: the exact method and scenario exchange reach the same value),
and the checks that enforce this do fail when the answers differ.
"""
import numpy as np
import pytest

import orrc

from benchmarks import closed_loop, comparison, lq_path, minmax, peers, pendulum, regret, run, widgets
from benchmarks.common import CheckFailed


def test_pendulum_orrc_and_solve_ocp_reach_the_same_optimum():
    rows = pendulum.run(M=5, thetas=(0.5, 1.0), reps_orrc=1, reps_peer=1)
    cold = [r for r in rows if r.ok is not None]
    assert [r.data["theta0"] for r in cold] == [0.5, 1.0]
    for r in cold:
        d = r.data
        assert np.isfinite(d["J_orrc"]) and d["J_orrc"] > 0
        assert abs(d["J_peer"] - d["J_orrc"]) <= 1e-4 * d["J_orrc"]
        assert abs(d["J_ipopt"] - d["J_orrc"]) <= 1e-6 * d["J_orrc"]  # SQP and IPOPT: the same optimum
        assert d["t_orrc"] > 0 and d["t_peer"] > 0 and d["t_ipopt"] > 0
    warm = [r for r in rows if "warm vs cold" in r.benchmark]
    assert len(warm) == 2 and all(r.data["it_warm"] >= 1 and r.data["it_cold"] >= 1 for r in warm)


def test_pendulum_referee_is_independent_and_catches_a_wrong_answer(monkeypatch):
    # the numpy referee against a hand-computed first step
    x0, u, w = np.array([0.3, -0.2]), np.array([1.5]), np.array([0.01, -0.02])
    x1 = np.array([0.3 + 0.05 * -0.2, -0.2 + 0.05 * (9.81 * np.sin(0.3) - 0.1 * -0.2 + 1.5)]) + w
    assert np.allclose(pendulum.step(x0, u, w), x1, rtol=0, atol=1e-15)
    X, J = pendulum.rollout(x0, np.array([u, [0.0]]), np.array([w, w]))
    assert J == pytest.approx(10 * 0.09 + 0.04 + 0.1 * 2.25 + 10 * x1[0] ** 2 + x1[1] ** 2, rel=1e-14)
    # a peer that returns a suboptimal sequence is caught
    real = pendulum.solve_ocp

    def worse(x0, W, M):
        U, res = real(x0, W, M)
        return U + 0.5, res

    monkeypatch.setattr(pendulum, "solve_ocp", worse)
    with pytest.raises(CheckFailed, match="values differ"):
        pendulum.run(M=5, thetas=(0.5,), reps_orrc=1, reps_peer=1)


def test_lq_path_orrc_equals_the_bare_loop():
    rows = lq_path.run(T=30, M=6, reps=1)
    main = rows[0]
    assert main.ok is not None and main.data["t_orrc"] > 0 and main.data["t_floor"] > 0
    assert "x, u" in main.check


def test_lq_path_check_catches_a_different_law(monkeypatch):
    real = lq_path.bare_loop

    def perturbed(A, B, K, L, w_all, x0, T, M):
        return real(A, B, K * (1 + 1e-6), L, w_all, x0, T, M)

    monkeypatch.setattr(lq_path, "bare_loop", perturbed)
    with pytest.raises(CheckFailed, match="disagree"):
        lq_path.run(T=30, M=6, reps=1)


def test_closed_loops_of_sqp_and_ipopt_agree_and_say_which_solver_took_each_step():
    rows = closed_loop.run(T=10, reps=1, reps_ipopt=1)
    runs = [r for r in rows if "warm vs cold" not in r.benchmark]
    assert [r.benchmark.split(", ")[-1] for r in runs] == ["pendulum", "Van der Pol", "non-convex time-varying cost"]
    assert [r.ok is not None for r in runs] == [True, False, False]  # the target is the pendulum's
    for r in runs:
        assert r.data["n_sqp"] + r.data["n_ipopt"] == 10 and abs(r.data["gap"]) <= 1e-6
        assert "steps by solver: SQP" in r.check


def test_closed_loop_check_catches_a_different_run(monkeypatch):
    real = orrc.simulate

    def shifted(*args, **kw):
        traj = real(*args, **kw)
        if args[1].solver == "ipopt":
            traj.costs = traj.costs * (1 + 1e-5)
        return traj

    monkeypatch.setattr(orrc, "simulate", shifted)
    with pytest.raises(CheckFailed, match="is not IPOPT's"):
        closed_loop.run(T=5, reps=1, reps_ipopt=1)


def test_run_quick_prints_a_table_and_succeeds(capsys):
    assert run.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "| benchmark |" in out and "pendulum M=5" in out and "LQ path T=40" in out
    assert "closed loop T=12" in out and "min-max, linear n=2, M=4" in out and "pendulum min-max M=5" in out
    assert "demo #1 (M: 3, a: 2)" in out and "5/5 moves re-drew the figure" in out
    assert "targets not judged" in out


def test_widget_benchmark_drives_every_explorer_in_a_kernel():
    """Two explorers in one kernel: each found from the cell outputs, each slider driven through its
    values and back; every move re-draws (a new PNG in the explorer's image), from the frames drawn
    ahead while the kernel was idle, and again with the frames forgotten."""
    cells = widgets.DEMO_CELLS + ["orrc.viz.explore(plot, M=[3, 4], a=[0.5], initial={'M': 4})"]
    first, second = widgets.drive_cells(cells)
    assert first["params"] == {"M": 3, "a": 2} and second["params"] == {"M": 2, "a": 1}
    assert len(first["times"]) == 3 + 2 and len(second["times"]) == 2      # every other value, then back
    for r, n in ((first, 6), (second, 2)):
        assert r["redrawn"] == len(r["times"]) and r["cold_redrawn"] == len(r["cold"]) == len(r["times"])
        # the first moves (one per slider and back) came right after the cells ran: each frame was drawn
        # once, ahead or on the move, and every other move was shown from the cache
        assert r["first_redrawn"] == len(r["first"]) == 2 * sum(k > 1 for k in r["params"].values())
        assert 0 <= r["first_on_move"] <= len(r["first"]) // 2     # a move back finds its frame drawn
        st = r["stats"]
        assert st["on_move"] + st["ahead"] == n - 1 and st["cached"] + st["on_move"] == len(r["times"]) + len(r["first"])
        assert all(t > 0 for t in r["times"] + r["cold"])


def test_widget_benchmark_catches_a_slider_that_redraws_nothing():
    cells = ["import ipywidgets as w\nw.VBox([w.SelectionSlider(options=[1, 2, 3]), w.Image(format='png')])"]
    cells.append("from IPython.display import display\nbar = w.HBox([w.FloatProgress()]); display(bar); bar.close()")
    (r,) = widgets.drive_cells(cells)          # the closed widget (a finished progress bar) is no explorer
    assert r["redrawn"] == 0 and len(r["times"]) == 3 and r["stats"] is None


def test_minmax_benchmark_runs_and_its_methods_agree():
    rows = minmax.run(Ms=(3, 4), reps=1, M_pendulum=4, T=3)
    lin = [r for r in rows if r.benchmark.startswith("min-max, linear")]
    assert [r.data["M"] for r in lin] == [3, 4]
    for r in lin:
        assert r.data["gap"] <= 1e-6 and r.data["scenarios"] <= r.data["sequences"]
        assert r.data["vertex_sequences"] == 2 ** (2 * r.data["M"]) and r.data["t_exact"] > 0
    step = next(r for r in rows if "closed-loop step" in r.benchmark)
    assert step.ok is not None and step.data["t_step"] > 0 and step.data["iterations"] <= minmax.PENDULUM_MAX_ITERATIONS


def test_minmax_benchmark_catches_an_exchange_that_disagrees(monkeypatch):
    real = orrc.MinMaxRHC.plan

    def off(self, x, *a, **k):
        p = real(self, x, *a, **k)
        if self.method == "exchange":
            p.value *= 1.01
        return p

    monkeypatch.setattr(orrc.MinMaxRHC, "plan", off)
    with pytest.raises(CheckFailed, match="values differ"):
        minmax.run(Ms=(3,), reps=1, M_pendulum=4, T=2)


def test_comparison_table_has_every_controller_and_the_clairvoyant_is_never_beaten(capsys):
    rows = comparison.run(T=8, M=3)
    kinds = {r.data["kind"] for r in rows}
    assert len(kinds) == 4 and len(rows) == 4 * 9
    for kind in kinds:
        rs = [r.data["row"] for r in rows if r.data["kind"] == kind]
        clair = rs[-1].cost
        assert rs[-1].name == "clairvoyant optimum" and all(clair <= r.cost * (1 + 1e-9) for r in rs)
        assert all(r.dynamic_regret == pytest.approx(r.cost - clair) for r in rs)
    assert run.main(["--quick", "--only", "comparison"]) == 0
    out = capsys.readouterr().out
    assert "regret-optimal (T = 10)" in out and "H∞, preview 4" in out


def test_peers_orrc_and_the_bare_casadi_loop_reach_the_same_closed_loop():
    rows = peers.run(T=10, M=5, reps=1, reps_control=1, peers=())
    bare = rows[0]
    assert bare.data["t_orrc"] > 0 and bare.data["t_bare"] > 0 and np.isfinite(bare.data["J"])
    assert "BLAS threads" in bare.check and "python-control" in rows[-1].case


def test_peers_check_catches_a_different_closed_loop(monkeypatch):
    real = peers.BareCasadiLoop.__call__

    def off(self, x0, w, T, read_status=False):
        X, U = real(self, x0, w, T, read_status)
        return X, U + 1e-3

    monkeypatch.setattr(peers.BareCasadiLoop, "__call__", off)
    with pytest.raises(CheckFailed, match="not the same closed loop"):
        peers.run(T=10, M=5, reps=1, reps_control=1, peers=())


def test_a_peer_that_cannot_be_installed_is_skipped_with_the_reason(monkeypatch):
    monkeypatch.setattr(peers, "peer_python", lambda name: (None, "no network"))
    report, reason = peers.run_peer("acados", peers.problem(5, 3), 1)
    assert report is None and "acados could not be installed (no network)" in reason


def test_regret_benchmark_structured_equals_the_sdp():
    rows = regret.run(sizes=((8, 2, 1, 5.0),), sdp_size=(5, 2, 1))
    assert abs(rows[-1].data["gap"]) <= 1e-6 and rows[0].ok is not None
