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
import numbers
import os
import warnings
from dataclasses import dataclass

import numpy as np


class OrrcValueError(ValueError):
    """Bad input to an ``orrc`` function (a ``ValueError`` subclass).

    Raised for input of the wrong type, shape or range, non-finite or complex input, empty
    dimensions, and computations too large for the limits of ``orrc.config`` (the message
    then states the estimate and the limit).

    Examples
    --------
    >>> import orrc
    >>> try:
    ...     orrc.LinearSystem([[1.0, 0.1], [0.0, 1.0]], [[0.0], [0.1], [1.0]])
    ... except orrc.OrrcValueError as err:
    ...     print(err)
    B must have shape (2, m) with m >= 1 to match A of shape (2, 2); got shape (3, 1)
    """


class SizeWarning(UserWarning):
    """A computation is large (above ``orrc.config`` 's warning thresholds) but allowed.

    Examples
    --------
    A computation above the warning threshold runs, and says how large it is:

    >>> import warnings
    >>> import orrc
    >>> with orrc.config.limits(warn_bytes=1e3), warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     vertices = orrc.Box(-1.0, 1.0, n=8).vertices()
    >>> vertices.shape, [w.category.__name__ for w in caught]
    ((256, 8), ['SizeWarning'])
    """


class NonFiniteWarning(RuntimeWarning):
    """A result overflowed (inf or NaN) although the input was finite; the message says where.

    Examples
    --------
    An unstable loop whose state stays finite while its stage costs overflow:

    >>> import warnings
    >>> import numpy as np
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable(A=1e100)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     traj = orrc.simulate(ex.system, orrc.ZeroInput(1, ex.cost), [1.0], np.zeros((3, 1)), T=3)
    >>> [w.category.__name__ for w in caught]
    ['NonFiniteWarning']
    """


def _describe(value) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def as_array(name: str, value, shape: tuple | None = None, *, ndim: int | None = None,
             allow_nonfinite: bool = False, allow_empty: bool = True) -> np.ndarray:
    """Convert ``value`` to a float array and check its shape, finiteness and (optionally) size.

    ``shape`` may contain ``None`` for a free dimension. Complex input is refused (its
    imaginary part would otherwise be dropped silently), and so is anything numpy cannot
    read as numbers. ``allow_empty=False`` refuses an array with a zero-length dimension.
    """
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise OrrcValueError(f"{name} must be numeric; got {_describe(value)}") from exc
    if raw.dtype.kind == "c":
        raise OrrcValueError(f"{name} must be real; got a complex array (dtype {raw.dtype}): "
                             "pass its real part explicitly if that is what you mean")
    try:
        arr = raw.astype(float, copy=False) if raw.dtype != float else raw
    except (TypeError, ValueError) as exc:
        raise OrrcValueError(f"{name} must be numeric; got {_describe(value)}") from exc
    if ndim is not None and arr.ndim != ndim:
        raise OrrcValueError(f"{name} must be {ndim}-dimensional; got shape {arr.shape}")
    if shape is not None and arr.shape != shape:   # (equal: no free dimension to match)
        ok = arr.ndim == len(shape) and all(s is None or s == d for s, d in zip(shape, arr.shape))
        if not ok:
            want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise OrrcValueError(f"{name} must have shape {want}; got shape {arr.shape}")
    if not allow_empty and arr.size == 0:
        raise OrrcValueError(f"{name} must not be empty; got shape {arr.shape}")
    if not allow_nonfinite and not np.isfinite(arr).all():
        raise OrrcValueError(f"{name} must be finite; got non-finite entries (NaN or inf)")
    return arr


def as_square(name: str, value, n: int | None = None) -> np.ndarray:
    """A non-empty square float matrix (a scalar is read as 1 x 1), of size n when given."""
    arr = np.atleast_2d(as_array(name, value))
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or (n is not None and arr.shape[0] != n):
        want = f"({n}, {n})" if n is not None else "square"
        raise OrrcValueError(f"{name} must be {want}; got shape {arr.shape}")
    if arr.shape[0] == 0:
        raise OrrcValueError(f"{name} must be a non-empty square matrix; got shape {arr.shape}")
    return arr


def as_int(name: str, value, minimum: int | None = None, maximum: int | None = None) -> int:
    """An integer (not a bool, not a float such as 2.0) within [minimum, maximum]."""
    if type(value) is not int:   # (a plain int, the common case, needs no check of its type's ABCs)
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise OrrcValueError(f"{name} must be an integer; got {_describe(value)}")
        value = int(value)
    if minimum is not None and value < minimum:
        raise OrrcValueError(f"{name} must be an integer >= {minimum}; got {value}")
    if maximum is not None and value > maximum:
        raise OrrcValueError(f"{name} must be an integer <= {maximum}; got {value}")
    return value


def as_bool(name: str, value) -> bool:
    """A truth value given as ``True`` or ``False`` (a Python or numpy bool), never coerced: ``bool("no")``
    is True, so a string, a number or None is refused."""
    if not isinstance(value, (bool, np.bool_)):
        raise OrrcValueError(f"{name} must be True or False; got {_describe(value)}")
    return bool(value)


