"""Parameter studies: one function over a grid of parameters and seeds (:func:`sweep`).

The book's experiments (Theorem 2's T^{2/3} law, the comparison over many disturbances, the
min-max frames, ...) run one closed loop per grid point and seed. :func:`sweep` runs such a study
and returns a tidy :class:`Table` (one row per run, in grid order):

* **serially** (``backend="serial"``), in this process;
* on **local processes** (``backend="processes"``): a ``concurrent.futures`` process pool started
  from a *forkserver* that has imported ``orrc`` once, and the heavy modules this process already
  uses (scipy, python-control), so that workers start without importing them (the first pool of a
  session pays 0.6 s for orrc alone, later ones about 0.1 s on an idle machine; a spawned pool pays
  1.2 s every time and each of its workers imports python-control again, 1 to 4 s on a loaded
  machine);
* **automatically** (``backend="auto"``, the default): the first run in this process, timed; the
  others on processes if that saves more than :data:`AUTO_MIN_SAVING` seconds with the cores that
  are idle (``os.getloadavg``), else serially. On a loaded machine that is serial, which is often
  faster than a loop because of the one BLAS thread below;
* on a **Dask cluster** when a ``dask.distributed.Client`` is passed (``client=``; the optional
  extra ``orrc[dask]``).

The function is sent to the workers with cloudpickle, so a function defined in a notebook works,
with the systems, costs and arrays it uses. CasADi objects that hold symbols (a nonlinear
``PreviewRHC``, a ``ParametricSystem``) do not pickle: ``fn`` builds its controller *inside*.

**Same results whatever the backend.** Every run is ``fn(**point, seed=s)`` with a seed fixed by
its place in the grid, never by which worker runs it: an integer derived from
``numpy.random.SeedSequence(seed)`` (``.spawn`` per grid point, then per replicate), or the seeds
given. ``fn`` runs with one BLAS thread in every backend (the parallelism is across runs; a BLAS
kernel's summation order may depend on its thread count), with this process's ``orrc.config``
limits and ``ORRC_*`` environment, and results come back through pickle, which is exact: the
serial, process and Dask tables are bit-identical.

Warnings that ``fn`` raises in a worker are raised again here, in grid order. An exception in
``fn`` stops the sweep with a :class:`SweepError` naming the grid point and seed that raised (the
original exception is its ``__cause__``, the worker's traceback a note), or, with
``on_error="record"``, fills that row's ``error`` column and the sweep goes on.

A progress bar (``tqdm.auto``: a widget in a notebook, text in a terminal) appears after a second
in an interactive session; never in the book's build (``ORRC_BOOK_BUILD=1``) nor where standard
error is not a terminal outside a kernel (tests, scripts piped to a file).
"""
from __future__ import annotations

import functools
import itertools
import math
import numbers
import os
import time

import numpy as np

from . import _sweep_run as run
from ._progress import watched
from ._sweep_run import AUTO_MIN_SAVING, SweepError  # noqa: F401  (re-exported: orrc.SweepError)
from ._validate import OrrcValueError, _describe, as_float, as_int, check_size

__all__ = ["sweep", "Table", "SweepError", "BACKENDS"]

BACKENDS = ("auto", "serial", "processes", "dask")
#: the default estimate of one call of ``fn`` (about 1 ms at 1e9 operations/s: a short closed loop)
CALL_OPS = 1e6
#: bytes of one row of the table per column (a dict entry and a small Python object)
_CELL_BYTES = 200.0
_ON_ERROR = ("raise", "record")


