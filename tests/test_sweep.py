"""orrc.sweep: a parameter study gives the same table serially, on local processes and on Dask.

The experiment is a small closed loop: Algorithm 1 (PreviewRHC, the exact LQ law) on the double
integrator under random disturbances, over a grid of horizons M and seeds; and Algorithm 1 on the
Van der Pol oscillator (a CasADi NLP built inside the function, as the parallel backends need).
"""
import sys
import warnings

import numpy as np
import pytest

import orrc

DI = orrc.examples.double_integrator()
VDP = orrc.examples.van_der_pol(dt=0.3, input_weight=0.01)
T = 30
GRID = {"M": [1, 3, 6], "radius": [0.1, 0.5]}


def closed_loop(M, radius, seed):
    """Algorithm 1 on the double integrator: total cost, attenuation ratio and the state trajectory."""
    w = orrc.disturbances.uniform_ball(T + M, 2, radius, seed=seed)
    tr = orrc.simulate(DI.system, orrc.PreviewRHC(DI.system, DI.cost, M), np.array([1.0, 0.0]), w, T)
    return {"cost": float(tr.costs.sum()), "ratio": orrc.attenuation_ratio(tr), "x": tr.x}


def nonlinear_loop(M, seed):
    """Algorithm 1 on Van der Pol: the NLP controller is built here, in the worker (CasADi does not pickle)."""
    w = orrc.disturbances.uniform_ball(8 + M, 2, 0.1, seed=seed)
    rhc = orrc.PreviewRHC(VDP.system, VDP.cost, M, input_bounds=VDP.input_bounds)
    tr = orrc.simulate(VDP.system, rhc, np.array([0.5, 0.0]), w, 8)
    return {"cost": float(tr.costs.sum()), "u": tr.u}


def fails_at_M3(M, radius, seed):
    if M == 3 and radius == 0.5:
        raise ZeroDivisionError("M = 3 is where it breaks")
    return M * radius


def warns(M, radius):
    warnings.warn(f"warned at M={M}", orrc.SolverWarning)
    return M


def config_seen(M):
    import os

    return {"max_ops": orrc.config.get_limits().max_ops, "quick": os.environ.get("ORRC_QUICK")}


def same(a, b) -> bool:
    """Bit for bit: equal types, equal keys in the same order, floats and arrays equal to the last bit."""
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return list(a) == list(b) and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
    if isinstance(a, float):
        return np.float64(a).tobytes() == np.float64(b).tobytes()
    return a == b


def identical(a, b) -> bool:
    """Two tables (or lists of rows) are the same bit for bit."""
    return same(list(a), list(b))


@pytest.fixture(scope="module")
def client():
    """A Dask LocalCluster of 2 worker processes, started once for the module and closed after it."""
    distributed = pytest.importorskip("distributed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # the cluster's own start-up notices
        cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                           silence_logs=40)
        c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_serial_processes_and_dask_give_bit_identical_tables(client):
    serial = orrc.sweep(closed_loop, GRID, seeds=2, backend="serial")
    procs = orrc.sweep(closed_loop, GRID, seeds=2, backend="processes", workers=2)
    dask = orrc.sweep(closed_loop, GRID, seeds=2, client=client)
    assert len(serial) == 3 * 2 * 2
    assert identical(serial, procs) and identical(serial, dask)
    # ... and the runs really differ (the comparison could fail): different seeds, different costs
    assert len(set(serial.column("cost"))) == len(serial)


def test_a_nonlinear_controller_built_in_the_worker_gives_the_serial_result():
    grid = {"M": [4, 8]}
    assert identical(orrc.sweep(nonlinear_loop, grid, seeds=[0], backend="serial"),
                     orrc.sweep(nonlinear_loop, grid, seeds=[0], backend="processes", workers=2))


def test_rows_follow_the_grid_order_last_parameter_fastest_then_seeds():
    table = orrc.sweep(closed_loop, GRID, seeds=2, backend="processes", workers=2, chunksize=1)
    order = [(r["M"], r["radius"], r["replicate"]) for r in table]
    assert order == [(M, rad, k) for M in GRID["M"] for rad in GRID["radius"] for k in range(2)]
    points = [{"M": 6, "radius": 0.1}, {"M": 1, "radius": 0.5}]     # a list of dicts: its own order
    table = orrc.sweep(closed_loop, points, seeds=[3], backend="processes", workers=2)
    assert [(r["M"], r["radius"]) for r in table] == [(6, 0.1), (1, 0.5)]


