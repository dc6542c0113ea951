"""The argument validators: each turns a given value into the array or number a function needs,
or raises :class:`~orrc.OrrcValueError` naming the argument, what was given and what is allowed.
Re-exported by ``orrc._validate``.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ._errors import OrrcValueError


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
