"""The EDMD dictionary ψ(x) ∈ R^K (that contains x itself): a user dictionary, monomials up to a
degree, Gaussian radial basis functions. Re-exported by :mod:`orrc.estimation.edmd`, where they are
documented.
"""
from __future__ import annotations

import itertools
import math
from typing import Callable

import casadi as ca
import numpy as np

from .._validate import OrrcValueError, as_array, as_bool, as_float, as_int, check_size


def _check_features(K: int, what: str, terms: int = 1) -> None:
    """The size guard of a dictionary of K features (each of about ``terms`` CasADi operations): building it
    and checking that it contains the state costs a (3K x K) probe matrix and its least squares, O(K³)."""
    check_size(f"{what} (K = {K} features)", nbytes=3.0 * K * K * 8 + 400.0 * K * terms,
               ops=3.0 * K ** 3 + 30.0 * K * K * terms,
               hint="lower the degree or the number of centres (the EDMD fit then costs O(N K²) and control on the "
                    "lifted model O(M³ K³))")


class Dictionary:
    """A dictionary ψ(x) ∈ R^K of functions of the state, written with CasADi operations.

    ``psi(x)`` receives a CasADi column vector of length ``n`` and returns K functions of it.
    The dictionary must contain the state: x = C ψ(x) for a linear projection C, found exactly
    when x appears among the features (else by least squares on probe points, to 1e-9 relative).
    A dictionary without the state raises :class:`~orrc.OrrcValueError`.

    Parameters
    ----------
    psi : ψ(x) in CasADi operations, returning the K features of a column vector of length n.
    n : the state dimension.
    name : a label.
    labels : the K features' names.

    Raises
    ------
    orrc.OrrcValueError
        When ψ does not contain the state or does not evaluate to finite numbers.

    Examples
    --------
    >>> import casadi as ca
    >>> from orrc import estimation
    >>> d = estimation.Dictionary(lambda x: ca.vertcat(x, ca.sin(x[0])), n=2)
    >>> d.K
    3
    """

    def __init__(self, psi: Callable, n: int, name: str = "dictionary", labels=None):
        if not callable(psi):
            raise OrrcValueError(f"psi must be callable psi(x); got {type(psi).__name__}")
        self.n = as_int("n", n, minimum=1)
        self.name = name
        x = ca.SX.sym("x", self.n)
        try:
            out = ca.vec(ca.SX(psi(x)))
        except Exception as exc:
            raise OrrcValueError(f"psi(x) must be written with CasADi operations; tracing it failed with: {exc}") from exc
        self.K = int(out.shape[0])
        self.function = ca.Function("psi", [x], [out])
        _check_features(self.K, f"the dictionary {name!r}", terms=max(1, self.function.n_nodes() // max(self.K, 1)))
        self.labels = [f"psi[{j}]" for j in range(self.K)] if labels is None else [str(s) for s in labels]
        if len(self.labels) != self.K:
            raise OrrcValueError(f"labels must name the K = {self.K} features; got {len(self.labels)}")
        self.C = self._projection()

    def _projection(self) -> np.ndarray:
        rng = np.random.default_rng(20210)
        P = rng.uniform(-1.0, 1.0, (max(3 * self.K, 20), self.n))
        Psi = self(P)
        if not np.all(np.isfinite(Psi)):
            raise OrrcValueError(f"the dictionary {self.name!r} is not finite on [-1, 1]^n (probe points)")
        C = np.zeros((self.n, self.K))
        for i in range(self.n):  # x_i itself among the features: exact selection
            hit = np.flatnonzero(np.all(Psi == P[:, [i]], axis=0))
            if hit.size == 0:
                break
            C[i, hit[0]] = 1.0
        else:
            return C
        C, *_ = np.linalg.lstsq(Psi, P, rcond=None)
        C = C.T
        err = np.linalg.norm(Psi @ C.T - P) / np.linalg.norm(P)
        if not err <= 1e-9:
            raise OrrcValueError(
                f"the dictionary {self.name!r} must contain the state x (x = C psi(x) for a linear projection C, "
                f"e.g. put x itself first); the best linear projection misses x by {err:.3g} (relative)")
        return C

    def __call__(self, X) -> np.ndarray:
        """ψ at one state (n,) → (K,), or at k states (k, n) → (k, K)."""
        X = as_array("X", X)
        single = X.ndim == 1
        X2 = X[None, :] if single else X
        if X2.ndim != 2 or X2.shape[1] != self.n:
            raise OrrcValueError(f"X must have shape (k, {self.n}) or ({self.n},); got shape {X.shape}")
        out = np.asarray(self.function.map(X2.shape[0])(X2.T)).T
        return out[0] if single else out

    def __repr__(self):
        return f"Dictionary({self.name!r}, n={self.n}, K={self.K})"


def polynomial_dictionary(n: int, degree: int, include_constant: bool = False) -> Dictionary:
    """All monomials of x ∈ R^n of total degree 1..``degree`` (x first), and 1 if ``include_constant``.

    K = C(n + degree, degree) - 1 (+1) features; the size is estimated first and refused above ``orrc.config``'s limits.

    Parameters
    ----------
    n : the state dimension.
    degree : the largest total degree, >= 1.
    include_constant : add the feature 1.

    Returns
    -------
    Dictionary
        K = C(n + degree, degree) - 1 (+1) features.

    Raises
    ------
    orrc.OrrcValueError
        When n or degree is out of range, or K exceeds the size limits.

    Examples
    --------
    >>> from orrc import estimation
    >>> d = estimation.polynomial_dictionary(2, 2)
    >>> d.K, d.labels
    (5, ['x1', 'x2', 'x1^2', 'x1 x2', 'x2^2'])
    """
    n = as_int("n", n, minimum=1)
    degree = as_int("degree", degree, minimum=1)
    include_constant = as_bool("include_constant", include_constant)
    K = math.comb(n + degree, degree) - 1 + include_constant
    _check_features(K, f"polynomial_dictionary(n={n}, degree={degree})", terms=degree)
    combos = [c for d in range(1, degree + 1) for c in itertools.combinations_with_replacement(range(n), d)]

    def label(c):
        parts = []
        for i in sorted(set(c)):
            k = c.count(i)
            parts.append(f"x{i + 1}" + (f"^{k}" if k > 1 else ""))
        return " ".join(parts)

    def psi(x):
        feats = [ca.SX(1.0)] if include_constant else []
        for c in combos:
            term = ca.SX(1.0)
            for i in c:
                term = term * x[i]
            feats.append(term)
        return ca.vertcat(*feats)

    labels = (["1"] if include_constant else []) + [label(c) for c in combos]
    return Dictionary(psi, n, name=f"polynomials of degree <= {degree}", labels=labels)


def rbf_dictionary(centers, width: float, include_constant: bool = False) -> Dictionary:
    """x, then Gaussian radial basis functions exp(-‖x - c_j‖² / (2 width²)) for each centre c_j.

    ``centers`` (k, n); ``width`` > 0. K = n + k (+1) features; the size is estimated first and refused above ``orrc.config``'s limits.

    Parameters
    ----------
    centers : (k, n) the centres c_j.
    width : the width, > 0.
    include_constant : add the feature 1.

    Returns
    -------
    Dictionary
        K = n + k (+1) features.

    Raises
    ------
    orrc.OrrcValueError
        When the centres are malformed, the width not positive, or K exceeds the size limits.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import estimation
    >>> estimation.rbf_dictionary(np.zeros((3, 2)), width=1.0).K
    5
    """
    centers = as_array("centers", centers)
    if centers.ndim != 2 or centers.shape[0] < 1:
        raise OrrcValueError(f"centers must have shape (k, n) with k >= 1; got shape {centers.shape}")
    width = as_float("width", width, minimum=0.0, strict_min=True)
    k, n = centers.shape
    include_constant = as_bool("include_constant", include_constant)
    _check_features(n + k + include_constant, f"rbf_dictionary with {k} centres", terms=3 * n)

    def psi(x):
        feats = [x]
        if include_constant:
            feats.append(ca.SX(1.0))
        for c in centers:
            d = x - ca.DM(c)
            feats.append(ca.exp(-ca.dot(d, d) / (2.0 * width ** 2)))
        return ca.vertcat(*feats)

    labels = [f"x{i + 1}" for i in range(n)] + (["1"] if include_constant else []) + [f"rbf{j}" for j in range(k)]
    return Dictionary(psi, n, name=f"{k} Gaussian RBFs (width {width:g})", labels=labels)