def test_seeds_depend_on_the_grid_point_not_on_workers_or_chunks():
    a = orrc.sweep(closed_loop, GRID, seeds=3, seed=7, backend="serial")
    b = orrc.sweep(closed_loop, GRID, seeds=3, seed=7, backend="processes", workers=2, chunksize=5)
    assert identical(a, b)
    seeds = a.column("seed")
    assert len(set(seeds)) == seeds.size, "independent seeds at every point and replicate"
    # a row is reproduced by calling fn with its point and seed
    row = a[4]
    assert identical([closed_loop(row["M"], row["radius"], row["seed"])], [{k: row[k] for k in ("cost", "ratio", "x")}])
    # another root seed, other seeds
    assert not set(seeds) & set(orrc.sweep(closed_loop, GRID, seeds=3, seed=8, backend="serial").column("seed"))


def test_common_seeds_are_the_same_at_every_grid_point():
    table = orrc.sweep(closed_loop, GRID, seeds=2, common_seeds=True, backend="serial")
    by_point = {}
    for r in table:
        by_point.setdefault((r["M"], r["radius"]), []).append(r["seed"])
    assert len({tuple(s) for s in by_point.values()}) == 1 and len(set(next(iter(by_point.values())))) == 2
    given = orrc.sweep(closed_loop, GRID, seeds=[11, 12], backend="serial")
    assert [r["seed"] for r in given] == [11, 12] * 6


def test_an_error_names_the_grid_point_and_seed_that_raised(client):
    for kw in ({"backend": "serial"}, {"backend": "processes", "workers": 2}, {"client": client}):
        with pytest.raises(orrc.SweepError) as info:
            orrc.sweep(fails_at_M3, GRID, seeds=[5], **kw)
        err = info.value
        assert "M=3, radius=0.5, seed=5" in str(err) and "ZeroDivisionError" in str(err), kw
        assert isinstance(err.__cause__, ZeroDivisionError) and err.point == {"M": 3, "radius": 0.5} and err.seed == 5
        assert err.row == 3, "run 4 of 6 in grid order"


def test_on_error_record_keeps_the_other_runs():
    table = orrc.sweep(fails_at_M3, GRID, seeds=[5], on_error="record", backend="processes", workers=2)
    bad = table.errors()
    assert [(r["M"], r["radius"]) for r in bad] == [(3, 0.5)] and "ZeroDivisionError" in bad[0]["error"]
    assert [r["value"] for r in table if "error" not in r] == [0.1, 0.5, 0.30000000000000004, 0.6000000000000001, 3.0]


def test_warnings_raised_in_workers_reach_the_caller():
    with pytest.warns(orrc.SolverWarning) as record:
        orrc.sweep(warns, {"M": [1, 2], "radius": [0.1]}, backend="processes", workers=2)
    assert sorted(str(w.message) for w in record if w.category is orrc.SolverWarning) == ["warned at M=1",
                                                                                           "warned at M=2"]


def test_workers_see_this_process_limits_and_run_size(monkeypatch):
    monkeypatch.setenv("ORRC_QUICK", "1")
    with orrc.config.limits(max_ops=3e11):
        table = orrc.sweep(config_seen, {"M": [1, 2]}, backend="processes", workers=2)
    assert [r["max_ops"] for r in table] == [3e11, 3e11] and [r["quick"] for r in table] == ["1", "1"]


def test_no_progress_bar_in_tests_or_the_book_build_and_one_on_request(capfd, monkeypatch):
    orrc.sweep(closed_loop, GRID, seeds=1, backend="processes", workers=2)    # not a terminal: silent
    assert capfd.readouterr().err == ""
    # on request: a bar, in a fresh interpreter (tqdm.auto picks its kind once per process, and other
    # tests of the session run in-process IPython shells)
    import subprocess

    code = "import orrc; orrc.sweep(lambda M: M, {'M': [1, 2, 3]}, backend='serial', progress=True)"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "3/3" in run.stderr, run.stderr[-2000:]
    from orrc._progress import watched    # the sweep's bar follows orrc.progress's rule

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert watched()
    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    assert not watched(), "the book's build shows no progress bar"


