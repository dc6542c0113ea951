"""Disturbance sets W (Assumption 1): the ball, the box and the polytope, each with its membership
projection and sampler. Re-exported by :mod:`orrc.disturbances`, where they are documented.
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_array, as_float, as_int, as_seed, check_size


def _rng(seed, name: str = "seed") -> np.random.Generator:
    """The generator of ``seed`` (None, an int >= 0, a Generator, ...), refused otherwise."""
    return as_seed(name, seed)


def _sequence_size(L: int, n: int) -> None:
    check_size(f"a disturbance sequence of L={L} rows and n={n} columns", nbytes=3 * 8.0 * L * n,
               ops=20.0 * L * n, hint="lower L")


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


class Polytope:
    """W = conv{v_1, ..., v_k} ⊂ R^n, a polytope given by its vertices (rows of ``vertices``, (k, n)).

    Parameters
    ----------
    vertices : array_like, shape (k, n)
        The points whose convex hull is W (k >= 1; repeated or interior points are allowed, they
        only enlarge the scenario tree of :class:`~orrc.MinMaxRHC` with ``policy="feedback"``).

    Examples
    --------
    >>> import orrc
    >>> W = orrc.Polytope([[0.3, 0.0], [-0.3, 0.1], [0.0, -0.2]])
    >>> W.vertices().shape, round(W.max_norm_sq, 2)
    ((3, 2), 0.1)
    """

    def __init__(self, vertices):
        V = as_array("vertices", vertices, ndim=2)
        if V.shape[0] < 1 or V.shape[1] < 1:
            raise OrrcValueError(f"vertices must have shape (k, n) with k >= 1 points of R^n; got shape {V.shape}")
        if np.abs(V).max() > 1e150 / np.sqrt(V.shape[1]):
            raise OrrcValueError("vertices must be at most 1e150/sqrt(n) in magnitude (so that max ‖w‖² is a float)")
        self._V = V.copy()
        self.n = V.shape[1]

    @property
    def max_norm_sq(self) -> float:
        """max_{w∈W} ‖w‖² (attained at a vertex), a float."""
        return float(np.max(np.sum(self._V ** 2, axis=1)))

    def vertices(self) -> np.ndarray:
        """The k given points, shape (k, n) (a copy)."""
        return self._V.copy()

    def contains(self, w, tol: float = 1e-9) -> bool:
        """True when every row of w ((n,) or (L, n)) is a convex combination of the vertices, up to
        ``tol`` relative to max‖v‖ (one small linear program per row)."""
        from scipy.optimize import linprog

        w = _points("w", w, self.n)
        tol = as_float("tol", tol, minimum=0.0)
        k = self._V.shape[0]
        scale = max(np.sqrt(self.max_norm_sq), 1e-300)
        for row in w:   # min s s.t. |Vᵀλ - w| <= s, λ >= 0, Σλ = 1
            c = np.zeros(k + 1)
            c[-1] = 1.0
            A = np.block([[self._V.T, -np.ones((self.n, 1))], [-self._V.T, -np.ones((self.n, 1))]])
            b = np.concatenate([row, -row])
            res = linprog(c, A_ub=A, b_ub=b, A_eq=np.concatenate([np.ones(k), [0.0]])[None, :], b_eq=[1.0],
                          bounds=[(0, None)] * (k + 1), method="highs")
            if not res.success or res.fun > tol * scale:
                return False
        return True

    def sample(self, L: int, seed=None) -> np.ndarray:
        """L random convex combinations of the vertices (Dirichlet(1) weights, i.i.d.), shape (L, n)."""
        L = as_int("L", L, minimum=1)
        _sequence_size(L, self.n)
        lam = _rng(seed).dirichlet(np.ones(self._V.shape[0]), size=L)
        return lam @ self._V

    def __repr__(self):
        return f"Polytope({self._V.shape[0]} vertices in R^{self.n})"