class Table(list):
    """The result of :func:`sweep`: a list of rows (dicts), one per run, in grid order.

    Each row holds the grid point's parameters, ``seed`` and ``replicate`` (when seeds were
    given), and what ``fn`` returned (the keys of a returned dict, else ``value``); a failed run
    recorded with ``on_error="record"`` has an ``error`` column instead. ``params`` names the
    grid's parameters.

    Parameters
    ----------
    rows : the rows, dicts.
    params : the names of the grid's parameters.

    Examples
    --------
    >>> import orrc
    >>> def run(M, radius, seed):
    ...     di = orrc.examples.double_integrator()
    ...     w = orrc.disturbances.uniform_ball(60, 2, radius, seed=seed)
    ...     traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M),
    ...                          di.x0, w, 50)
    ...     return {"cost": traj.costs.sum()}
    >>> table = orrc.sweep(run, {"M": [1, 10], "radius": [0.1]}, seeds=3, backend="serial")
    >>> table.where(M=10).column("cost").shape
    (3,)
    >>> table.to_records().dtype.names
    ('M', 'radius', 'seed', 'replicate', 'cost')
    """

    def __init__(self, rows=(), params=()):
        super().__init__(rows)
        self.params = tuple(params)

    @property
    def columns(self) -> list[str]:
        """Every column name, in order of first appearance."""
        return list(dict.fromkeys(k for row in self for k in row))

    def column(self, name: str) -> np.ndarray:
        """The values of one column as an array (stacked when they are arrays of one shape; an
        object array otherwise). Every row must have the column."""
        if not isinstance(name, str) or not self or any(name not in row for row in self):
            raise OrrcValueError(f"name must be a column of every row; got {_describe(name)}, "
                                 f"columns: {self.columns}")
        values = [row[name] for row in self]
        try:
            return np.asarray(values)
        except ValueError:          # ragged: arrays of different shapes
            out = np.empty(len(values), dtype=object)
            out[:] = values
            return out

    def where(self, **match) -> "Table":
        """The rows whose columns equal the given values (``table.where(M=4, estimator="given w")``)."""
        unknown = sorted(set(match) - set(self.columns))
        if unknown:
            raise OrrcValueError(f"where: unknown columns {unknown}; columns: {self.columns}")
        return Table([row for row in self if all(k in row and row[k] == v for k, v in match.items())], self.params)

    def errors(self) -> "Table":
        """The rows of runs that raised (``on_error="record"``)."""
        return Table([row for row in self if "error" in row], self.params)

    def to_records(self) -> np.ndarray:
        """The table as a numpy structured array of its scalar columns (numbers, booleans, strings)."""
        cols = [c for c in self.columns if all(c in row and _scalar(row[c]) for row in self)]
        if not cols:
            raise OrrcValueError(f"to_records: no column holds a scalar in every row; columns: {self.columns}")
        arrays = [np.asarray([row[c] for row in self]) for c in cols]
        return np.rec.fromarrays(arrays, names=cols)


def _scalar(v) -> bool:
    return isinstance(v, (numbers.Number, str, np.generic)) and not isinstance(v, complex)


# -- the grid ---------------------------------------------------------------------------------------
def _check_key(key, where: str) -> str:
    if not isinstance(key, str) or not key.isidentifier():
        raise OrrcValueError(f"{where}: parameter names must be identifiers (strings); got {_describe(key)}")
    return key


def _grid_size(grid) -> tuple[list[str], int]:
    """The parameter names and the number of points, without building the points."""
    if isinstance(grid, dict):
        names = [_check_key(k, "grid") for k in grid]
        count = 1
        for k, values in grid.items():
            if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__len__") or \
                    (isinstance(values, np.ndarray) and values.ndim != 1):
                raise OrrcValueError(f"grid[{k!r}] must be a list (or 1-D array) of values; got {_describe(values)}")
            if len(values) == 0:
                raise OrrcValueError(f"grid[{k!r}] must hold at least one value; got an empty {type(values).__name__}")
            count *= len(values)
        return names, count
    if isinstance(grid, (list, tuple)):
        if not grid:
            raise OrrcValueError("grid must hold at least one point; got an empty list")
        for i, p in enumerate(grid):
            if not isinstance(p, dict):
                raise OrrcValueError(f"grid[{i}] must be a dict of parameters; got {_describe(p)}")
        names = [_check_key(k, "grid[0]") for k in grid[0]]
        for i, p in enumerate(grid):
            if set(p) != set(names):
                raise OrrcValueError(f"grid[{i}] has the parameters {sorted(p)}; every point must have those of "
                                     f"grid[0], {sorted(names)}")
        return names, len(grid)
    raise OrrcValueError(f"grid must be a dict of lists (their product is the grid) or a list of dicts; "
                         f"got {_describe(grid)}")


def _points(grid, names) -> list[dict]:
    if isinstance(grid, dict):
        lists = [v.tolist() if isinstance(v, np.ndarray) else list(v) for v in grid.values()]
        return [dict(zip(names, combo)) for combo in itertools.product(*lists)]
    return [{k: p[k] for k in names} for p in grid]


