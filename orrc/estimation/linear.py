"""Least squares for a linear system x_{k+1} = A x_k + B u_k + w_k (the paper's first case).

With the disturbances given (Algorithm 2's data set holds w_k: the controller observes the past
disturbances, ``Observation.w_past``), x_{k+1} - w_k = [A B] [x_k; u_k] holds exactly, so the
estimate is exact as soon as the data matrix [x_k; u_k]_{k<N} has rank n + m (persistent
excitation): N = n + m exciting steps suffice and g(N) = 0, as the paper's discussion says.
Without them, w is noise in the regression and the error decays like 1/√N (for i.i.d. w).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import OrrcValueError, as_array
from ..systems import LinearSystem
from .data import Estimate, full_rank_solve, transitions

__all__ = ["LinearEstimate", "least_squares_linear"]


@dataclass
class LinearEstimate(Estimate):
    """The estimate (Â, B̂) of :func:`least_squares_linear` (an :class:`~orrc.estimation.Estimate`).

    ``A`` (n, n), ``B`` (n, m); ``theta`` = vec([Â B̂]) row by row (as
    ``orrc.ParametricSystem.linear(n, m)`` orders it); ``error`` = ‖[Â - A, B̂ - B]‖_F when the
    true system was given.

    Attributes
    ----------
    A : (n, n) the estimate Â.
    B : (n, m) the estimate B̂.

    The other attributes are those of :class:`~orrc.estimation.Estimate`.

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
    >>> est.A.shape, est.B.shape, bool(np.allclose(est.B, di.system.B))
    ((2, 2), (2, 1), True)
    """

    A: np.ndarray = None
    B: np.ndarray = None

    @property
    def system(self) -> LinearSystem:
        """The estimated model x+ = Â x + B̂ u + w."""
        return LinearSystem(self.A, self.B, name="estimated linear system")


def true_linear_theta(true, n: int, m: int) -> np.ndarray:
    """vec([A B]) (row by row) of the true system, from a LinearSystem or an (A, B) pair."""
    if isinstance(true, LinearSystem):
        A, B = true.A, true.B
    elif isinstance(true, (tuple, list)) and len(true) == 2:
        A, B = as_array("true[0] (A)", true[0]), as_array("true[1] (B)", true[1])
        if B.ndim == 1:
            B = B[:, None]
    else:
        raise OrrcValueError(f"true must be an orrc LinearSystem or a pair (A, B); got {type(true).__name__}")
    if A.shape != (n, n) or B.shape != (n, m):
        raise OrrcValueError(f"true must have A of shape ({n}, {n}) and B of shape ({n}, {m}) like the data; got "
                             f"{A.shape} and {B.shape}")
    return np.hstack([A, B]).ravel()


def least_squares_linear(X, U, W=None, true=None, rank_deficient: str = "raise") -> LinearEstimate:
    """(Â, B̂) = argmin Σ_k ‖x_{k+1} - w_k - A x_k - B u_k‖² (Algorithm 2's estimation, linear case).

    Parameters
    ----------
    X : (N+1, n) states x_0..x_N (or a list of such arrays, one per experiment).
    U : (N, m) inputs u_0..u_{N-1}.
    W : (N, n) disturbances w_0..w_{N-1}, or None: the estimator is then not given w and treats
        it as noise (the regression target is x_{k+1}; the error decays like 1/√N for i.i.d. w).
    true : optional true system (a LinearSystem or (A, B)): the estimate then reports
        ``error`` = ‖[Â - A, B̂ - B]‖_F, the paper's ‖θ̂ - θ‖.
    rank_deficient : "raise" (default): data that are not persistently exciting (rank of
        [x_k; u_k] below n + m) raise :class:`~orrc.OrrcValueError` with the rank found and the rank
        needed; "warn": a :class:`~orrc.estimation.RankWarning` and the minimum-norm estimate.

    With W given and exciting data, the estimate is exact up to rounding: the error is of order
    eps·cond([x_k; u_k])·‖[A B]‖ (``condition`` is reported).

    Returns
    -------
    LinearEstimate
        Â (n, n), B̂ (n, m), θ̂ = vec([Â B̂]) (n(n + m),), the rank and conditioning of the regression
        and, with ``true``, ``error``.

    Raises
    ------
    orrc.OrrcValueError
        When the data are malformed, N < n + m, or (with ``rank_deficient="raise"``) the data do
        not determine [A B].

    Examples
    --------
    With the disturbances the estimate is exact; without them, w is noise:

    >>> import numpy as np
    >>> import orrc
    >>> from orrc import estimation
    >>> di = orrc.examples.double_integrator()
    >>> U = estimation.prbs(40, 1, seed=0)                       # 40 exciting inputs
    >>> W = orrc.disturbances.uniform_ball(40, 2, 0.01, seed=1)
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> bool(estimation.least_squares_linear(X, U, W, true=di.system).error < 1e-10)
    True
    >>> bool(estimation.least_squares_linear(X, U, None, true=di.system).error < 0.05)
    True
    """
    D = transitions(X, U, W)
    n, m, N = D.x.shape[1], D.u.shape[1], D.N
    if N < n + m:
        raise OrrcValueError(
            f"N = {N} transitions are too few for the linear estimator: [A B] has n + m = {n + m} columns, so at "
            f"least N >= n + m = {n + m} exciting steps are needed")
    Z = np.hstack([D.x, D.u])
    Y = D.x_next - (D.w if D.w is not None else 0.0)
    Theta, rank, cond = full_rank_solve(Z, Y, "least_squares_linear", "[x_k; u_k]", rank_deficient)
    AB = Theta.T
    residual = float(np.sqrt(np.sum((Y - Z @ Theta) ** 2) / N))
    theta = AB.ravel()
    error = None
    if true is not None:
        error = float(np.linalg.norm(theta - true_linear_theta(true, n, m)))
    method = ("least squares with the disturbance record (exact for exciting data)" if D.w is not None
              else "least squares without the disturbances (w treated as noise)")
    return LinearEstimate(theta=theta, N=N, rank=rank, rank_needed=n + m, residual=residual, condition=cond,
                          used_w=D.w is not None, error=error, method=method, A=AB[:, :n].copy(),
                          B=AB[:, n:].copy())
