"""The size guards: the limits of one computation (set by :mod:`orrc.config`) and
:func:`check_size`, which refuses or warns before a computation whose memory or time grows fast.
Re-exported by ``orrc._validate``.
"""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass

from ._arguments import as_float
from ._errors import OrrcValueError, SizeWarning


# -- size guards ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Limits:
    """The size limits of one computation (documented in :mod:`orrc.config`, which sets them).

    Attributes
    ----------
    max_bytes, max_ops : refuse (``OrrcValueError``) above these estimates.
    warn_bytes, warn_ops : warn (``orrc.SizeWarning``) above these.

    Examples
    --------
    >>> import orrc
    >>> limits = orrc.config.get_limits()
    >>> sorted(vars(limits))
    ['max_bytes', 'max_ops', 'warn_bytes', 'warn_ops']
    """

    max_bytes: float = 4 * 2 ** 30
    max_ops: float = 1e11
    warn_bytes: float = 2 ** 30
    warn_ops: float = 1e10


_LIMITS_ENV = {"max_bytes": "ORRC_MAX_BYTES", "max_ops": "ORRC_MAX_OPS", "warn_bytes": "ORRC_WARN_BYTES",
               "warn_ops": "ORRC_WARN_OPS"}
_limits: Limits | None = None


def limit_value(name: str, value) -> float:
    """One limit: a positive number of bytes or operations (``math.inf`` switches it off)."""
    return as_float(name, value, minimum=0.0, strict_min=True, allow_inf=True)


def get_limits() -> Limits:
    """The limits in force: read from the environment variables ``ORRC_MAX_BYTES``, ``ORRC_MAX_OPS``,
    ``ORRC_WARN_BYTES``, ``ORRC_WARN_OPS`` on first use, then as :func:`orrc.config.set_limits` sets them.

    Returns
    -------
    Limits
        ``max_bytes``, ``max_ops``, ``warn_bytes``, ``warn_ops``.

    Examples
    --------
    >>> import orrc
    >>> with orrc.config.limits(warn_ops=1e9):
    ...     print(orrc.config.get_limits().warn_ops)
    1000000000.0
    """
    global _limits
    if _limits is None:
        values = {}
        for field, var in _LIMITS_ENV.items():
            text = os.environ.get(var, "").strip()
            if text:
                try:
                    values[field] = limit_value(var, float(text))
                except ValueError as exc:
                    raise OrrcValueError(f"the environment variable {var} must be a positive number (bytes or "
                                         f"operations, or inf); got {text!r}") from exc
        _limits = Limits(**values)
    return _limits


def use_limits(new: Limits) -> Limits:
    """Put ``new`` in force (the mechanism of :func:`orrc.config.set_limits`); returns the previous limits."""
    global _limits
    previous = get_limits()
    _limits = new
    return previous


#: The nominal speed behind the time estimates: elementary floating-point operations per second.
OPS_PER_SECOND = 1e9
#: The cost of one numpy call on small arrays inside a Python loop, in operations (about 4 µs).
PY_CALL_OPS = 4e3
#: Bytes of one small numpy array beyond its data (object header, shape, strides).
ARRAY_OVERHEAD_BYTES = 112


def _fmt_bytes(nbytes: float) -> str:
    for unit, size in (("TiB", 2 ** 40), ("GiB", 2 ** 30), ("MiB", 2 ** 20), ("KiB", 2 ** 10)):
        if nbytes >= size:
            return f"{nbytes / size:.3g} {unit}"
    return f"{nbytes:.0f} bytes"


def _fmt_ops(ops: float) -> str:
    seconds = ops / OPS_PER_SECOND
    when = f"{seconds:.2g} s" if seconds < 120 else (f"{seconds / 60:.3g} min" if seconds < 7200
                                                      else f"{seconds / 3600:.3g} h")
    return f"{ops:.3g} operations (about {when} at {OPS_PER_SECOND:.0e} operations/s)"


def check_size(what: str, *, nbytes: float = 0.0, ops: float = 0.0, hint: str = "") -> None:
    """Refuse or warn before a computation whose memory or time grows fast.

    Call it with the caller's own estimate, *before* allocating or looping:

    * ``what``: the computation and the arguments that set its size, e.g.
      ``"PreviewRHC's exact LQ law at M=1000000, n=2"`` (the message must name the argument);
    * ``nbytes``: the peak memory it needs, in bytes (the big arrays, with their temporaries);
    * ``ops``: the elementary floating-point operations it performs; a Python loop costs about
      :data:`PY_CALL_OPS` per numpy call per iteration on top of its arithmetic. Times in the
      messages assume :data:`OPS_PER_SECOND`.
    * ``hint``: what the user can change (e.g. "lower M").

    Above ``orrc.config.get_limits().max_bytes`` or ``.max_ops`` it raises :class:`OrrcValueError`
    stating the estimate and the limit; above ``warn_bytes`` or ``warn_ops`` it issues a
    :class:`SizeWarning` and returns. The limits are ``orrc.config``'s (documented there,
    overridable with ``orrc.config.set_limits`` / ``orrc.config.limits`` or the environment
    variables ``ORRC_MAX_BYTES``, ``ORRC_MAX_OPS``, ``ORRC_WARN_BYTES``, ``ORRC_WARN_OPS``).
    Estimates may be rough (within a small factor); they exist to stop a 29 TiB allocation or
    an hour-long loop before it starts, not to time anything.
    """
    lim = get_limits()
    nbytes, ops = float(nbytes), float(ops)
    advice = f" {hint[:1].upper()}{hint[1:]}." if hint else ""
    if nbytes > lim.max_bytes or ops > lim.max_ops:
        parts = []
        if nbytes > lim.max_bytes:
            parts.append(f"about {_fmt_bytes(nbytes)} of memory (the limit is {_fmt_bytes(lim.max_bytes)})")
        if ops > lim.max_ops:
            parts.append(f"{_fmt_ops(ops)} (the limit is {lim.max_ops:.3g} operations)")
        raise OrrcValueError(
            f"{what}: too large to compute, it needs {' and '.join(parts)}.{advice} If the machine can afford it, "
            "raise the limit with orrc.config.limits(max_bytes=..., max_ops=...) or the environment variables "
            "ORRC_MAX_BYTES / ORRC_MAX_OPS.")
    if nbytes > lim.warn_bytes or ops > lim.warn_ops:
        warnings.warn(f"{what}: a large computation, about {_fmt_bytes(nbytes)} of memory and {_fmt_ops(ops)} "
                      f"(the warning thresholds are {_fmt_bytes(lim.warn_bytes)} and {lim.warn_ops:.3g} operations, "
                      f"orrc.config.limits).{advice}", SizeWarning, stacklevel=3)
