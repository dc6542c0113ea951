import os
import shutil
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

# the repository root, so that `benchmarks` and `tools` import under plain `pytest` too
# (`python -m pytest` from the root, as `make test` runs it, has it already)
ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

# Where the test session builds the book: a folder of its own, never the published
# _build/html (which only `make book` writes, at full size). ORRC_BOOK_OUT=/some/dir moves
# everything the tests write (the test build and the screenshots) to /some/dir/_build.
BUILD_ROOT = Path(os.environ.get("ORRC_BOOK_OUT", ROOT)) / "_build"
BOOK_OUT = BUILD_ROOT / "test"          # jupyter-book's --path-output for the test build
BOOK_HTML = BOOK_OUT / "_build" / "html"
BOOK_LOG = BOOK_OUT / "book-build.log"   # everything the session's book build printed
PUBLISHED_HTML = ROOT / "_build" / "html"
SHOTS = BUILD_ROOT / "screenshots"
# the libraries that controllers compile (orrc._jit) go to the build folder, not the user's ~/.cache
# (the chapters' kernels and the fresh environments inherit it)
os.environ.setdefault("ORRC_CACHE_DIR", str(BUILD_ROOT / "jit-cache"))


def tree_fingerprint(folder: Path):
    """(relative path, size, mtime in ns) of every file below ``folder``, sorted; None when it
    does not exist. Two equal fingerprints: nothing was written, touched or removed there."""
    folder = Path(folder)
    if not folder.exists():
        return None
    return sorted((str(p.relative_to(folder)), p.stat().st_size, p.stat().st_mtime_ns)
                  for p in folder.rglob("*") if p.is_file())


# ---------------------------------------------------------------- the session's timeline
# When each background job (the book's build, the gradings, the jobs that wait on them) ran, and when
# the tests in the main thread waited for one: printed at the end of the run with the slowest tests
# and the critical path (pytest_terminal_summary), and written to _build/test-timeline.json.
_T0 = time.time()
_JOBS: dict[str, dict] = {}
_WAITS: list[dict] = []
_TESTS: list[dict] = []
_TIMELINE_LOCK = threading.Lock()


class timed:
    """``with timed(name, after=...)``: record when the background job ``name`` ran (``after``: the
    job it waited for before it started)."""

    def __init__(self, name: str, after: str | None = None):
        self.name, self.after = name, after

    def __enter__(self):
        self.start = time.time()

    def __exit__(self, *exc):
        with _TIMELINE_LOCK:
            _JOBS[self.name] = {"start": self.start - _T0, "end": time.time() - _T0, "after": self.after}


def _wait_for(name: str, future):
    """``future.result()``, recording how long the main thread waited for it."""
    if threading.current_thread() is not threading.main_thread() or future.done():
        return future.result()
    start = time.time()
    try:
        return future.result()
    finally:
        with _TIMELINE_LOCK:
            _WAITS.append({"job": name, "start": start - _T0, "end": time.time() - _T0})


def pytest_sessionstart(session):
    global _T0
    _T0 = time.time()


def pytest_runtest_logreport(report):
    with _TIMELINE_LOCK:
        _TESTS.append({"id": report.nodeid, "when": report.when, "start": report.start - _T0,
                       "end": report.stop - _T0})


