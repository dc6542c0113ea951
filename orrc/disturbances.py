"""Disturbance sequences w_0, w_1, ... and disturbance sets W (Assumption 1).

Sequences are arrays of shape (L, n), time along axis 0. A simulation of T steps
with preview M reads rows 0..T+M-2, so generate ``L = T + M`` rows to give the
controller a full preview up to the end (see :func:`orrc.simulate`).
Every random generator takes ``seed`` (an int or a ``numpy.random.Generator``).
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_array, as_float, as_int, as_seed, check_finite_result, check_size

KINDS = ("zero", "constant", "sinusoid", "uniform_ball", "uniform_box", "gaussian", "bursts")


def _rng(seed, name: str = "seed") -> np.random.Generator:
    """The generator of ``seed`` (None, an int >= 0, a Generator, ...), refused otherwise."""
    return as_seed(name, seed)


def _sequence_size(L: int, n: int) -> None:
    check_size(f"a disturbance sequence of L={L} rows and n={n} columns", nbytes=3 * 8.0 * L * n,
               ops=20.0 * L * n, hint="lower L")


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


def _points(name: str, w, n: int) -> np.ndarray:
    """w as an (L, n) array: one point (n,) or L points (L, n)."""
    w = as_array(name, w)
    if w.ndim == 1 and w.shape[0] == n:
        return w[None, :]
    if w.ndim != 2 or w.shape[1] != n:
        raise OrrcValueError(f"{name} must have shape ({n},) or (L, {n}); got shape {w.shape}")
    return w


class Ball:
    """W = {w : ‖w‖₂ <= radius} ⊂ R^n.

    Parameters
    ----------
    radius : the radius, >= 0.
    n : the dimension, >= 1.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> W = orrc.Ball(0.5, 2)
    >>> W.max_norm_sq, W.contains(np.array([0.3, 0.3])), W.sample(3, seed=0).shape
    (0.25, True, (3, 2))
    """

    def __init__(self, radius: float, n: int):
        self.radius = as_float("radius", radius, minimum=0.0, maximum=1e150)  # radius² stays a float
        self.n = as_int("n", n, minimum=1)

    @property
    def max_norm_sq(self) -> float:
        """max_{w∈W} ‖w‖² (the w_c² of Assumption 1)."""
        return self.radius ** 2

    def contains(self, w, tol: float = 1e-9) -> bool:
        """True when every row of w ((n,) or (L, n)) lies in the ball, up to a relative ``tol``
        (‖w‖ is computed to n·eps relative; the allowance scales with the radius, so the test
        does not depend on units)."""
        w = _points("w", w, self.n)
        tol = as_float("tol", tol, minimum=0.0)
        return bool(np.all(np.linalg.norm(w, axis=1) <= self.radius * (1 + tol)))

    def sample(self, L: int, seed=None) -> np.ndarray:
        """L points drawn uniformly from the ball (i.i.d.), shape (L, n)."""
        L = as_int("L", L, minimum=1)
        _sequence_size(L, self.n)
        rng = _rng(seed)
        d = rng.standard_normal((L, self.n))
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
        r = self.radius * rng.random((L, 1)) ** (1.0 / self.n)
        return d * r

    def __repr__(self):
        return f"Ball(radius={self.radius}, n={self.n})"


class Box:
    """W = {w : lo <= w <= hi} ⊂ R^n (lo, hi scalars or length-n arrays).

    Parameters
    ----------
    lo, hi : the corners (scalars or length-n arrays, lo <= hi).
    n : the dimension, when lo and hi are both scalars.

    Examples
    --------
    >>> import orrc
    >>> W = orrc.Box(-1.0, [1.0, 2.0])
    >>> W.vertices()
    array([[-1., -1.],
           [-1.,  2.],
           [ 1., -1.],
           [ 1.,  2.]])
    """

    def __init__(self, lo, hi, n: int | None = None):
        lo, hi = np.atleast_1d(as_array("lo", lo)), np.atleast_1d(as_array("hi", hi))
        if n is None:
            n = max(lo.size, hi.size)
        self.n = as_int("n", n, minimum=1)
        if lo.ndim != 1 or hi.ndim != 1 or lo.size not in (1, self.n) or hi.size not in (1, self.n):
            raise OrrcValueError(f"lo and hi must be scalars or length-{self.n} arrays; got shapes "
                                 f"{lo.shape}, {hi.shape}")
        self.lo, self.hi = np.broadcast_to(lo, (self.n,)).copy(), np.broadcast_to(hi, (self.n,)).copy()
        if np.any(self.lo > self.hi):
            raise OrrcValueError(f"need lo <= hi in every coordinate; got lo={self.lo}, hi={self.hi}")
        if max(np.abs(self.lo).max(), np.abs(self.hi).max()) > 1e150 / np.sqrt(self.n):
            raise OrrcValueError(f"lo and hi must be at most 1e150/sqrt(n) in magnitude (so that max ‖w‖² is a "
                                 f"float); got lo={self.lo}, hi={self.hi}")

    @property
    def max_norm_sq(self) -> float:
        """max_{w∈W} ‖w‖² (attained at a vertex)."""
        return float(np.sum(np.maximum(self.lo ** 2, self.hi ** 2)))

    def vertices(self) -> np.ndarray:
        """The 2^n corners of the box, shape (2^n, n), in the order of ``itertools.product``
        (the first coordinate varies slowest). Refused when 2^n rows exceed ``orrc.config``'s limits."""
        n = self.n
        check_size(f"the 2^n vertices of a box in n={n} dimensions", nbytes=3 * 8.0 * 2.0 ** n * n,
                   ops=4.0 * 2.0 ** n * n, hint="lower n, or enumerate vertices lazily")
        bits = (np.arange(2 ** n)[:, None] >> np.arange(n - 1, -1, -1)[None, :]) & 1
        return np.where(bits == 1, self.hi, self.lo)

    def contains(self, w, tol: float = 1e-9) -> bool:
        """True when every row of w ((n,) or (L, n)) lies in the box, up to ``tol`` relative to
        each coordinate's scale max(|lo_i|, |hi_i|) (so the test does not depend on units)."""
        w = _points("w", w, self.n)
        tol = as_float("tol", tol, minimum=0.0)
        slack = tol * np.maximum(np.abs(self.lo), np.abs(self.hi))
        return bool(np.all(w >= self.lo - slack) and np.all(w <= self.hi + slack))

    def sample(self, L: int, seed=None) -> np.ndarray:
        """L points drawn uniformly from the box (i.i.d.), shape (L, n)."""
        L = as_int("L", L, minimum=1)
        _sequence_size(L, self.n)
        r = _rng(seed).random((L, self.n))
        return self.lo * (1.0 - r) + self.hi * r

    def __repr__(self):
        return f"Box(lo={self.lo}, hi={self.hi})"