def _seed_plan(seeds, seed, common_seeds: bool, n_points: int):
    """(k, seeds_of(i)): the seeds of grid point i (a list of k ints), or (1, None) for no seeds.

    Nothing is drawn here (the grid's size is checked first, with k): ``seeds_of`` derives the seeds
    of point i when asked, from the child i of ``SeedSequence(seed)`` (``spawn_key=(i,)``, the same
    child as the i-th of ``SeedSequence(seed).spawn(n_points)``)."""
    if seeds is None:
        return 1, None
    root = as_int("seed", seed, minimum=0)
    if isinstance(seeds, numbers.Integral) and not isinstance(seeds, bool):
        k = as_int("seeds", seeds, minimum=1)

        def draw(ss):
            return [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for c in ss.spawn(k)]

        if common_seeds:
            shared = functools.cache(lambda: draw(np.random.SeedSequence(root)))
            return k, lambda i: shared()
        return k, lambda i: draw(np.random.SeedSequence(root, spawn_key=(i,)))
    if isinstance(seeds, (list, tuple, np.ndarray)) and len(seeds) > 0:
        given = [as_int(f"seeds[{j}]", s.item() if isinstance(s, np.generic) else s, minimum=0)
                 for j, s in enumerate(seeds)]
        return len(given), lambda i: given
    raise OrrcValueError(f"seeds must be None, a number of seeds per point (an integer >= 1) or a non-empty list of "
                         f"integer seeds; got {_describe(seeds)}")