def critical_path(end: float, jobs: dict, waits: list[dict]) -> list[tuple[str, float, float]]:
    """The chain of work that decided the session's length, as (what, start, end) seconds from the
    session's start: the background job the tests waited for last, what that job waited for before
    it started, and the tests in the main thread after it; without a wait, the tests alone."""
    if not waits:
        return [("the tests in the main thread", 0.0, end)]
    last = max(waits, key=lambda w: w["end"])
    chain, name = [], last["job"]
    while name in jobs:
        chain.insert(0, (name, jobs[name]["start"], jobs[name]["end"]))
        name = jobs[name]["after"]
    if chain and chain[0][1] > 0.5:
        chain.insert(0, ("collection and the tests before it", 0.0, chain[0][1]))
    chain.append(("the tests after it", last["end"], end))
    return chain


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    """The slowest tests, the background jobs and the critical path, at the end of the run."""
    import json

    end = time.time() - _T0
    with _TIMELINE_LOCK:
        tests, jobs, waits = list(_TESTS), dict(_JOBS), list(_WAITS)
    if not tests:
        return
    per_test: dict[str, float] = {}
    for t in tests:
        per_test[t["id"]] = per_test.get(t["id"], 0.0) + t["end"] - t["start"]
    waited = sum(w["end"] - w["start"] for w in waits)
    tr = terminalreporter
    tr.section("the suite's time")
    tr.write_line(f"{end:.0f} s in all; {len(per_test)} tests; the main thread waited {waited:.0f} s for background jobs")
    tr.write_line("slowest tests (setup + call + teardown, waits for a background job included):")
    for nodeid, seconds in sorted(per_test.items(), key=lambda kv: -kv[1])[:15]:
        tr.write_line(f"  {seconds:7.1f} s  {nodeid}")
    modules: dict[str, float] = {}
    for nodeid, seconds in per_test.items():
        modules[nodeid.split("::")[0]] = modules.get(nodeid.split("::")[0], 0.0) + seconds
    tr.write_line("slowest test files:")
    for module, seconds in sorted(modules.items(), key=lambda kv: -kv[1])[:10]:
        tr.write_line(f"  {seconds:7.1f} s  {module}")
    if jobs:
        tr.write_line("background jobs (seconds from the session's start):")
        for name, j in sorted(jobs.items(), key=lambda kv: kv[1]["start"]):
            w = sum(x["end"] - x["start"] for x in waits if x["job"] == name)
            tr.write_line(f"  {name:<18} {j['start']:6.0f} -> {j['end']:6.0f}  ({j['end'] - j['start']:5.0f} s;"
                          f" the tests waited {w:4.0f} s for it)")
    path = critical_path(end, jobs, waits)
    tr.write_line("critical path: " + " -> ".join(f"{n} {a:.0f}-{b:.0f} s" for n, a, b in path))
    BUILD_ROOT.mkdir(parents=True, exist_ok=True)
    (BUILD_ROOT / "test-timeline.json").write_text(json.dumps(
        {"seconds": end, "jobs": jobs, "waits": waits, "critical_path": path,
         "slowest": sorted(per_test.items(), key=lambda kv: -kv[1])[:30]}, indent=1))


_BOOK = {}
_READER = {}


def _start_reader():
    """Start building (or finding) the environment whose kernels execute the chapters, in a thread
    of its own; once per session."""
    from concurrent.futures import ThreadPoolExecutor

    from fresh_env import reader_env

    if "future" in _READER:
        return

    def run():
        with timed("reader environment"):
            return reader_env()

    pool = ThreadPoolExecutor(max_workers=1)
    _READER["future"] = pool.submit(run)
    pool.shutdown(wait=False)


@pytest.hookimpl(tryfirst=True)
def pytest_collection(session):
    """When the whole suite runs (``make test``: the tests folder, nothing selected out), the
    environment the book's build waits for starts building now, beside the collection, which
    keeps one core busy only."""
    opt = session.config.option
    whole = [Path(a).resolve() for a in session.config.args] in ([ROOT / "tests"], [ROOT])
    if whole and not (opt.keyword or opt.markexpr or opt.collectonly or getattr(opt, "lf", False)
                      or getattr(opt, "deselect", None)):
        _start_reader()


def _start_book():
    """Start the session's one book build in a thread of its own (the build is a jupyter-book
    subprocess): the tests that do not need the book run beside it (they are ordered first,
    pytest_collection_modifyitems), so the second core is not idle while the chapters execute."""
    from concurrent.futures import ThreadPoolExecutor

    from tools.build_book import build

    _start_reader()

    def run():
        published = tree_fingerprint(PUBLISHED_HTML)
        started, t0 = time.time(), time.perf_counter()
        # every chapter is executed once per session, here, by a kernel of the environment its download
        # installs (tests/fresh_env.py: built once, reused while requirements-reader.txt and the package
        # do not change), in a temporary folder; every check of a chapter's run reads this build
        python = _READER["future"].result()
        # build() sets ORRC_BOOK_BUILD=1 for the chapters (static frames, no progress bars in the outputs)
        with timed("book build", after="reader environment"):
            BOOK_OUT.mkdir(parents=True, exist_ok=True)
            rc = build(BOOK_OUT, extra_env={"ORRC_QUICK": os.environ.get("ORRC_QUICK", "1")}, kernel_python=python,
                       log=BOOK_LOG)
        return {"rc": rc, "seconds": time.perf_counter() - t0, "started": started, "published": published,
                "python": python}

    pool = ThreadPoolExecutor(max_workers=1)
    _BOOK["future"] = pool.submit(run)
    pool.shutdown(wait=False)


