"""EDMD with inputs: a lifted linear model of a nonlinear system (the paper's Koopman approach).

A dictionary ψ(x) ∈ R^K of functions of the state (that contains x itself, so x = C ψ(x) for a
linear projection C) lifts the data; ridge-regularised least squares then fits

    z_{k+1} ≈ A z_k + B u_k + E w_k,      z_k = ψ(x_k),      x̂_k = C z_k,

the finite-dimensional approximation of the Koopman operator with inputs (Williams et al. 2015;
Korda and Mezić 2018). The result, :class:`EDMDModel`, is an ordinary :class:`~orrc.LinearSystem`
on the lifted state (``model.system``): :class:`~orrc.controllers.LiftedRHC` runs Algorithm 1 on it
(the exact LQ path for a quadratic cost without bounds), and :meth:`EDMDModel.predict` rolls it
forward from x_0 for given inputs.

* :class:`Dictionary` -- a user dictionary ψ(x) written in CasADi operations (checked to contain x);
* :func:`polynomial_dictionary`, :func:`rbf_dictionary` -- monomials up to a degree, Gaussian
  radial basis functions (both with x first);
* :func:`edmd` -- the fit; :class:`EDMD` -- the same as an estimator object for Algorithm 2;
* :func:`prediction_error` -- h-step prediction error of any model on fresh data (EDMD's g(N)).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .._validate import PY_CALL_OPS, NonFiniteWarning, OrrcValueError, as_array, as_float, as_int, check_size
from ..systems import LinearSystem, NonlinearSystem, System
from ._dictionary import Dictionary, polynomial_dictionary, rbf_dictionary
from .data import Estimate, full_rank_solve, transitions

__all__ = ["Dictionary", "polynomial_dictionary", "rbf_dictionary", "EDMD", "EDMDModel", "edmd", "prediction_error"]


@dataclass
class EDMDModel(Estimate):
    """The lifted linear model z+ = A z + B u + E w, z = ψ(x), x = C z, fitted by :func:`edmd`.

    ``theta`` is vec([A B E]) row by row; ``rank``/``rank_needed`` those of the regression matrix
    [ψ(x_k); u_k; w_k]; ``residual`` the RMS one-step residual of x (not of z).

    Attributes
    ----------
    A : (K, K) the lifted dynamics.
    B : (K, m) the input matrix.
    E : (K, n) the disturbance matrix (zero when fitted without W).
    C : (n, K) the projection x = C z.

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
    >>> model = estimation.edmd(X, U, estimation.polynomial_dictionary(2, 1), W=W)
    >>> model.A.shape, model.B.shape, model.E.shape, model.C.shape
    ((2, 2), (2, 1), (2, 2), (2, 2))
    """

    A: np.ndarray = None
    B: np.ndarray = None
    E: np.ndarray = None
    C: np.ndarray = None
    dictionary: Dictionary = None
    ridge: float = 0.0

    @property
    def K(self) -> int:
        return self.A.shape[0]

    @property
    def system(self) -> LinearSystem:
        """The lifted model as a :class:`~orrc.LinearSystem` on z (its disturbance input is E w)."""
        return LinearSystem(self.A, self.B, name=f"EDMD model ({self.dictionary.name})")

    def lift(self, x) -> np.ndarray:
        """z = ψ(x)."""
        return self.dictionary(x)

    def predict(self, x0, U, W=None) -> np.ndarray:
        """x̂_0..x̂_h (h+1, n) from x_0 under inputs U (h, m) and disturbances W (h, n) (None: w = 0)."""
        n, m = self.dictionary.n, self.B.shape[1]
        x0 = as_array("x0", x0, (n,))
        U = as_array("U", U)
        if U.ndim == 1 and m == 1:
            U = U[:, None]
        if U.ndim != 2 or U.shape[1] != m:
            raise OrrcValueError(f"U must have shape (h, {m}); got shape {U.shape}")
        if W is not None:
            W = as_array("W", W, (len(U), n))
        check_size(f"EDMDModel.predict over h={len(U)} steps (K={self.K} features)",
                   nbytes=3 * 8.0 * (len(U) + 1) * (self.K + n), ops=len(U) * (2.0 * self.K * (self.K + m + n) + 3 * PY_CALL_OPS), hint="shorten U")
        with np.errstate(over="ignore", invalid="ignore"):
            X = _lifted_rollout(self, self.lift(x0)[None, :], U[None], None if W is None else W[None])[0] @ self.C.T
        bad = ~np.all(np.isfinite(X), axis=1)
        if bad.any():
            warnings.warn(f"EDMDModel.predict: the prediction overflows the float range from step "
                          f"{int(np.argmax(bad))} of {len(U)} (the lifted model's spectral radius is "
                          f"{float(np.max(np.abs(np.linalg.eigvals(self.A)))):.4g}); shorten the horizon",
                          NonFiniteWarning, stacklevel=2)
        return X

    def __repr__(self):
        return (f"EDMDModel(K={self.K}, N={self.N}, ridge={self.ridge:g}, dictionary={self.dictionary.name!r}, "
                f"residual={self.residual:.3g})")


def _lifted_rollout(model: EDMDModel, Z0, U, W):
    """Batched z-rollouts: Z0 (S, K), U (S, h, m), W (S, h, n) or None → (S, h+1, K)."""
    S, h = U.shape[0], U.shape[1]
    out = np.empty((S, h + 1, Z0.shape[1]))
    out[:, 0] = Z0
    z = Z0
    for k in range(h):
        z = z @ model.A.T + U[:, k] @ model.B.T
        if W is not None:
            z = z + W[:, k] @ model.E.T
        out[:, k + 1] = z
    return out


def edmd(X, U, dictionary: Dictionary, W=None, ridge: float = 1e-8) -> EDMDModel:
    """EDMD with inputs: [A B E] = argmin (1/N) Σ_k ‖ψ(x_{k+1}) - A ψ(x_k) - B u_k - E w_k‖² + ridge ‖[A B E]‖_F².

    Parameters
    ----------
    X, U, W : the data (see :func:`orrc.estimation.transitions`; lists for several experiments).
        W None: the model has no disturbance channel (E = 0), w is treated as noise.
    dictionary : a :class:`Dictionary` (it contains x, so C with x = C ψ(x) is known).
    ridge : the ridge weight (>= 0), per sample. With ridge = 0 the data must determine [A B E]
        (rank check as in :func:`~orrc.estimation.least_squares_linear`).

    The ridge problem is solved as one least-squares problem on the stacked matrix
    [Φ; √(N ridge) I] (no normal equations, so its conditioning is that of Φ, not its square).

    Returns
    -------
    EDMDModel
        A (K, K), B (K, m), E (K, n), C (n, K), the lift ψ and the fit's diagnostics.

    Raises
    ------
    orrc.OrrcValueError
        When the data or the dictionary are malformed, or the regression exceeds the size limits.

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
    >>> model = estimation.edmd(X, U, estimation.polynomial_dictionary(2, 2), W=W)
    >>> model.A.shape
    (5, 5)
    """
    if not isinstance(dictionary, Dictionary):
        raise OrrcValueError(f"dictionary must be an orrc.estimation.Dictionary (e.g. polynomial_dictionary); "
                             f"got {type(dictionary).__name__}")
    ridge = as_float("ridge", ridge, minimum=0.0)
    D = transitions(X, U, W, n=dictionary.n)
    N, K, m, n = D.N, dictionary.K, D.u.shape[1], dictionary.n
    cols = K + m + (n if D.w is not None else 0)
    check_size(f"the EDMD regression with N = {N} transitions and K + m (+ n) = {cols} columns",
               nbytes=8.0 * (N + cols) * cols * 3, ops=6.0 * (N + cols) * cols * cols,
               hint="use fewer data or a smaller dictionary")
    Z0, Z1 = dictionary(D.x), dictionary(D.x_next)
    if not (np.all(np.isfinite(Z0)) and np.all(np.isfinite(Z1))):
        raise OrrcValueError("the dictionary is not finite on the data (overflow: scale the states or lower the degree)")
    Phi = np.hstack([Z0, D.u] + ([D.w] if D.w is not None else []))
    if ridge > 0:
        s = np.linalg.svd(Phi, compute_uv=False)
        rank = int(np.count_nonzero(s > s[0] * max(Phi.shape) * np.finfo(float).eps))
        aug = np.vstack([Phi, math.sqrt(N * ridge) * np.eye(cols)])
        Theta, *_ = np.linalg.lstsq(aug, np.vstack([Z1, np.zeros((cols, K))]), rcond=None)
        sa = np.linalg.svd(aug, compute_uv=False)
        cond = float(sa[0] / sa[-1])
    else:
        Theta, rank, cond = full_rank_solve(Phi, Z1, "edmd", "[psi(x_k); u_k; w_k]")
    A, B = Theta[:K].T, Theta[K:K + m].T
    E = Theta[K + m:].T if D.w is not None else np.zeros((K, n))
    C = dictionary.C
    x_res = float(np.sqrt(np.sum((D.x_next - (Phi @ Theta) @ C.T) ** 2) / N))
    return EDMDModel(theta=Theta.T.ravel(), N=N, rank=rank, rank_needed=cols, residual=x_res, condition=cond,
                     used_w=D.w is not None, method=f"EDMD with inputs, {dictionary.name}, ridge {ridge:g}",
                     A=A, B=B, E=E, C=C, dictionary=dictionary, ridge=ridge)


class EDMD:
    """EDMD as the estimator of Algorithm 2: ``EDMD(dictionary, ridge).fit(X, U, W)`` = :func:`edmd`.

    Parameters
    ----------
    dictionary : the :class:`Dictionary`.
    ridge : the ridge weight (>= 0).

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
    >>> model = estimation.EDMD(estimation.polynomial_dictionary(2, 1)).fit(X, U, W)
    >>> type(model).__name__
    'EDMDModel'
    """

    def __init__(self, dictionary: Dictionary, ridge: float = 1e-8):
        if not isinstance(dictionary, Dictionary):
            raise OrrcValueError(f"dictionary must be an orrc.estimation.Dictionary; got {type(dictionary).__name__}")
        self.dictionary = dictionary
        self.ridge = as_float("ridge", ridge, minimum=0.0)
        self.n = dictionary.n

    def fit(self, X, U, W=None) -> EDMDModel:
        return edmd(X, U, self.dictionary, W=W, ridge=self.ridge)

    def __repr__(self):
        return f"EDMD({self.dictionary!r}, ridge={self.ridge:g})"


def _rollouts(model, X0, U, W):
    """Batched rollouts of any model: (S, h+1, n) states from X0 (S, n), U (S, h, m), W (S, h, n) or None."""
    S, h = U.shape[:2]
    n = X0.shape[1]
    if isinstance(model, EDMDModel):
        return _lifted_rollout(model, model.lift(X0), U, W) @ model.C.T
    if isinstance(model, Estimate) and hasattr(model, "system"):
        model = model.system
    if not isinstance(model, System):
        raise OrrcValueError(f"model must be an EDMDModel, an estimate with .system, or an orrc System; got "
                             f"{type(model).__name__}")
    out = np.empty((S, h + 1, n))
    out[:, 0] = X0
    x = X0
    Wz = np.zeros((S, h, n)) if W is None else W
    F = model.function.map(S) if isinstance(model, NonlinearSystem) else None
    for k in range(h):
        if F is None:
            x = x @ model.A.T + U[:, k] @ model.B.T + Wz[:, k]
        else:
            x = np.asarray(F(x.T, U[:, k].T, Wz[:, k].T)).T
        out[:, k + 1] = x
    return out


def prediction_error(model, X, U, W=None, horizon: int = 20) -> float:
    """RMS over all start times k of ‖x̂_{k+h} - x_{k+h}‖: the h-step prediction error on data.

    ``model``: an :class:`EDMDModel`, an estimate with ``.system``, or any orrc System (e.g. the
    linearisation ``orrc.LinearSystem(*f.linearize())``). Each prediction starts from the true
    x_k and uses the recorded inputs u_k..u_{k+h-1} (and disturbances, when W is given; else
    w = 0). Data: one trajectory (N+1, n) with U (N, m), or lists of them. On fresh data (not
    used for fitting) this is the generalisation error, EDMD's counterpart of g(N).

    Parameters
    ----------
    model : the model to evaluate (see above).
    X, U, W : the data; W None: predictions with w = 0.
    horizon : the prediction length h >= 1.

    Returns
    -------
    float
        the RMS h-step prediction error.

    Raises
    ------
    orrc.OrrcValueError
        When the data are malformed or shorter than the horizon.

    Examples
    --------
    The true system predicts its own data exactly:

    >>> import numpy as np
    >>> import orrc
    >>> from orrc import estimation
    >>> di = orrc.examples.double_integrator()
    >>> U = estimation.prbs(40, 1, seed=0)                       # 40 exciting inputs
    >>> W = orrc.disturbances.uniform_ball(40, 2, 0.01, seed=1)
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> bool(estimation.prediction_error(di.system, X, U, W, horizon=5) < 1e-12)
    True
    """
    horizon = as_int("horizon", horizon, minimum=1)
    Xs = X if isinstance(X, (list, tuple)) else [X]
    Us = U if isinstance(U, (list, tuple)) else [U]
    Ws = [None] * len(Xs) if W is None else (W if isinstance(W, (list, tuple)) else [W])
    if not (len(Xs) == len(Us) == len(Ws)):
        raise OrrcValueError(f"X, U and W must list the same number of experiments; got {len(Xs)}, {len(Us)}, "
                             f"{len(Ws)}")
    sq, count = 0.0, 0
    for x, u, w in zip(Xs, Us, Ws):
        D = transitions(x, u, w)
        N = D.N
        if N < horizon:
            continue
        xs = np.vstack([D.x, D.x_next[-1:]])
        starts = np.arange(N - horizon + 1)
        idx = starts[:, None] + np.arange(horizon)[None, :]
        check_size(f"prediction_error's {len(starts)} rollouts of horizon={horizon} steps (n={D.x.shape[1]})",
                   nbytes=8.0 * len(starts) * (horizon + 1) * (2 * D.x.shape[1] + D.u.shape[1]),
                   ops=len(starts) * horizon * 20.0 * D.x.shape[1] + horizon * 3 * PY_CALL_OPS, hint="lower horizon")
        with np.errstate(over="ignore", invalid="ignore"):
            pred = _rollouts(model, xs[starts], D.u[idx], None if D.w is None else D.w[idx])
            err = pred[:, -1] - xs[starts + horizon]
            sq += float(np.sum(err * err))
        count += len(starts)
    if count == 0:
        raise OrrcValueError(f"no trajectory is long enough for a {horizon}-step prediction (each needs N >= horizon)")
    if not math.isfinite(sq):
        warnings.warn(f"prediction_error: the model's {horizon}-step predictions overflow the float range (the error "
                      "is inf or NaN); shorten the horizon", NonFiniteWarning, stacklevel=2)
    return math.sqrt(sq / count)