# -- the sweep --------------------------------------------------------------------------------------
def sweep(fn, grid, seeds=None, *, seed: int = 0, common_seeds: bool = False, backend: str | None = None,
          client=None, workers: int | None = None, chunksize: int | None = None, progress: bool | None = None,
          on_error: str = "raise", ops_per_call: float = CALL_OPS) -> Table:
    """Run ``fn(**point, seed=s)`` for every point of ``grid`` and every seed; return a :class:`Table`.

    Parameters
    ----------
    fn : the experiment, called with the grid's parameters as keywords (and ``seed=`` when seeds are
        given); it returns a dict of results (its keys become columns) or one value (column ``value``).
        It must be picklable with cloudpickle for the parallel backends: build CasADi controllers inside.
    grid : a dict of lists (the grid is their product, the last parameter varying fastest, like nested
        loops) or a list of dicts (the points themselves). ``{}`` is one point without parameters.
    seeds : None (``fn`` takes no seed); an integer k (k seeds per point, derived from
        ``numpy.random.SeedSequence(seed)``: independent between points, or the same k at every point
        with ``common_seeds=True``, for comparisons on common random numbers); or a list of integer
        seeds, passed as they are at every point.
    backend : "auto" (processes when they pay, see the module docstring), "processes" (local worker
        processes), "serial" (this process) or "dask" (``client``, or the current ``dask.distributed``
        client). Passing ``client`` selects "dask". Default: the environment variable ``ORRC_SWEEP_BACKEND``
        if set (e.g. to run a whole chapter's sweeps on processes), else "auto". The backend never changes the results.
    workers : worker processes (default: the cores available); ``chunksize``: runs per task (default
        about a quarter of the runs per worker, so that tasks balance).
    progress : show a progress bar (None: in an interactive session only, never in the book's build).
    on_error : "raise" (default: :class:`SweepError` at the first failing run) or "record" (an ``error``
        column; the sweep goes on).
    ops_per_call : an estimate of one call's operations, for the size check (default 1e6, about 1 ms):
        the grid is refused above ``orrc.config``'s limits, with the estimate in the message.

    A grid of one run, and ``workers=1``, run in this process (the same results, without a pool).

    Returns
    -------
    Table
        one row (a dict) per run, in grid order: the point's parameters, ``seed`` and ``replicate``
        when seeds are given, and what ``fn`` returned.

    Raises
    ------
    orrc.OrrcValueError
        When the grid, the seeds or an option is malformed, or the grid exceeds the size limits.
    orrc.SweepError
        When ``fn`` raises at a grid point (unless ``on_error="record"``).

    Examples
    --------
    Algorithm 1's cost for two horizons, three disturbance draws each:

    >>> import orrc
    >>> def run(M, radius, seed):
    ...     di = orrc.examples.double_integrator()
    ...     w = orrc.disturbances.uniform_ball(60, 2, radius, seed=seed)
    ...     traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M),
    ...                          di.x0, w, 50)
    ...     return {"cost": traj.costs.sum()}
    >>> table = orrc.sweep(run, {"M": [1, 10], "radius": [0.1]}, seeds=3, backend="serial")
    >>> len(table), table.columns
    (6, ['M', 'radius', 'seed', 'replicate', 'cost'])
    >>> mean_cost = {M: table.where(M=M).column("cost").mean() for M in (1, 10)}
    >>> bool(mean_cost[10] < mean_cost[1])
    True
    """
    if not callable(fn):
        raise OrrcValueError(f"fn must be callable fn(**point, seed=...); got {_describe(fn)}")
    names, n_points = _grid_size(grid)
    if seeds is not None and "seed" in names:
        raise OrrcValueError("grid must not have a parameter named 'seed' when seeds are given: sweep passes seed=")
    if not isinstance(common_seeds, bool):
        raise OrrcValueError(f"common_seeds must be True or False; got {_describe(common_seeds)}")
    k, seeds_of = _seed_plan(seeds, seed, common_seeds, n_points)
    if backend is None:
        backend = os.environ.get("ORRC_SWEEP_BACKEND", "").strip() or "auto"
        if backend not in BACKENDS:
            raise OrrcValueError(f"the environment variable ORRC_SWEEP_BACKEND must be one of {list(BACKENDS)}; "
                                 f"got {backend!r}")
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise OrrcValueError(f"backend must be one of {list(BACKENDS)}; got {_describe(backend)}")
    if on_error not in _ON_ERROR:
        raise OrrcValueError(f"on_error must be one of {list(_ON_ERROR)}; got {_describe(on_error)}")
    if progress is not None and not isinstance(progress, bool):
        raise OrrcValueError(f"progress must be None, True or False; got {_describe(progress)}")
    ops_per_call = as_float("ops_per_call", ops_per_call, minimum=0.0)
    workers = run._cores() if workers is None else as_int("workers", workers, minimum=1)
    runs = n_points * k
    shape = " × ".join(f"{len(v)} {n}" for n, v in grid.items()) if isinstance(grid, dict) else f"{n_points} points"
    check_size(f"orrc.sweep over a grid of {n_points} points ({shape or 'no parameters'}) × {k} seeds = {runs} "
               f"runs of fn at ops_per_call={ops_per_call:.3g}", ops=runs * ops_per_call,
               nbytes=runs * _CELL_BYTES * (len(names) + 4), hint="use a coarser grid or fewer seeds")
    if client is not None:
        backend = "dask"
    if backend == "dask":
        client = run._dask_client(client)
        workers = max(1, sum(client.nthreads().values()))
    given_chunksize = chunksize is not None
    chunksize = max(1, math.ceil(runs / (4 * workers))) if chunksize is None else as_int("chunksize", chunksize,
                                                                                        minimum=1)

    points = _points(grid, names)
    tasks = []
    for i, p in enumerate(points):
        for r, s in enumerate(seeds_of(i) if seeds_of else [None]):
            tasks.append((len(tasks), p, s, r))
    _check_signature(fn, points[0], seeds_of is not None)
    rows: list = [None] * runs
    bar = _bar(runs, progress)
    try:
        if backend == "auto" and runs > 1:
            start = time.perf_counter()
            run._serial(fn, tasks[:1], rows, on_error, bar, runs)
            backend, workers = run._auto(time.perf_counter() - start, runs - 1, workers)
            if backend == "processes" and not given_chunksize:
                chunksize = max(1, math.ceil((runs - 1) / (4 * workers)))
            tasks = tasks[1:]
        if backend in ("serial", "auto") or (backend == "processes" and (len(tasks) == 1 or workers == 1)):
            run._serial(fn, tasks, rows, on_error, bar, runs)
        else:
            run._parallel(fn, tasks, rows, on_error, bar, backend, client, min(workers, len(tasks)), chunksize, runs)
    finally:
        if bar is not None:
            bar.close()
    return Table(rows, names)


def _check_signature(fn, point: dict, with_seed: bool):
    import inspect

    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # a builtin without a signature: its own error will say
        return
    try:
        sig.bind(**point, **({"seed": 0} if with_seed else {}))
    except TypeError as exc:
        got = ", ".join(list(point) + (["seed"] if with_seed else []))
        raise OrrcValueError(f"fn{sig} cannot be called with the grid's keywords ({got or 'none'}): {exc}") from None


def _bar(total: int, progress):
    if not (progress if progress is not None else watched()):
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc="orrc.sweep", unit="run", delay=0 if progress else 1.0)

