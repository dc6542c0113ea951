"""CasADi functions evaluated on numpy buffers: the hot paths' way of calling CasADi.

Calling a ``casadi.Function`` with numpy arrays converts every argument to a CasADi matrix and
every result back: about 35 µs per call on this project's machine, for a function that computes
in 1 µs (the pendulum's dynamics), and half the time of a 0.2 ms SQP solve. ``Function.buffer()``
evaluates on caller-owned contiguous arrays instead (1.6 µs for the same call). :class:`Buffered`
wraps it; :func:`buffered` keeps one per object, function and thread (a buffer is working memory:
two threads must not share one), and :class:`DropsBuffers` leaves the buffers out of a pickle.
"""
from __future__ import annotations

import functools
import threading

import casadi as ca
import numpy as np

try:   # the SWIG function behind FunctionBuffer.stats (its Python wrapper adds a frame: 0.8 µs of 7)
    from casadi._casadi import FunctionBuffer_stats as _buffer_stats
except ImportError:  # pragma: no cover (another CasADi build)
    _buffer_stats = ca.FunctionBuffer.stats


class Buffered:
    """A ``casadi.Function`` evaluated on numpy arrays it owns (``Function.buffer``): the arguments are
    copied into :attr:`args`, the results appear in :attr:`res`, and no CasADi matrix is built per call.
    The results are overwritten by the next call (copy what you keep)."""

    def __init__(self, fn: ca.Function, args=None, res=None):
        self.fn = fn
        # ``args``, ``res``: contiguous arrays to evaluate on instead of arrays of its own (e.g. another buffer's)
        self.args = list(args) if args is not None else [np.zeros(fn.nnz_in(i)) for i in range(fn.n_in())]
        self.res = list(res) if res is not None else [np.zeros(fn.nnz_out(i)) for i in range(fn.n_out())]
        self.buffer, self._evaluate = fn.buffer()
        #: the statistics of the last evaluation (``Function.stats`` of the buffer's memory), a callable
        self.read_stats = functools.partial(_buffer_stats, self.buffer)
        #: an NLP solver's counters (``n_call_*``) accumulate over the evaluations of this buffer (None:
        #: not known yet; :class:`orrc.solvers.warm_sqp.WarmSQP` finds out)
        self.counts_accumulate = None
        #: a compiled solver's count of its SQP iterations in this thread (``orrc._jit``; None: none), and
        #: how many of its solves were checked against the statistics (``WarmSQP``)
        self.counter, self.counter_checks = None, 0
        for i, a in enumerate(self.args):
            self.buffer.set_arg(i, memoryview(a))
        for i, r in enumerate(self.res):
            self.buffer.set_res(i, memoryview(r))

    def __call__(self, *args) -> int:
        """Evaluate with ``args`` (the inputs' nonzeros in column-major order, one array or scalar per
        input; None keeps the last value); returns CasADi's return code (0: success)."""
        for a, v in zip(self.args, args):
            if v is not None:
                a[:] = v
        self._evaluate()
        return self.buffer.ret()

    def evaluate(self, *args) -> None:
        """As calling it, without reading the return code (for functions that cannot fail: an SX
        function of the model, the rollout, the acceptance checks)."""
        for a, v in zip(self.args, args):
            if v is not None:
                a[:] = v
        self._evaluate()

    def stats(self) -> dict:
        """The statistics of the last evaluation (``Function.stats`` of the buffer's memory)."""
        return self.read_stats()


def buffered(owner, key: str, make, *initial) -> Buffered:
    """The :class:`Buffered` of ``owner`` named ``key`` for the calling thread, made by ``make()``
    (which returns the ``casadi.Function``, or a :class:`Buffered` of it) on first use, its arguments set to ``initial`` then
    (arguments that never change, e.g. bounds)."""
    try:
        cache = owner.__dict__["_casadi_buffers"]
    except KeyError:
        cache = owner.__dict__["_casadi_buffers"] = {}
    k = (key, threading.get_ident())
    call = cache.get(k)
    if call is None:
        made = make()
        call = cache[k] = made if isinstance(made, Buffered) else Buffered(made)
        for a, v in zip(call.args, initial):
            if v is not None:
                a[:] = v
    return call


class DropsBuffers:
    """Mixin: the buffers of :func:`buffered` are working memory, left out when the object is pickled
    or copied (they are made again on first use)."""

    def __getstate__(self):
        state = self.__dict__.copy()
        state.pop("_casadi_buffers", None)
        return state