@pytest.fixture(scope="session")
def book():
    """Build the whole book once per session (every chapter executed, ORRC_QUICK=1 sizes)
    into BOOK_OUT (``_build/test``), never into the published ``_build/html``.

    Returns the build's exit code, duration, start time (a wall-clock timestamp, to tell
    this build's outputs from older ones) and the fingerprint of the published
    ``_build/html`` taken before the build (tests/test_book.py checks that the session
    leaves it untouched), and the Python whose kernel executed the chapters (the environment a
    download installs, tests/fresh_env.py). Used by tests/test_book.py (the HTML),
    tests/test_chapters.py (the executed notebooks) and tests/test_downloads.py. The build starts when the tests are collected (:func:`_start_book`).
    """
    return book_result()


def assert_legible(fig, min_pt: float = 9.0, max_width: float = 7.4):
    """A figure of the book as drawn (before orrc.viz.figures.render raises anything): at most
    ``max_width`` inches wide (740 px at 100 dpi, inside the 757 px text column) and every
    text, tick labels included, at least ``min_pt`` points (12.5 px at 100 dpi)."""
    from matplotlib.text import Text

    width = fig.get_size_inches()[0]
    assert width <= max_width + 1e-9, f"the figure is {width:.2f} in wide (at most {max_width})"
    small = [(t.get_text()[:30], t.get_fontsize()) for t in fig.findobj(Text)
             if t.get_text().strip() and t.get_visible() and t.get_fontsize() < min_pt]
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            small += [(t.get_text()[:30], t.get_fontsize()) for t in axis.get_ticklabels()
                      if t.get_fontsize() < min_pt]
    assert not small, f"texts below {min_pt} pt: {small[:5]}"


