"""Compiled copies (orrc._jit): the warm SQP step's solver and acceptance checks as machine code give
the interpreted ones' answers bit for bit, are built once per machine, and are optional."""
import copy
import ctypes
import os
import time
import warnings

import casadi as ca
import numpy as np
import pytest

import orrc
from orrc import _jit
from orrc._casadi import Buffered
from orrc.solvers import nlp as nlp_module
from runs import pendulum_case, same_runs

pytestmark = pytest.mark.skipif(_jit.compiler() is None, reason="no C compiler on this machine")


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """One cache for this module's tests (each library is built once here)."""
    return tmp_path_factory.mktemp("jit-cache")


@pytest.fixture
def compile_now(monkeypatch, cache):
    """Compiled copies asked for from the first warm step, cached in ``cache``."""
    monkeypatch.setattr(nlp_module, "COMPILE_AFTER", 0)
    monkeypatch.setenv("ORRC_CACHE_DIR", str(cache))
    monkeypatch.delenv("ORRC_JIT", raising=False)


def _wait(rhc):
    for job in rhc._nlp._jit.values():
        job.wait()


def _run(system, rhc, x0, w, costs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", orrc.SolverWarning)
        return orrc.simulate(system, rhc, x0, w, 40, costs=costs)


@pytest.mark.parametrize("case", ["accepted", "steps fail", "time-varying cost"])
def test_a_closed_loop_with_the_compiled_solver_and_checks_is_the_interpreted_one(case, compile_now, monkeypatch):
    """The warm SQP step switches to the compiled solver and checks once they are built; the closed loop
    is bit for bit the one of a controller that never compiles (ORRC_JIT=0), failed steps and the iteration
    counts (read from the compiled solver's own statistics) included."""
    system, cost, kw, x0, w, costs = pendulum_case(case)
    rhc = orrc.PreviewRHC(system, cost, **kw)
    first = _run(system, rhc, x0, w, costs)   # asks for the compiled copies
    _wait(rhc)
    assert rhc._nlp.compile_error("sqp") is None and rhc._nlp.compile_error("acceptance") is None
    second = _run(system, rhc, x0, w, costs)
    solver = rhc._nlp._call("sqp-compiled")
    assert solver.counter is not None and solver.counter_checks == _jit.COUNTER_CHECKS, \
        "the compiled solver took the warm steps, its iteration counter checked against its statistics"
    monkeypatch.setenv("ORRC_JIT", "0")
    plain = orrc.PreviewRHC(system, cost, **kw)
    interpreted = _run(system, plain, x0, w, costs)
    assert plain._nlp.compile_error("sqp") is not None and "ORRC_JIT=0" in plain._nlp.compile_error("sqp")
    same_runs(first, interpreted)
    same_runs(second, interpreted)


def test_the_compiled_acceptance_checks_give_the_interpreted_values(compile_now):
    """On random answers with zeros, infinities and NaNs in them, the compiled checks give the interpreted
    values (a NaN where it gives NaN) and the same verdict."""
    ex = orrc.examples.inverted_pendulum()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    fn = rhc._nlp._acceptance
    fast = Buffered(_jit.compiled_function(fn).wait())
    slow = Buffered(fn)
    rng = np.random.default_rng(1)
    for _ in range(500):
        for a, b in zip(slow.args, fast.args):
            v = rng.normal(size=a.shape) * rng.choice([1e-12, 1.0, 1e8], size=a.shape)
            special = rng.integers(0, 8)
            if special < 4:
                v[rng.integers(0, v.size)] = (np.nan, np.inf, -np.inf, 0.0)[special]
            a[:], b[:] = v, v
        slow.evaluate()
        fast.evaluate()
        for r, s in zip(slow.res, fast.res):
            assert np.array_equal(r, s, equal_nan=True)


def test_a_library_is_built_once_and_then_loaded_from_the_cache(compile_now, cache):
    """A second controller on the same problem loads the library its first one built: no compiler runs."""
    ex = orrc.examples.inverted_pendulum()
    first = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    job = _jit.compiled_function(first._nlp._acceptance)
    assert job.wait() is not None and job.path.parent == cache
    built = job.path.stat().st_mtime_ns
    second = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    again = _jit.compiled_function(second._nlp._acceptance)
    assert again.path == job.path and not again.building and again.function() is not None
    assert job.path.stat().st_mtime_ns == built


@pytest.mark.parametrize("cc", ["/nonexistent/cc", "false"])
def test_without_a_working_compiler_the_interpreted_functions_take_every_step(cc, compile_now, monkeypatch, tmp_path):
    """No compiler, or one that fails: the reason is kept, the interpreted solver and checks run, the same run."""
    monkeypatch.setenv("CC", cc)
    monkeypatch.setenv("ORRC_CACHE_DIR", str(tmp_path))   # nothing cached: the compiler must run
    system, cost, kw, x0, w, costs = pendulum_case("accepted")
    rhc = orrc.PreviewRHC(system, cost, **kw)
    run = _run(system, rhc, x0, w, costs)
    _wait(rhc)
    again = _run(system, rhc, x0, w, costs)
    error = rhc._nlp.compile_error("sqp")
    assert error is not None and ("no C compiler" in error if cc.startswith("/") else "failed" in error), error
    assert rhc._nlp.compiled("sqp") is None and rhc._nlp.compiled("acceptance") is None
    monkeypatch.setenv("ORRC_JIT", "0")
    same_runs(run, _run(system, orrc.PreviewRHC(system, cost, **kw), x0, w, costs))
    same_runs(again, run)


def test_a_copied_controller_leaves_its_compiled_copies_behind_and_loads_them_again(compile_now):
    """A controller copied after compiling (as pickling does: DropsBuffers) carries no library or thread; its copy loads the cached library
    on its own warm steps and runs the same closed loop."""
    system, cost, kw, x0, w, costs = pendulum_case("accepted")
    rhc = orrc.PreviewRHC(system, cost, **kw)
    run = _run(system, rhc, x0, w, costs)
    _wait(rhc)
    twin = copy.deepcopy(rhc)
    assert twin._nlp._jit == {}
    same_runs(_run(system, twin, x0, w, costs), run)
    assert twin._nlp.compiled("sqp") is not None


def test_a_very_long_c_code_is_not_compiled(compile_now, monkeypatch):
    """C code past CODE_LIMIT would take the compiler longer than it saves: the interpreted one stays."""
    monkeypatch.setattr(_jit, "CODE_LIMIT", 1000)
    ex = orrc.examples.inverted_pendulum()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    job = _jit.compiled_function(rhc._nlp._acceptance)
    assert job.function() is None and "characters of C code" in job.error and not job.building


def test_an_iteration_counter_that_disagrees_with_the_statistics_is_dropped_for_them(compile_now):
    """Were the compiled solver to evaluate its Hessian other than once per iteration, its counter would
    disagree with CasADi's statistics on the first solves it is checked on: the warm step drops it and
    reads the statistics, and the run is the same (here a counter that never moves)."""
    system, cost, kw, x0, w, costs = pendulum_case("accepted")
    rhc = orrc.PreviewRHC(system, cost, **kw)
    reference = _run(system, rhc, x0, w, costs)
    _wait(rhc)
    solver = rhc._nlp._call("sqp-compiled")
    solver.counter, solver.counter_checks = ctypes.c_longlong(0), 0
    same_runs(_run(system, rhc, x0, w, costs), reference)
    assert solver.counter is None and solver.counts_accumulate is not None


def test_a_controller_compiles_when_asked_and_says_why_it_cannot(compile_now, monkeypatch):
    """PreviewRHC.compile(wait=True) builds both copies before any solve (True), and plan() uses them at
    the interpreted optimum; on the exact LQ path, or with ORRC_JIT=0, it returns False and says why."""
    ex = orrc.examples.inverted_pendulum()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    assert rhc.compile_error() is None and rhc.compile(wait=True) and rhc.compile_error() is None
    W = np.zeros((10, 2))
    plan = rhc.plan(np.array([0.5, 0.0]), W)
    monkeypatch.setenv("ORRC_JIT", "0")
    plain = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    assert not plain.compile(wait=True) and "ORRC_JIT=0" in plain.compile_error()
    other = plain.plan(np.array([0.5, 0.0]), W)
    assert np.array_equal(plan.inputs, other.inputs) and plan.value == other.value
    assert plan.iterations == other.iterations and plan.status == other.status
    lq = orrc.PreviewRHC(orrc.LinearSystem(np.eye(2), np.eye(2)), orrc.QuadraticCost(np.eye(2), np.eye(2)), 5)
    assert not lq.compile(wait=True) and "NLP path" in lq.compile_error()


def test_a_cold_step_on_the_compiled_solver_reads_its_iterations_from_its_counter(compile_now):
    """plan() on the compiled solver: its first solves check the counter against the statistics, later ones
    read the counter alone; every plan equals the interpreted solver's, iterations and status included."""
    ex = orrc.examples.inverted_pendulum()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    assert rhc.compile(wait=True)
    solver = rhc._nlp.compiled("sqp")
    states = [np.array([a, 0.0]) for a in (0.2, 0.5, 1.0, 1.5, 0.3)]
    W = np.zeros((10, 2))
    plans = [rhc.plan(x, W) for x in states]
    assert solver.counter is not None and solver.counter_checks >= _jit.COUNTER_CHECKS
    plain = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    for x, plan in zip(states, plans):
        other = plain.plan(x, W)   # interpreted (not compiled: too few solves)
        assert np.array_equal(plan.inputs, other.inputs) and plan.value == other.value
        assert (plan.iterations, plan.status, plan.success) == (other.iterations, other.status, other.success)


def test_the_folder_of_a_build_left_by_an_ended_process_is_removed(compile_now, cache):
    """A build folder older than twice BUILD_SECONDS (its process ended while the compiler ran) is removed
    by the next build; a recent one (a build under way elsewhere) is left alone."""
    stale, fresh = cache / (_jit._BUILD_PREFIX + "stale"), cache / (_jit._BUILD_PREFIX + "fresh")
    for folder in (stale, fresh):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "half.c").write_text("/* a build that never ended */")
    old = time.time() - 3 * _jit.BUILD_SECONDS
    os.utime(stale, (old, old))
    x = ca.SX.sym("x")
    job = _jit.compiled_function(ca.Function("stale_test", [x], [ca.sin(x) * 3.25]))
    assert job.wait() is not None
    assert not stale.exists() and fresh.exists()
