"""Disturbance sequences w_0, w_1, ... and disturbance sets W (Assumption 1).

Sequences are arrays of shape (L, n), time along axis 0. A simulation of T steps
with preview M reads rows 0..T+M-2, so generate ``L = T + M`` rows to give the
controller a full preview up to the end (see :func:`orrc.simulate`).
Every random generator takes ``seed`` (an int or a ``numpy.random.Generator``).
"""
from __future__ import annotations

import numpy as np

from ._disturbance_sets import Ball, Box, Polytope, _rng, _sequence_size
from ._validate import OrrcValueError, as_array, as_float, as_int, check_finite_result

__all__ = ["zero", "constant", "sinusoid", "uniform_ball", "uniform_box", "gaussian", "bursts", "make", "energy",
           "Ball", "Box", "Polytope"]

KINDS = ("zero", "constant", "sinusoid", "uniform_ball", "uniform_box", "gaussian", "bursts")


def _dims(L, n):
    L, n = as_int("L", L, minimum=1), as_int("n", n, minimum=1)
    _sequence_size(L, n)
    return L, n


def zero(L: int, n: int) -> np.ndarray:
    """w_t = 0 for every t: the disturbance-free case of Eq. (1).

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.

    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.zero(3, 2)
    array([[0., 0.],
           [0., 0.],
           [0., 0.]])
    """
    L, n = _dims(L, n)
    return np.zeros((L, n))


def constant(L: int, n: int, value) -> np.ndarray:
    """w_t = value for every t: a constant disturbance of Eq. (1).

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    value : a scalar (every coordinate) or a vector of length n.
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.constant(2, 2, [0.5, -1.0])
    array([[ 0.5, -1. ],
           [ 0.5, -1. ]])
    """
    L, n = _dims(L, n)
    value = np.broadcast_to(as_array("value", value), (n,)) if np.ndim(value) == 0 else as_array("value", value, (n,))
    return np.tile(value, (L, 1))


def sinusoid(L: int, n: int, amplitude: float = 1.0, period: float = 20.0, phase: float = 0.0) -> np.ndarray:
    """w_t = amplitude · sin(2π t / period + phase + 2π i / n) in coordinate i: a bounded periodic disturbance.

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    amplitude : the amplitude, >= 0.
    period : the period in steps, > 0.
    phase : the phase of coordinate 0 (radians).
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.sinusoid(3, 1, amplitude=2.0, period=4.0).round(6)
    array([[0.],
           [2.],
           [0.]])
    """
    L, n = _dims(L, n)
    amplitude = as_float("amplitude", amplitude, minimum=0.0)
    period = as_float("period", period, minimum=0.0, strict_min=True)
    phase = as_float("phase", phase)
    t = np.arange(L)[:, None]
    return amplitude * np.sin(2 * np.pi * t / period + phase + 2 * np.pi * np.arange(n)[None, :] / n)


def uniform_ball(L: int, n: int, radius: float = 1.0, seed=None) -> np.ndarray:
    """w_t drawn uniformly from the Euclidean ball ‖w‖ <= radius, i.i.d.: bounded as Assumption 1 asks.

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    radius : the ball's radius, >= 0.
    seed : a seed or ``numpy.random.Generator`` (None: fresh entropy).
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> w = orrc.disturbances.uniform_ball(L=100, n=2, radius=0.1, seed=0)
    >>> w.shape, bool(np.all(np.linalg.norm(w, axis=1) <= 0.1))
    ((100, 2), True)
    """
    L, n = _dims(L, n)
    return Ball(radius, n).sample(L, seed)


def uniform_box(L: int, n: int, lo=-1.0, hi=1.0, seed=None) -> np.ndarray:
    """w_t drawn uniformly from the box lo <= w <= hi, i.i.d.: bounded as Assumption 1 asks.

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    lo, hi : the box's corners, scalars or length-n arrays with lo <= hi.
    seed : a seed or ``numpy.random.Generator`` (None: fresh entropy).
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> w = orrc.disturbances.uniform_box(L=50, n=2, lo=[-1.0, 0.0], hi=[1.0, 0.5], seed=0)
    >>> w.shape, bool((w[:, 1] >= 0.0).all() and (w[:, 1] <= 0.5).all())
    ((50, 2), True)
    """
    L, n = _dims(L, n)
    return Box(lo, hi, n).sample(L, seed)


