"""Running the runs of :func:`orrc.sweep`: in this process, on a local process pool (a forkserver that
imported orrc and the heavy modules in use), or on Dask; the "auto" choice between them; errors and
warnings carried back from the workers with their grid point. The grid, the seeds and the table are
:mod:`orrc.sweep`'s.
"""
from __future__ import annotations

import hashlib
import os
import pickle
import sys
import traceback
import warnings

from ._validate import OrrcValueError, _describe

#: "auto" starts worker processes only when they save more than this many seconds (the measured cost of a pool
#: whose forkserver imports orrc, scipy and python-control on a loaded 2-core machine: 1 to 4 s)
AUTO_MIN_SAVING = 2.0


class SweepError(RuntimeError):
    """``fn`` raised at a grid point of :func:`sweep` (the message names the point and the seed).

    Attributes: ``point`` (the grid point, a dict), ``seed`` (the seed passed, or None), ``row``
    (the run's index in the table). The original exception is ``__cause__``.

    Parameters
    ----------
    message : what raised, at which grid point and seed.
    point : the grid point, a dict.
    seed : the seed passed, or None.
    row : the run's index in the table.

    Examples
    --------
    >>> import orrc
    >>> def fn(M):
    ...     if M == 2:
    ...         raise ValueError("no")
    ...     return M
    >>> try:
    ...     orrc.sweep(fn, {"M": [1, 2, 3]}, backend="serial")
    ... except orrc.SweepError as err:
    ...     print(err.point, err.row, type(err.__cause__).__name__)
    {'M': 2} 1 ValueError
    """

    def __init__(self, message: str, point=None, seed=None, row=None):
        super().__init__(message)
        self.point, self.seed, self.row = point, seed, row


_LOADED: dict = {}     # payload digest -> fn, in a worker process


def _call(fn, point: dict, s):
    return fn(**point) if s is None else fn(**point, seed=s)


def _apply_context(context):
    """In a worker: this sweep's ORRC_* environment and orrc.config limits."""
    from . import config

    env, limits = context
    for k in [k for k in os.environ if k.startswith("ORRC_") and k not in env]:
        del os.environ[k]
    os.environ.update(env)
    config.set_limits(**limits)


def _run_chunk(payload: bytes, context, chunk):
    """Run ``chunk`` (a list of (row, point, seed)) in a worker: [(row, ok, value or error, warnings)]."""
    from .solvers.lq import _one_blas_thread

    key = hashlib.sha256(payload).digest()
    if key not in _LOADED:
        import cloudpickle

        _LOADED.clear()
        _LOADED[key] = cloudpickle.loads(payload)
    fn = _LOADED[key]
    _apply_context(context)
    out = []
    with _one_blas_thread():
        for row, point, s in chunk:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    result = (row, True, _call(fn, point, s))
                except Exception as exc:  # reported with its grid point by the caller
                    result = (row, False, _portable(exc))
            out.append(result + ([(w.category, str(w.message), w.filename, w.lineno) for w in caught],))
    return out


def _portable(exc: BaseException):
    """(exception, traceback text), the exception replaced by a RuntimeError if it does not pickle."""
    tb = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    try:
        pickle.loads(pickle.dumps(exc))
    except Exception:
        exc = RuntimeError(f"{type(exc).__name__}: {exc}")
    return exc, tb


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


#: modules that orrc imports on first use and that take seconds to import on a loaded machine (python-control
#: 1 to 4 s, scipy.signal 1 to 2 s): the forkserver imports those this process has already imported
_HEAVY = ("scipy.linalg", "scipy.optimize", "scipy.signal", "scipy.sparse.linalg", "control", "threadpoolctl", "cvxpy")


def _forkserver():
    """The multiprocessing context of the process pools: a forkserver that imported orrc and the heavy modules
    already imported here, so that every worker forked from it starts with them (spawn where there is no
    forkserver). The server starts with the first pool of the session and serves every later one."""
    import multiprocessing as mp

    try:
        ctx = mp.get_context("forkserver")
    except ValueError:  # pragma: no cover - Windows
        return mp.get_context("spawn")
    ctx.set_forkserver_preload(["orrc"] + [m for m in _HEAVY if m in sys.modules])   # used when the server starts
    return ctx


def _auto(first: float, left: int, workers: int) -> tuple[str, int]:
    """("processes", w) when w idle cores save more than AUTO_MIN_SAVING seconds on ``left`` runs of ``first``
    seconds each; else ("serial", 1). Idle cores: the cores less the load average, plus this process's own
    (it waits while the workers run)."""
    try:
        load = os.getloadavg()[0]
    except OSError:  # pragma: no cover - no load average
        return "serial", 1
    w = min(workers, left, int(_cores() - load + 1))
    if w >= 2 and first * left * (1 - 1 / w) > AUTO_MIN_SAVING:
        return "processes", w
    return "serial", 1