def legend_under_axes(fig, ax) -> bool:
    """Whether ``ax``'s legend, as drawn (Agg), sits under the axes and inside the figure (a PNG of
    the figure's size would cut off a legend below its edge)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(r)
    return legend.y1 < ax.get_window_extent(r).y0 and legend.y0 >= fig.bbox.y0 - 1


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# Random test problems have bounded conditioning: a draw outside these bounds is redrawn (from
# the same generator, so a seed still gives one problem). The bounds hold for ~99 % of first
# draws (measured over 3000 seeds: random_lq redraws 1 %, random_lq_problem 0.1 %), so the
# fixed seeds of the suite give the problems they always gave; they cut off the tail that no
# fixed tolerance can serve:
COND_MAX = 1e2   # κ₂(Q), κ₂(R), and κ₂ of A's eigenvector matrix (‖A^j‖ <= κ₂ ρ(A)^j: bounded transients)
P_MAX = 1e3      # ‖P‖₂/λ_max(Q), P the stabilising solution of the DARE: (A, B) stabilisable, and
                 # the infinite-horizon value xᵀPx within 1e3 of the stage cost (V_M <= that for all M)


def conditioning(A, B, Q, R) -> dict:
    """The quantities COND_MAX and P_MAX bound (inf when (A, B) is not stabilisable)."""
    from scipy import linalg

    try:
        P = linalg.solve_discrete_are(A, B, Q, R)
        p = float(np.linalg.norm(P, 2) / np.linalg.eigvalsh(Q)[-1])
    except (np.linalg.LinAlgError, ValueError):
        p = np.inf
    return {"cond_Q": np.linalg.cond(Q), "cond_R": np.linalg.cond(R),
            "cond_eigvecs_A": np.linalg.cond(np.linalg.eig(A)[1]), "P_over_Q": p}


def well_conditioned(A, B, Q, R) -> bool:
    c = conditioning(A, B, Q, R)
    return max(c["cond_Q"], c["cond_R"], c["cond_eigvecs_A"]) <= COND_MAX and c["P_over_Q"] <= P_MAX


def random_lq(rng, n=3, m=2, spectral_radius=1.2):
    """A random (A, B, Q, R) with A scaled to the given spectral radius, within COND_MAX and P_MAX."""
    while True:
        A = rng.standard_normal((n, n))
        A *= spectral_radius / max(abs(np.linalg.eigvals(A)))
        B = rng.standard_normal((n, m))
        G = rng.standard_normal((n, n))
        Q = G @ G.T / n + 0.1 * np.eye(n)
        H = rng.standard_normal((m, m))
        R = H @ H.T / m + 0.1 * np.eye(m)
        if well_conditioned(A, B, Q, R):
            return A, B, Q, R


def random_lq_problem(rng, n=None, m=None, rho_range=(0.2, 1.3)):
    """A random linear-quadratic problem (orrc.LinearSystem, orrc.QuadraticCost).

    n in {1, 2, 3} and m in {1, 2} unless given; A scaled to a spectral radius drawn from
    ``rho_range`` (stable or unstable); Q ⪰ I (so α_lo >= 1) plus a random PSD part;
    R a random multiple of the identity; within COND_MAX and P_MAX.
    """
    import orrc

    n_given, m_given = n, m
    while True:
        n = int(rng.integers(1, 4)) if n_given is None else n_given
        m = int(rng.integers(1, 3)) if m_given is None else m_given
        A = rng.standard_normal((n, n))
        A *= rng.uniform(*rho_range) / max(abs(np.linalg.eigvals(A)))
        B = rng.standard_normal((n, m))
        G = rng.standard_normal((n, n))
        Q = 0.3 * G @ G.T / n + np.diag(rng.uniform(1, 2, n))
        R = rng.uniform(0.05, 1.0) * np.eye(m)
        if well_conditioned(A, B, Q, R):
            return orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, R)


def batch_optimum(A, B, Q, R, M, x, W, cond=False):
    """The M-step optimum by condensing: x_j = A^j x + Σ A^{j-1-i}(B u_i + w_i); one linear solve.

    Returns (U, V), and with ``cond=True`` also κ₂ of the condensed Hessian GuᵀQ̄Gu + R̄, the
    conditioning of the problem for U."""
    n, m = B.shape
    Phi = np.zeros((M * n, n))
    Gu = np.zeros((M * n, M * m))
    Gw = np.zeros((M * n, M * n))
    for j in range(M):  # rows for x_j, j = 0..M-1 (x_M is not costed)
        Phi[j * n:(j + 1) * n] = np.linalg.matrix_power(A, j)
        for i in range(j):
            Aji = np.linalg.matrix_power(A, j - 1 - i)
            Gu[j * n:(j + 1) * n, i * m:(i + 1) * m] = Aji @ B
            Gw[j * n:(j + 1) * n, i * n:(i + 1) * n] = Aji
    Qb, Rb = np.kron(np.eye(M), Q), np.kron(np.eye(M), R)
    c = Phi @ x + Gw @ W.reshape(-1)
    K = Gu.T @ Qb @ Gu + Rb
    U = np.linalg.solve(K, -Gu.T @ Qb @ c)
    X = c + Gu @ U
    out = (U.reshape(M, m), float(X @ Qb @ X + U @ Rb @ U))
    return (*out, float(np.linalg.cond(K))) if cond else out



#: options that make every NLP solve of the pendulum fail (the forced failure, on the default NLP
#: path: one SQP iteration does not reach its tolerance from a cold start, nor one IPOPT iteration)
FORCED_FAILURE = {"sqpmethod.max_iter": 1, "ipopt.max_iter": 1}


# ---------------------------------------------------------------- the graded assignments, in the background
# Grading the assignments (tests/test_assignments.py: otter assign, then otter run on the solution, the
# blank notebook and each wrong submission of each, in a fresh environment built from the autograder
# zip) takes a couple of minutes, mostly waiting on kernels; it starts as soon as the tests are
# collected, runs beside the rest of the suite (the book build included), and the tests that read
# its results run last.
_GRADING = {}
_BUILT = {}

# The gradings' results are read last, the book's first: on a busy machine the gradings (their fresh
# environment, every otter run, the documented grading commands) take the cores the tests and the
# book build leave, at a lower priority (a nice value higher by GRADING_NICE), instead of slowing both.
# Linux gives each thread its nice value and every thread and process it starts inherits it.
GRADING_NICE = 5


def _yield_to_the_critical_path(by: int = GRADING_NICE):
    """Lower the calling thread's priority by ``by`` (Linux only: elsewhere the nice value is the
    whole process's, and the tests must keep theirs)."""
    if sys.platform.startswith("linux"):
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, min(19, os.getpriority(os.PRIO_PROCESS, tid) + by))


