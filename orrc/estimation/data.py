"""The data set D of Algorithm 2 and what every estimator reports.

Algorithm 2 collects D = {(x_{k+1}, x_k, u_k, w_k)} during its estimation phase. The estimators
take it as arrays with time along axis 0: ``X`` (N+1, n) the states x_0..x_N, ``U`` (N, m) the
inputs u_0..u_{N-1} and ``W`` (N, n) the disturbances w_0..w_{N-1} (or None when the estimator is
not given them and treats w as noise). Several experiments may be passed as lists of such arrays
(one trajectory each); their transitions are pooled.

* :func:`transitions` -- the validated, pooled transitions (x_k, u_k, w_k, x_{k+1});
* :class:`Estimate` -- the result every estimator returns: θ̂, the data rank, the residual and,
  when the true θ is given, the error ‖θ̂ - θ‖ (so that g(N) can be measured);
* :func:`full_rank_solve` -- least squares with the rank check that says when the data are not
  persistently exciting.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .._validate import OrrcValueError, as_array

__all__ = ["Transitions", "transitions", "Estimate", "RankWarning"]


class RankWarning(UserWarning):
    """The data do not determine θ (rank deficient); a minimum-norm estimate was returned.

    Examples
    --------
    Data that do not excite the system (zero inputs from the origin, no disturbance):

    >>> import warnings
    >>> import numpy as np
    >>> from orrc import estimation
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     # no excitation at all
    ...     X, U, W = np.zeros((6, 2)), np.zeros((5, 1)), np.zeros((5, 2))
    ...     est = estimation.least_squares_linear(X, U, W, rank_deficient='warn')
    >>> [w.category.__name__ for w in caught], est.rank, est.rank_needed
    (['RankWarning'], 0, 3)
    """


class Transitions(NamedTuple):
    """Pooled transitions of Algorithm 2's data D = {(x_{k+1}, x_k, u_k, w_k)}.

    Attributes
    ----------
    x : (N, n) the states x_k.
    u : (N, m) the inputs u_k.
    w : (N, n) the disturbances w_k, or None.
    x_next : (N, n) the next states x_{k+1}.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc import estimation
    >>> di = orrc.examples.double_integrator()
    >>> U = estimation.prbs(40, 1, seed=0)                       # 40 exciting inputs
    >>> W = orrc.disturbances.uniform_ball(40, 2, 0.01, seed=1)
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> D = estimation.transitions(X, U, W)
    >>> D.x.shape, D.u.shape, D.w.shape, D.x_next.shape
    ((40, 2), (40, 1), (40, 2), (40, 2))
    """

    x: np.ndarray
    u: np.ndarray
    w: np.ndarray | None
    x_next: np.ndarray

    @property
    def N(self) -> int:
        return len(self.x)


def _as_list(name, value):
    return list(value) if isinstance(value, (list, tuple)) else [value]


def transitions(X, U, W=None, n: int | None = None, m: int | None = None) -> Transitions:
    """Validate the data of Algorithm 2 and pool them into transitions.

    ``X`` (N+1, n), ``U`` (N, m) (a 1-D U is m = 1), ``W`` (N, n) or None; or lists of such
    arrays, one per experiment (then W is a list too, or None). ``n``, ``m``: the dimensions the
    model expects (checked when given). Raises :class:`~orrc.OrrcValueError` naming the argument
    on wrong shapes, mismatched lengths or non-finite data.

    Parameters
    ----------
    X : (N+1, n) the states, or a list of such arrays (one per experiment).
    U : (N, m) the inputs (or a list).
    W : (N, n) the disturbances (or a list), or None.
    n, m : the dimensions the model expects, checked when given.

    Returns
    -------
    Transitions
        ``x`` (N, n), ``u`` (N, m), ``w`` (N, n) or None, ``x_next`` (N, n), pooled over experiments.

    Raises
    ------
    orrc.OrrcValueError
        On wrong shapes, mismatched lengths or non-finite data.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc import estimation
    >>> di = orrc.examples.double_integrator()
    >>> U = estimation.prbs(40, 1, seed=0)                       # 40 exciting inputs
    >>> W = orrc.disturbances.uniform_ball(40, 2, 0.01, seed=1)
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> estimation.transitions(X, U, W).x_next.shape
    (40, 2)
    """
    Xs, Us = _as_list("X", X), _as_list("U", U)
    Ws = [None] * len(Xs) if W is None else _as_list("W", W)
    if not (len(Xs) == len(Us) == len(Ws)):
        raise OrrcValueError(f"X, U and W must list the same number of experiments; got {len(Xs)}, {len(Us)}, "
                             f"{len(Ws)}")
    if any((w is None) != (Ws[0] is None) for w in Ws):
        raise OrrcValueError("W must be given for every experiment or for none")
    parts = []
    for i, (x, u, w) in enumerate(zip(Xs, Us, Ws)):
        tag = "" if len(Xs) == 1 else f"[{i}]"
        x = as_array(f"X{tag}", x)
        if x.ndim == 1:
            x = x[:, None]
        if x.ndim != 2 or x.shape[0] < 2:
            raise OrrcValueError(f"X{tag} must have shape (N+1, n) with N >= 1 (states x_0..x_N); got shape {x.shape}")
        N, nx = x.shape[0] - 1, x.shape[1]
        if n is not None and nx != n:
            raise OrrcValueError(f"X{tag} must have n = {n} columns (the model's states); got shape {x.shape}")
        u = as_array(f"U{tag}", u)
        if u.ndim == 1:
            u = u[:, None]
        if u.ndim != 2 or u.shape[0] != N or (m is not None and u.shape[1] != m):
            want = f"({N}, {m if m is not None else 'm'})"
            raise OrrcValueError(f"U{tag} must have shape {want} (inputs u_0..u_(N-1) for the {N + 1} states of "
                                 f"X{tag}); got shape {u.shape}")
        if w is not None:
            w = as_array(f"W{tag}", w)
            if w.ndim == 1 and nx == 1:
                w = w[:, None]
            if w.shape != (N, nx):
                raise OrrcValueError(f"W{tag} must have shape ({N}, {nx}) (disturbances w_0..w_(N-1)); got shape "
                                     f"{w.shape}")
        parts.append((x[:-1], u, w, x[1:]))
    nx, mu = parts[0][0].shape[1], parts[0][1].shape[1]
    for i, (x, u, _, _) in enumerate(parts):
        if x.shape[1] != nx or u.shape[1] != mu:
            raise OrrcValueError(f"experiment {i} has n={x.shape[1]}, m={u.shape[1]}; experiment 0 has n={nx}, m={mu}")
    return Transitions(np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]),
                       None if W is None else np.concatenate([p[2] for p in parts]),
                       np.concatenate([p[3] for p in parts]))


@dataclass
class Estimate:
    """What an estimator returns (Algorithm 2: θ̂ = estimation(D)).

    Attributes
    ----------
    theta : θ̂ (p,), the estimated parameters.
    N : number of transitions used.
    rank, rank_needed : rank of the regression matrix and the rank that determines θ (p, or n + m
        for a linear system): rank < rank_needed means the data were not persistently exciting.
    residual : RMS one-step residual sqrt(Σ‖x_{k+1} - x̂_{k+1}‖² / N).
    condition : condition number of the regression matrix (inf when rank deficient).
    used_w : whether the estimator was given the disturbances (if not, w was treated as noise).
    error : ‖θ̂ - θ‖₂ when the true θ was given, else None (g(N) of the paper).
    method : a short description.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc import estimation
    >>> di = orrc.examples.double_integrator()
    >>> U = estimation.prbs(40, 1, seed=0)                       # 40 exciting inputs
    >>> W = orrc.disturbances.uniform_ball(40, 2, 0.01, seed=1)
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> est = estimation.least_squares_linear(X, U, W, true=di.system)
    >>> est.N, est.rank, est.rank_needed, bool(est.error < 1e-10)
    (40, 3, 3, True)
    """

    theta: np.ndarray
    N: int
    rank: int
    rank_needed: int
    residual: float
    condition: float
    used_w: bool
    error: float | None = None
    method: str = ""
    info: dict = field(default_factory=dict, repr=False)

    @property
    def exciting(self) -> bool:
        """True when the data determine θ (rank == rank_needed: persistently exciting)."""
        return self.rank == self.rank_needed


def full_rank_solve(Phi: np.ndarray, Y: np.ndarray, what: str, needed_rows: str,
                    rank_deficient: str = "raise") -> tuple[np.ndarray, int, float]:
    """Least squares Θ = argmin ‖Phi Θ - Y‖_F with the rank check of persistent excitation.

    The numerical rank counts singular values above max(rows, cols)·eps·σ_max (numpy's
    ``matrix_rank`` rule). When it is below the number of unknowns: ``rank_deficient="raise"``
    (default) raises :class:`~orrc.OrrcValueError` naming the rank found and the rank needed;
    ``"warn"`` issues a :class:`RankWarning` and returns the minimum-norm solution (useful when
    only some directions matter). Returns (Θ, rank, condition number).
    """
    if rank_deficient not in ("raise", "warn"):
        raise OrrcValueError(f"rank_deficient must be 'raise' or 'warn'; got {rank_deficient!r}")
    need = Phi.shape[1]
    s = np.linalg.svd(Phi, compute_uv=False)
    tol = s[0] * max(Phi.shape) * np.finfo(float).eps if s.size else 0.0
    rank = int(np.count_nonzero(s > tol))
    cond = float(s[0] / s[-1]) if rank == need and s[-1] > 0 else float("inf")
    if rank < need:
        msg = (f"{what}: the data are not persistently exciting: the regression matrix {needed_rows} has rank "
               f"{rank}, and the rank needed is {need}")
        if rank_deficient == "raise":
            raise OrrcValueError(msg + "; excite longer or with a richer input, or pass rank_deficient='warn' for "
                                       "the minimum-norm estimate")
        warnings.warn(msg + "; returning the minimum-norm estimate", RankWarning, stacklevel=3)
    theta, *_ = np.linalg.lstsq(Phi, Y, rcond=None)
    return theta, rank, cond
