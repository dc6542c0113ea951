"""Input checks shared by the whole package.

Every public function of ``orrc`` validates what it is given with these helpers,
so that bad input fails early with a message that names the argument, says what
was given and what is allowed (never a silent NaN, never a hang).
"""
from __future__ import annotations

import numbers

import numpy as np


class OrrcValueError(ValueError):
    """Bad input to an ``orrc`` function (a ``ValueError`` subclass)."""


def _describe(value) -> str:
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def as_array(name: str, value, shape: tuple | None = None, *, ndim: int | None = None,
             allow_nonfinite: bool = False) -> np.ndarray:
    """Convert ``value`` to a float array and check its shape and finiteness.

    ``shape`` may contain ``None`` for a free dimension.
    """
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise OrrcValueError(f"{name} must be numeric; got {_describe(value)}") from exc
    if ndim is not None and arr.ndim != ndim:
        raise OrrcValueError(f"{name} must be {ndim}-dimensional; got shape {arr.shape}")
    if shape is not None:
        ok = arr.ndim == len(shape) and all(s is None or s == d for s, d in zip(shape, arr.shape))
        if not ok:
            want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
            raise OrrcValueError(f"{name} must have shape {want}; got shape {arr.shape}")
    if not allow_nonfinite and not np.all(np.isfinite(arr)):
        raise OrrcValueError(f"{name} must be finite; got non-finite entries (NaN or inf)")
    return arr


def as_square(name: str, value, n: int | None = None) -> np.ndarray:
    arr = np.atleast_2d(as_array(name, value))
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or (n is not None and arr.shape[0] != n):
        want = f"({n}, {n})" if n is not None else "square"
        raise OrrcValueError(f"{name} must be {want}; got shape {arr.shape}")
    return arr


def as_int(name: str, value, minimum: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise OrrcValueError(f"{name} must be an integer; got {_describe(value)}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise OrrcValueError(f"{name} must be an integer >= {minimum}; got {value}")
    return value


def as_float(name: str, value, *, minimum: float | None = None, maximum: float | None = None,
             strict_min: bool = False, strict_max: bool = False, allow_inf: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise OrrcValueError(f"{name} must be a real number; got {_describe(value)}")
    value = float(value)
    if np.isnan(value) or (np.isinf(value) and not allow_inf):
        raise OrrcValueError(f"{name} must be finite; got {value}")
    if minimum is not None and (value < minimum or (strict_min and value == minimum)):
        op = ">" if strict_min else ">="
        raise OrrcValueError(f"{name} must be {op} {minimum}; got {value}")
    if maximum is not None and (value > maximum or (strict_max and value == maximum)):
        op = "<" if strict_max else "<="
        raise OrrcValueError(f"{name} must be {op} {maximum}; got {value}")
    return value


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
    """Check that the square ``mat`` is symmetric positive semidefinite (``strict``: definite).

    Every test is relative to the scale of ``mat``, so a matrix passes or fails the same way
    whatever its units and whatever BLAS kernel computes its eigenvalues:

    * symmetric: max |mat - matᵀ| <= 1e-10 max |mat|. A matrix built symmetric but computed in
      floating point (G Gᵀ, a sum of such) is off by at most ~2k·eps·max|mat| (k the inner
      dimension), far below; a matrix that is not meant to be symmetric is far above.
    * eigenvalues: ``tol`` (default :func:`eigvalsh_tol`, N·eps·‖mat‖₂) bounds their rounding
      error. λ_min < -tol proves that mat is indefinite; with ``strict``, λ_min <= tol cannot be
      told apart from a singular matrix, so it is refused as not positive definite.
    """
    if mat.size and not np.abs(mat - mat.T).max() <= 1e-10 * np.abs(mat).max():
        raise OrrcValueError(f"{name} must be symmetric")
    lo = float(np.linalg.eigvalsh(mat).min()) if mat.size else 0.0
    tol = eigvalsh_tol(mat) if tol is None else tol
    if strict and lo <= tol:
        raise OrrcValueError(f"{name} must be positive definite; its smallest eigenvalue is {lo:.3g}")
    if not strict and lo < -tol:
        raise OrrcValueError(f"{name} must be positive semidefinite; its smallest eigenvalue is {lo:.3g}")


def check_options(name: str, given: dict, allowed) -> None:
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        raise OrrcValueError(f"unknown {name} {unknown}; allowed: {sorted(allowed)}")