def _start_grading(wanted=frozenset()):
    """Grade every assignment in the background; then compute the background fixtures in ``wanted``
    that wait on the gradings (see ``after`` below)."""
    from concurrent.futures import Future, ThreadPoolExecutor

    from tools import assignments

    from fresh_env import autograder_env

    fixtures = ROOT / "tests" / "fixtures" / "assignments"
    pool = ThreadPoolExecutor(max_workers=1, initializer=_yield_to_the_critical_path)
    # every notebook is graded by the otter of a fresh environment built from the autograder zip
    # alone (tests/fresh_env.py: built once, shared by every assignment, reused while nothing changes);
    # every assignment is built before the first grading, and the jobs that need the built notebooks
    # only (``after("built", ...)``) start then, beside the gradings
    built_pool = ThreadPoolExecutor(max_workers=1, initializer=_yield_to_the_critical_path)
    _BUILT["future"] = built = Future()

    def on_built(results):
        with _TIMELINE_LOCK:
            _JOBS["assignments built"] = {"start": started - _T0, "end": time.time() - _T0, "after": None}
        built.set_result({r["name"]: r for r in results})

    def grade_all(*args, **kwargs):
        try:
            with timed("gradings", after="assignments built"):
                return assignments.run_all(*args, on_built=on_built, **kwargs)
        except BaseException as exc:   # what waits on the built assignments fails with the gradings
            if not built.done():
                built.set_exception(exc)
            raise

    started = time.time()
    _GRADING["future"] = pool.submit(
        grade_all, BOOK_OUT / "_build" / "assignments",
        extra=lambda n: {p.stem[len(n) + 1:]: p for p in sorted(fixtures.glob(f"{n}_wrong*.md"))},
        python=lambda paths: str(autograder_env(paths["autograder"])))
    _start_after("built", set(wanted), built_pool)
    _start_after("graded", set(wanted), pool)
    built_pool.shutdown(wait=False)
    pool.shutdown(wait=False)


# Session fixtures that only wait on the book or on the gradings and take long (the solution-free
# edition, the downloads in a fresh environment, the reader notebooks, the documented grading
# commands) are computed in
# the background as soon as what they wait on is ready, beside the tests that read the book (the
# browser's, mostly waiting on one core), instead of one after the other when their tests come.
# A test module registers one with ``@after("book", "student_book")``: the function takes the
# book's (or the gradings') result and returns the fixture's value; the fixture returns
# ``background("student_book")``. Errors are raised where the fixture is used, as before.
_AFTER = {"book": {}, "built": {}, "graded": {}}
_BACKGROUND = {}


_ORDER: dict[str, int] = {}


def after(what: str, name: str, order: int = 0):
    """Register ``fn(result of what)`` as the value of the session fixture ``name``, computed in the
    background once ``what`` ("book", "built" or "graded") is ready (see above); jobs start in increasing
    ``order`` (the longest first, so that it is not left to run alone at the end)."""
    def register(fn):
        _AFTER[what][name] = fn
        _ORDER[name] = order
        return fn
    return register


def background(name: str):
    """The value of the background fixture ``name``: its result (waited for), or computed now when
    it was not started at collection (e.g. a single test run by name)."""
    if name not in _BACKGROUND:
        what, fn = next((w, fns[name]) for w, fns in _AFTER.items() if name in fns)
        return fn(_waited(what))
    return _wait_for(name, _BACKGROUND[name])


def _start_after(what: str, names: set[str], pool) -> None:
    def job(name, fn):
        result = _waited(what)
        with timed(name, after={"book": "book build", "built": "assignments built", "graded": "gradings"}[what]):
            return fn(result)

    for name in _in_start_order(what):
        if name in names:
            _BACKGROUND[name] = pool.submit(job, name, _AFTER[what][name])


def _in_start_order(what: str) -> list[str]:
    """The background fixtures that wait on ``what``, in the order they start (``order``, then
    registration)."""
    return sorted(_AFTER[what], key=lambda name: _ORDER[name])


def _waited(what: str):
    """The result of what a background fixture waits on: the book's build, the built assignments or
    the gradings."""
    return {"book": book_result, "built": built_result, "graded": graded_result}[what]()


