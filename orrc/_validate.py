"""Input checks, size guards and result checks shared by the whole package.

Every public function of ``orrc`` validates what it is given with these helpers, so that
bad input fails early with a message that names the argument, says what was given and what
is allowed (never a silent NaN, never a hang, never a raw traceback from deep inside numpy or
CasADi). The policy, in one place:

* **Bad input** (wrong type or shape, NaN or inf, complex, empty, out of range) raises
  :class:`OrrcValueError`, a ``ValueError``, naming the argument (:func:`as_array`,
  :func:`as_float`, :func:`as_int`, :func:`as_seed`, ...).
* **Too large to compute**: before a computation whose memory or time grows fast, the caller
  estimates both and calls :func:`check_size`, which refuses (``OrrcValueError`` stating the
  estimate and the limit) above ``orrc.config`` 's limits and warns (:class:`SizeWarning`)
  above its warning thresholds.
* **Finite input, non-finite result** (overflow, division by a number that underflowed to 0):
  an error from the pure formulas (:func:`finite_result`, :func:`check_finite_result`); a
  :class:`NonFiniteWarning` where a long but legitimate computation overflows
  (:func:`orrc.simulate` on an unstable loop: costs, σ or V_M past the float range).
"""
from __future__ import annotations

import functools
import inspect
import math

import numpy as np

from ._arguments import (_describe, as_array, as_bool, as_float, as_int, as_seed, as_square,  # noqa: F401
                         check_evaluates, check_options, check_psd, eigvalsh_tol, probe_points)
from ._errors import NonFiniteWarning, OrrcValueError, SizeWarning  # noqa: F401
from ._size_limits import (ARRAY_OVERHEAD_BYTES, OPS_PER_SECOND, PY_CALL_OPS, Limits, _fmt_bytes,  # noqa: F401
                           _fmt_ops, _LIMITS_ENV, check_size, get_limits, limit_value, use_limits)

__all__ = ["OrrcValueError", "SizeWarning", "NonFiniteWarning", "as_array", "as_square", "as_int", "as_bool",
           "as_float", "as_seed", "eigvalsh_tol", "check_psd", "check_options", "probe_points", "check_evaluates",
           "Limits", "limit_value", "get_limits", "use_limits", "check_size", "check_finite_result", "finite_result"]


# -- results of finite input must be finite -----------------------------------------------------------
def _all_finite(out) -> bool:
    if isinstance(out, (bool, np.bool_)):
        return True
    if isinstance(out, (int, float)):
        return math.isfinite(out)
    if isinstance(out, tuple):     # a record of results (e.g. a NamedTuple of bounds)
        return all(_all_finite(v) for v in out)
    return bool(np.all(np.isfinite(out)))


def check_finite_result(what: str, value, args: str = "", hint: str = ""):
    """``value`` unchanged when it is finite; else :class:`OrrcValueError` saying that ``what``
    overflowed for the (finite) arguments ``args`` (a string such as "alpha_lo=1e-200")."""
    if not _all_finite(value):
        raise OrrcValueError(
            f"{what} is not finite ({_describe(value)}) for the finite arguments {args}: the computation "
            "overflows the float range" + (f"; {hint}" if hint else "; rescale the problem"))
    return value


def finite_result(fn):
    """Decorator for a pure formula: finite arguments must give a finite result.

    A ``ZeroDivisionError`` or ``OverflowError`` raised by float arithmetic, or a result that
    is inf or NaN (a numpy overflow), becomes an :class:`OrrcValueError` that names the
    function and every argument with its value. Arguments are validated by the function itself
    first (their errors pass through unchanged).
    """
    sig = inspect.signature(fn)

    def describe(args, kwargs) -> str:
        try:
            bound = sig.bind(*args, **kwargs)
        except TypeError:
            return "(as given)"
        return ", ".join(f"{k}={_describe(v)}" for k, v in bound.arguments.items())

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
                out = fn(*args, **kwargs)
        except (ZeroDivisionError, OverflowError) as exc:
            raise OrrcValueError(
                f"{fn.__name__}({describe(args, kwargs)}) is not representable in floating point "
                f"({type(exc).__name__}: {exc}): the constants are too far apart or too close to the "
                "limits of their ranges; rescale them") from exc
        if not _all_finite(out):
            raise OrrcValueError(
                f"{fn.__name__}({describe(args, kwargs)}) is not finite: the formula overflows the float "
                "range for these constants; rescale them")
        return out

    return wrapper