def gaussian(L: int, n: int, std: float = 1.0, seed=None) -> np.ndarray:
    """w_t ~ N(0, std² I) i.i.d.: unbounded, outside Assumption 1, for comparison only.

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    std : the standard deviation of each coordinate, >= 0.
    seed : a seed or ``numpy.random.Generator`` (None: fresh entropy).
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.gaussian(L=1000, n=3, std=0.5, seed=0).shape
    (1000, 3)
    """
    L, n = _dims(L, n)
    std = as_float("std", std, minimum=0.0)
    return std * _rng(seed).standard_normal((L, n))


def bursts(L: int, n: int, magnitude: float = 1.0, every: int = 25, duration: int = 3, seed=None) -> np.ndarray:
    """Rare large pulses: every ``every`` steps, ``duration`` steps of norm ``magnitude`` in a random direction; zero otherwise.

    Parameters
    ----------
    L : the number of steps (rows), L >= 1; a controller with preview M simulated for T steps
        needs L >= T + M - 1.
    n : the state dimension, n >= 1.
    magnitude : the norm ‖w_t‖ during a pulse, >= 0.
    every : the steps from one pulse's start to the next (the first starts at every // 2).
    duration : the steps a pulse lasts.
    seed : a seed or ``numpy.random.Generator`` for the directions (None: fresh entropy).
    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When L or n is not an integer >= 1, another argument is out of range, or the sequence
        would exceed the size limits of ``orrc.config``.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> w = orrc.disturbances.bursts(L=50, n=2, magnitude=2.0, every=25, duration=3, seed=0)
    >>> np.flatnonzero(np.linalg.norm(w, axis=1) > 0)
    array([12, 13, 14, 37, 38, 39])
    """
    L, n = _dims(L, n)
    magnitude = as_float("magnitude", magnitude, minimum=0.0)
    every = as_int("every", every, minimum=1)
    duration = as_int("duration", duration, minimum=1)
    rng = _rng(seed)
    w = np.zeros((L, n))
    for start in range(every // 2, L, every):
        d = rng.standard_normal(n)
        w[start:start + duration] = magnitude * d / np.linalg.norm(d)
    return w


def make(kind: str, L: int, n: int, scale: float = 1.0, seed=None) -> np.ndarray:
    """A disturbance of a named ``kind`` (one of :data:`KINDS`) with size ``scale``.

    Parameters
    ----------
    kind : one of :data:`KINDS` ("zero", "constant", "sinusoid", "uniform_ball", "uniform_box",
        "gaussian", "bursts").
    L, n : the number of steps and the state dimension.
    scale : the size: the norm of a constant, the amplitude, the radius, the half-width of the box,
        the standard deviation or the pulses' magnitude.
    seed : a seed for the random kinds.

    Returns
    -------
    numpy.ndarray
        (L, n), row t is w_t.

    Raises
    ------
    orrc.OrrcValueError
        When ``kind`` is unknown or a size is out of range.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.make("uniform_box", L=4, n=2, scale=0.5, seed=1).shape
    (4, 2)
    """
    if not isinstance(kind, str) or kind not in KINDS:
        raise OrrcValueError(f"unknown disturbance kind {kind!r}; allowed: {list(KINDS)}")
    scale = as_float("scale", scale, minimum=0.0)
    if kind == "zero":
        return zero(L, n)
    if kind == "constant":
        return constant(L, n, scale / np.sqrt(n))
    if kind == "sinusoid":
        return sinusoid(L, n, amplitude=scale)
    if kind == "uniform_ball":
        return uniform_ball(L, n, radius=scale, seed=seed)
    if kind == "uniform_box":
        return uniform_box(L, n, -scale, scale, seed=seed)
    if kind == "gaussian":
        return gaussian(L, n, std=scale, seed=seed)
    return bursts(L, n, magnitude=scale, seed=seed)


def energy(w) -> float:
    """Σ_t ‖w_t‖² of a sequence: the disturbance energy that Eq. (2) weighs by γ.

    Parameters
    ----------
    w : (L, n) the sequence.

    Returns
    -------
    float
        Σ_t ‖w_t‖².

    Raises
    ------
    orrc.OrrcValueError
        When w is not a finite 2-D array, or the sum overflows.

    Examples
    --------
    >>> import orrc
    >>> orrc.disturbances.energy([[3.0, 4.0], [1.0, 0.0]])
    26.0
    """
    w = as_array("w", w, ndim=2)
    with np.errstate(over="ignore"):
        return check_finite_result("the energy Σ‖w_t‖²", float(np.sum(w * w)), "w", "rescale w")