@pytest.hookimpl(trylast=True)   # after -m/-k deselection: a deselected test starts no build
def pytest_collection_modifyitems(session, config, items):
    """Order: the tests that need neither the book nor the gradings first (they run while the book
    builds and the assignments are graded in the background), then those that read the book, then
    those that read the gradings, and last those that read a job computed from the book (the
    student edition, then the browser's checks)."""
    def needs(item, name):
        return name in getattr(item, "fixturenames", ())

    graded = [it for it in items if needs(it, "graded")]
    # a test of a background fixture computed after the book waits for it like one that reads the book
    on_book = [it for it in items if it not in graded and any(needs(it, n) for n in ("book", *_AFTER["book"]))]
    on_job = [it for it in on_book if any(needs(it, n) for n in _AFTER["book"])]
    on_book = [it for it in on_book if it not in on_job]
    # the jobs computed from the book start in their order (the longest first, _start_after) and that
    # one ends last: its tests come last, those of the jobs started after it before them
    started = _in_start_order("book")
    on_job.sort(key=lambda it: -max(started.index(n) for n in _AFTER["book"] if needs(it, n)))
    # the gradings end before the book's build: their tests run while the jobs computed from the
    # book still run, not after them
    items[:] = [it for it in items if it not in graded and it not in on_book and it not in on_job] + on_book \
        + graded + on_job
    wanted = {name for it in items for name in getattr(it, "fixturenames", ())}
    if config.option.collectonly:   # nothing runs: no background job either
        return
    if on_book or on_job or graded:
        _start_book()
        from concurrent.futures import ThreadPoolExecutor

        # two at a time (the downloads' kernels and the browser's pages wait on other processes
        # much of the time); more would only share the same cores
        pool = ThreadPoolExecutor(max_workers=2)
        _start_after("book", wanted, pool)
        pool.shutdown(wait=False)
    if graded:
        _start_grading(wanted)


def book_result():
    if "future" not in _BOOK:
        _start_book()
    return _wait_for("book build", _BOOK["future"])


def built_result():
    """Every assignment built, with the notebooks to grade (before any grading), by name."""
    if "future" not in _BUILT:
        _start_grading()
    return _wait_for("assignments built", _BUILT["future"])


def graded_result():
    if "future" not in _GRADING:
        _start_grading()
    return {r["name"]: r for r in _wait_for("gradings", _GRADING["future"])}


@pytest.fixture(scope="session")
def graded():
    """Every assignment built and graded once per session (solution, blank, wrong), by name."""
    return graded_result()


# ---------------------------------------------------------------- the browser (one Chromium per session)

def find_chromium() -> str | None:
    env = os.environ.get("ORRC_CHROMIUM")
    if env:
        return env if Path(env).is_file() else None
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").is_file() else None


HOW_TO_ENABLE = ("the browser tests need Chromium: `sudo apt-get install chromium` (Debian/Ubuntu), "
                 "or set ORRC_CHROMIUM=/path/to/chromium; Playwright never downloads a browser here")


@pytest.fixture(scope="session")
def chromium():
    path = find_chromium()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:  # pragma: no cover - playwright is pinned in requirements.txt
        sync_playwright = None
    if path is None or sync_playwright is None:
        why = "no Chromium found" if path is None else "the playwright package is missing"
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but {why}: {HOW_TO_ENABLE}")
        pytest.skip(f"{why}; {HOW_TO_ENABLE}")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=path, args=["--no-sandbox", "--disable-gpu"])
        yield browser
        browser.close()


def run_coroutine(coro):
    """``asyncio.run(coro)`` in a thread of its own: the session's Chromium (Playwright's sync API)
    keeps an event loop running in the main thread, where asyncio.run refuses to start another."""
    import asyncio

    result = {}

    def target():
        try:
            result["value"] = asyncio.run(coro)
        except BaseException as exc:   # re-raised in the caller's thread
            result["error"] = exc

    thread = threading.Thread(target=target)
    thread.start()
    thread.join()
    if "error" in result:
        raise result["error"]
    return result.get("value")


def pytest_unconfigure(config):
    """Close the widgets the tests made (explorers outside a kernel) while the interpreter still runs.
    ipywidgets keeps every open widget until it is closed; left to the interpreter's exit, each one's
    ``__del__`` runs after the modules it needs are gone and prints an ignored exception. A widget
    opened before ipykernel was imported (``tools.lab_contents`` imports it) is registered with the
    comm manager that ipykernel's import replaced; it has nothing left to close then."""
    widgets = sys.modules.get("ipywidgets.widgets.widget")
    if widgets is None:
        return
    for widget in list(widgets._instances.values()):
        try:
            widget.close()
        except KeyError:
            widget.comm = None