def test_auto_starts_processes_only_when_idle_cores_save_time(monkeypatch):
    sweep_module = sys.modules["orrc._sweep_run"]
    monkeypatch.setattr(sweep_module, "_cores", lambda: 2)
    monkeypatch.setattr(sweep_module.os, "getloadavg", lambda: (0.2, 0.2, 0.2))     # an idle machine
    assert sweep_module._auto(1.0, 10, 8) == ("processes", 2)       # 10 runs of 1 s: saves 5 s
    assert sweep_module._auto(0.01, 10, 8) == ("serial", 1)         # 0.1 s of work: not worth a pool
    assert sweep_module._auto(1.0, 10, 1) == ("serial", 1)          # workers=1
    monkeypatch.setattr(sweep_module.os, "getloadavg", lambda: (5.0, 5.0, 5.0))     # other jobs hold the cores
    assert sweep_module._auto(1.0, 10, 8) == ("serial", 1)


def test_auto_gives_the_table_of_every_backend():
    import os

    auto = orrc.sweep(lambda M, seed: {**closed_loop(M, 0.1, seed), "pid": os.getpid()}, {"M": [1, 3]}, seeds=2)
    assert auto[0]["pid"] == os.getpid(), "the first run is timed in this process"
    serial = orrc.sweep(closed_loop, {"M": [1, 3], "radius": [0.1]}, seeds=2, backend="serial")
    assert identical([{k: v for k, v in r.items() if k != "pid"} for r in auto],
                     [{k: v for k, v in r.items() if k != "radius"} for r in serial])


def test_a_one_run_grid_runs_in_this_process():
    import os

    table = orrc.sweep(lambda: {"pid": os.getpid()}, {})
    assert table.columns == ["pid"] and table[0]["pid"] == os.getpid()


def test_the_table_helpers():
    table = orrc.sweep(closed_loop, GRID, seeds=2, backend="serial")
    assert table.params == ("M", "radius") and table.columns == ["M", "radius", "seed", "replicate", "cost", "ratio",
                                                                 "x"]
    assert table.column("x").shape == (12, T + 1, 2)
    sub = table.where(M=6, radius=0.5)
    assert len(sub) == 2 and all(r["M"] == 6 for r in sub)
    rec = table.to_records()
    assert rec.dtype.names == ("M", "radius", "seed", "replicate", "cost", "ratio")
    assert np.array_equal(rec["cost"], table.column("cost"))


def test_exploration_tradeoff_measures_the_same_on_every_backend(client):
    """Theorem 2's trade-off (one sweep task per seed; the model, a LinearParametricSystem, travels to the
    workers as its constructor's arguments)."""
    from orrc.tradeoff import exploration_tradeoff

    system = orrc.LinearSystem([[0.5]], [[1.0]])
    args = (system, orrc.ParametricSystem.linear(1, 1), orrc.L1Cost([1.0], [[0.1]]), 3, np.array([10, 20, 40]))
    kw = dict(seeds=3, window=40, excitation_amplitude=0.5, theta_true=[0.5, 1.0])
    runs = [exploration_tradeoff(*args, backend=b, **kw) for b in ("serial", "processes")]
    runs.append(exploration_tradeoff(*args, client=client, **kw))
    fields = ("explore_cost", "known_cost", "transient", "loss", "errors")
    for other in runs[1:]:
        assert same([getattr(runs[0], f) for f in fields], [getattr(other, f) for f in fields])
        assert runs[0].c0 == other.c0 and runs[0].fit == other.fit
    assert len(set(runs[0].loss[:, 0])) == 3, "the seeds differ"


# -- the book: a chapter's sweeps give the same tables whatever the backend ----------------------------------
def _chapters_with_sweeps():
    from conftest import ROOT
    from tools.toc import notebook_pages

    return [ch for ch in notebook_pages() if "orrc.sweep(" in (ROOT / f"{ch}.md").read_text(encoding="utf-8")]