def as_float(name: str, value, *, minimum: float | None = None, maximum: float | None = None,
             strict_min: bool = False, strict_max: bool = False, allow_inf: bool = False) -> float:
    """A real number (not a bool, not complex), finite unless ``allow_inf``, within the bounds."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise OrrcValueError(f"{name} must be a real number; got {_describe(value)}")
    value = float(value)
    if math.isnan(value) or (math.isinf(value) and not allow_inf):
        raise OrrcValueError(f"{name} must be finite; got {value}")
    if minimum is not None and (value < minimum or (strict_min and value == minimum)):
        op = ">" if strict_min else ">="
        raise OrrcValueError(f"{name} must be {op} {minimum}; got {value}")
    if maximum is not None and (value > maximum or (strict_max and value == maximum)):
        op = "<" if strict_max else "<="
        raise OrrcValueError(f"{name} must be {op} {maximum}; got {value}")
    return value


def as_seed(name: str, seed) -> np.random.Generator:
    """A ``numpy.random.Generator`` from ``seed``: None (fresh entropy), a non-negative integer,
    a ``Generator`` (used as is), a ``SeedSequence`` or a ``BitGenerator``."""
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None or isinstance(seed, (np.random.SeedSequence, np.random.BitGenerator)):
        return np.random.default_rng(seed)
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise OrrcValueError(
            f"{name} must be None, a non-negative integer or a numpy.random.Generator; got {_describe(seed)}")
    return np.random.default_rng(int(seed))


def eigvalsh_tol(mat: np.ndarray) -> float:
    """N·eps·‖mat‖₂: a bound on the rounding error of every eigenvalue ``np.linalg.eigvalsh`` returns
    for the symmetric N×N ``mat``. LAPACK's symmetric eigensolvers are backward stable (the computed
    eigenvalues are exact for mat + E, ‖E‖₂ <= p(N)·eps·‖mat‖₂ with p(N) a modest function of N;
    p(N) = N here) and, by Weyl's inequality, each eigenvalue moves by at most ‖E‖₂. The bound
    scales with the data and holds whatever BLAS kernel runs."""
    if mat.size == 0:
        return 0.0
    return mat.shape[0] * float(np.finfo(float).eps) * float(np.linalg.norm(mat, 2))


def check_psd(name: str, mat: np.ndarray, *, strict: bool = False, tol: float | None = None) -> None:
    """``mat`` symmetric positive semidefinite (``strict``: definite); ``mat`` may be a stack
    (..., k, k) of matrices, each checked.

    Every test is relative to the scale of each matrix, so a matrix passes or fails the same way
    whatever its units and whatever BLAS kernel computes its eigenvalues:

    * symmetric: max |mat - matᵀ| <= 1e-10 max |mat|. A matrix built symmetric but computed in
      floating point (G Gᵀ, a sum of such) is off by at most ~2k·eps·max|mat| (k the inner
      dimension), far below; a matrix that is not meant to be symmetric is far above.
    * eigenvalues: ``tol`` (default k·eps·‖mat‖₂, :func:`eigvalsh_tol`) bounds their rounding
      error. λ_min < -tol proves that mat is indefinite; with ``strict``, λ_min <= tol cannot be
      told apart from a singular matrix, so it is refused as not positive definite.
    """
    if mat.size == 0:
        return
    asym = np.abs(mat - np.swapaxes(mat, -1, -2)).max(axis=(-2, -1))
    if not np.all(asym <= 1e-10 * np.abs(mat).max(axis=(-2, -1))):
        raise OrrcValueError(f"{name} must be symmetric")
    lam_all = np.linalg.eigvalsh(mat)
    lam = lam_all[..., 0]
    if tol is None:   # eigvalsh_tol of each matrix, with ‖mat‖₂ = max |λ| (symmetric)
        tol = mat.shape[-1] * float(np.finfo(float).eps) * np.abs(lam_all).max(axis=-1)
    excess = lam - (tol if strict else -np.asarray(tol))    # <= 0 (strict) / < 0: refused
    k = int(np.argmin(excess))
    lo = float(np.ravel(lam)[k])
    where = "" if lam.ndim == 0 else f" (at row {k})"
    if strict and np.ravel(excess)[k] <= 0:
        raise OrrcValueError(f"{name} must be positive definite; its smallest eigenvalue is {lo:.3g}{where}")
    if not strict and np.ravel(excess)[k] < 0:
        raise OrrcValueError(f"{name} must be positive semidefinite; its smallest eigenvalue is {lo:.3g}{where}")


def check_options(name: str, given: dict, allowed) -> None:
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        raise OrrcValueError(f"unknown {name} {unknown}; allowed: {sorted(allowed)}")


# -- user functions ---------------------------------------------------------------------------------
def probe_points(n: int, m: int):
    """The origin, then a fixed generic point (x_i, u_i in (0.1, 0.6), not symmetric)."""
    yield np.zeros(n), np.zeros(m)
    yield 0.1 + 0.5 * (np.arange(n) + 1) / (n + 1), 0.1 + 0.3 * (np.arange(m) + 1) / (m + 1)


def check_evaluates(name: str, what: str, evaluate, n: int, m: int) -> None:
    """Evaluate a user function once, at the origin and (if that is not finite) at a generic point,
    and refuse it when neither value is finite: typically ``math.sin`` (or numpy) applied to a
    CasADi symbol, which traces to NaN everywhere instead of failing."""
    for x, u in probe_points(n, m):
        try:
            value = np.asarray(evaluate(x, u), dtype=float)
        except Exception as exc:  # the traced function fails numerically
            raise OrrcValueError(f"{name}: evaluating {what} at x={x}, u={u} failed: {exc}") from exc
        if np.all(np.isfinite(value)):
            return
    raise OrrcValueError(
        f"{name}: {what} is not finite at the origin nor at x={x}, u={u}: it evaluates to {value.ravel()}. "
        "Write it with CasADi operations (ca.sin, ca.exp, ...): math or numpy functions applied to a CasADi "
        "symbol do not fail, they trace to NaN")


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