def _dask_client(client):
    try:
        from distributed import Client, get_client
    except ImportError as exc:  # pragma: no cover - the suite installs the extra
        raise OrrcValueError("backend='dask' needs dask.distributed: install the extra, pip install 'orrc[dask]'") \
            from exc
    if client is None:
        try:
            return get_client()
        except ValueError:
            raise OrrcValueError("backend='dask' needs a dask.distributed client: pass client=Client(...) "
                                 "(none is running)") from None
    if not isinstance(client, Client):
        raise OrrcValueError(f"client must be a dask.distributed.Client; got {_describe(client)}")
    return client


def _row(task, value) -> dict:
    _, point, s, r = task
    row = dict(point)
    if s is not None:
        row.update(seed=s, replicate=r)
    result = value if isinstance(value, dict) else {"value": value}
    clash = sorted(set(result) & set(row))
    if clash:
        raise OrrcValueError(f"fn returned the keys {clash}, which are also columns of the grid (parameters, seed, "
                             "replicate): rename them")
    row.update(result)
    return row


def _where(task, runs: int) -> str:
    row, point, s, _ = task
    at = ", ".join(f"{k}={_describe(v)}" for k, v in point.items()) or "the only grid point"
    return f"at grid point {at}" + (f", seed={s}" if s is not None else "") + f" (run {row + 1} of {runs})"


def _failed(task, exc, tb, runs, on_error, rows):
    if on_error == "record":
        rows[task[0]] = {**_row(task, {}), "error": f"{type(exc).__name__}: {exc}"}
        return
    err = SweepError(f"fn raised {type(exc).__name__}: {exc} {_where(task, runs)}", dict(task[1]), task[2], task[0])
    if tb:
        err.add_note("in the worker:\n" + tb)
    raise err from exc


def _serial(fn, tasks, rows, on_error, bar, runs):
    from .solvers.lq import _one_blas_thread

    with _one_blas_thread():
        for task in tasks:
            try:
                value = _call(fn, task[1], task[2])
            except Exception as exc:
                _failed(task, exc, "", runs, on_error, rows)
            else:
                rows[task[0]] = _row(task, value)
            if bar is not None:
                bar.update(1)


def _parallel(fn, tasks, rows, on_error, bar, backend, client, workers, chunksize, runs):
    import cloudpickle

    from .config import get_limits

    try:
        payload = cloudpickle.dumps(fn)
    except Exception as exc:
        raise OrrcValueError(f"fn cannot be sent to the worker processes ({type(exc).__name__}: {exc}). Build what "
                             "does not pickle (CasADi controllers, solvers, ParametricSystem models) inside fn, or "
                             "use backend='serial'") from exc
    context = ({k: v for k, v in os.environ.items() if k.startswith("ORRC_")}, vars(get_limits()))
    chunks = [[t[:3] for t in tasks[i:i + chunksize]] for i in range(0, len(tasks), chunksize)]
    registry: dict = {}
    by_row = {t[0]: t for t in tasks}

    def collect(chunk, outcome):
        for (row, ok, value, caught), task in zip(outcome, (by_row[c[0]] for c in chunk)):
            for category, message, filename, lineno in caught:
                warnings.warn_explicit(message, category, filename, lineno, registry=registry)
            if ok:
                rows[row] = _row(task, value)
            else:
                _failed(task, value[0], value[1], runs, on_error, rows)
        if bar is not None:
            bar.update(len(chunk))

    def result(future, chunk):
        try:
            return future.result()
        except Exception as exc:   # the task itself failed: a result that does not pickle, a dead worker
            first, last = chunk[0][0], chunk[-1][0]
            why = ("a worker process died: it ran out of memory, crashed, or (in a script) re-ran the script's top "
                   "level, which must call sweep under `if __name__ == '__main__':`" if "BrokenProcessPool" in
                   type(exc).__name__ else "fn must return picklable values (numbers, arrays, dicts, orrc Trajectory "
                   "objects), not CasADi objects")
            raise SweepError(f"the runs {first + 1} to {last + 1} of {runs} could not be completed or sent back "
                             f"({type(exc).__name__}: {exc}): {why}; the first of them is "
                             f"{_where(by_row[first], runs)}", dict(by_row[first][1]), by_row[first][2], first) \
                from exc

    if backend == "dask":
        from distributed import as_completed

        futures = [client.submit(_run_chunk, payload, context, chunk, pure=False) for chunk in chunks]
        by_key = {f.key: c for f, c in zip(futures, chunks)}
        try:
            for fut in as_completed(futures):
                collect(by_key[fut.key], result(fut, by_key[fut.key]))
        except BaseException:
            client.cancel(futures)
            raise
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed

    pool = ProcessPoolExecutor(max_workers=min(workers, len(chunks)), mp_context=_forkserver())
    try:
        futures = {pool.submit(_run_chunk, payload, context, chunk): chunk for chunk in chunks}
        for fut in as_completed(futures):
            collect(futures[fut], result(fut, futures[fut]))
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