def _sweep_checks(source: str) -> list[str]:
    """For each ``name = orrc.sweep(...)`` of a cell's source: the code that runs the same sweep serially
    and fails unless its table is ``name``'s, bit for bit (every value's pickle equal: a float's pickle
    is its 8 bytes; the rows as a whole are not compared by pickle, which also records which rows share
    an object)."""
    import ast

    checks = []
    for node in ast.walk(ast.parse(source)):
        if (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)
                and isinstance(node.value, ast.Call) and ast.unparse(node.value.func) == "orrc.sweep"):
            call = node.value
            serial = ast.Call(call.func, call.args, [k for k in call.keywords if k.arg not in ("backend", "client")]
                              + [ast.keyword("backend", ast.Constant("serial"))])
            name = node.targets[0].id
            checks.append(f"import pickle as _pickle\n_serial = {ast.unparse(serial)}\n"
                          f"_bits = lambda t: [[(k, _pickle.dumps(v)) for k, v in row.items()] for row in t]\n"
                          f"assert _bits({name}) == _bits(_serial), "
                          f"'{name}: the table on processes differs from the serial one'")
    return checks


def test_the_sweep_check_runs_each_sweep_serially_and_compares_its_table():
    import types

    code = 'table = orrc.sweep(levels, {"M": Ms}, backend="auto")\nother = sweep(f, {})'
    (check,) = _sweep_checks(code)
    calls = []
    fake = types.SimpleNamespace(sweep=lambda fn, grid, **kw: calls.append(kw) or [{"M": 1, "g": 0.5}])
    namespace = {"orrc": fake, "levels": None, "Ms": [1], "table": [{"M": 1, "g": 0.5}]}
    exec(check, namespace)
    assert calls == [{"backend": "serial"}]
    namespace["table"] = [{"M": 1, "g": 0.5 + 2.0 ** -53}]   # the last bit differs
    with pytest.raises(AssertionError, match="table: the table on processes differs"):
        exec(check, namespace)


@pytest.mark.slow
@pytest.mark.parametrize("chapter", _chapters_with_sweeps())
def test_a_chapters_sweeps_give_on_processes_the_tables_they_give_serially(chapter, monkeypatch):
    """A chapter's sweeps run its own functions (defined in the notebook, sent to the workers by cloudpickle
    with the systems they read). Its cells run in a kernel up to its last sweep, every sweep on worker
    processes (ORRC_SWEEP_BACKEND=processes); after each sweep the same sweep runs serially in that kernel,
    and the two tables are the same, bit for bit. The numbers the chapter glues are computed from these
    tables, so the chapter glues the same numbers whatever the backend."""
    import jupytext
    from nbclient import NotebookClient
    from nbformat.v4 import new_code_cell

    from conftest import ROOT

    monkeypatch.setenv("ORRC_SWEEP_BACKEND", "processes")
    monkeypatch.setenv("ORRC_QUICK", "1")
    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = jupytext.read(ROOT / f"{chapter}.md")
    cells, last = [], 0   # the code cells, each sweep's check after it; up to the last check
    for cell in (c for c in nb.cells if c.cell_type == "code"):
        checks = _sweep_checks(cell.source) if "orrc.sweep(" in cell.source else []
        cells += [cell, *(new_code_cell(c) for c in checks)]
        last = len(cells) if checks else last
    assert last > 0, f"{chapter}: no `name = orrc.sweep(...)` found"
    nb.cells = cells[:last]
    NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(ROOT / "book")}}).execute()


@pytest.mark.slow
def test_no_chapter_of_the_build_shows_a_progress_bar(book):
    """The build sets ORRC_BOOK_BUILD=1: the sweeps of the chapters leave no tqdm bar in the executed notebooks."""
    import nbformat

    from conftest import BOOK_OUT
    from tools.toc import notebook_pages

    for chapter in notebook_pages():
        nb = nbformat.read(BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.ipynb", as_version=4)
        bars = [i for i, c in enumerate(nb.cells) for o in c.get("outputs", []) if "orrc.sweep:" in str(o)]
        assert not bars, f"{chapter}: a progress bar in the output of cells {bars}"
