"""Least squares for systems linear in the parameters (the paper's second case):

    x_{k+1} = x_k + f(x_k, u_k) + g(x_k, u_k) θ + w_k,

or more generally any :class:`~orrc.ParametricSystem` whose f is affine in θ,
f(x, u, w; θ) = f₀(x, u, w) + G(x, u, w) θ (checked symbolically; the regressors f₀ and
G = ∂f/∂θ come from CasADi). Stacking the N transitions gives one linear least-squares problem
in θ; with the disturbances given it is exact once the stacked G has rank p (persistent
excitation), so again g(N) = 0 after finitely many steps.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError
from ..parametric import ParametricSystem
from .data import Estimate, full_rank_solve, transitions

__all__ = ["least_squares_parametric"]


def least_squares_parametric(model: ParametricSystem, X, U, W=None, true=None,
                             rank_deficient: str = "raise") -> Estimate:
    """θ̂ = argmin Σ_k ‖x_{k+1} - f₀(x_k, u_k, w_k) - G(x_k, u_k, w_k) θ‖² for a model affine in θ.

    Parameters
    ----------
    model : an :class:`~orrc.ParametricSystem` with ``linear_in_theta`` (else raises).
    X, U, W : the data of Algorithm 2 (see :func:`orrc.estimation.transitions`); W None: the
        regressors are evaluated at w = 0 and w is treated as noise (for an additive w this is
        the least-squares estimate with w in the residual).
    true : optional true θ (p,): the estimate then reports ``error`` = ‖θ̂ - θ‖₂.
    rank_deficient : "raise" (default) or "warn", as in :func:`~orrc.estimation.least_squares_linear`.

    Returns
    -------
    Estimate
        θ̂ (p,), the rank and conditioning of the regression and, with ``true``, ``error``.

    Raises
    ------
    orrc.OrrcValueError
        When the model is not affine in θ, the data are malformed, or (with ``rank_deficient="raise"``)
        the data do not determine θ.

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
    >>> model = orrc.ParametricSystem.linear(2, 1)
    >>> est = estimation.least_squares_parametric(model, X, U, W)
    >>> bool(np.allclose(est.theta, model.pack(di.system.A, di.system.B)))
    True
    """
    if not isinstance(model, ParametricSystem):
        raise OrrcValueError(f"model must be an orrc.ParametricSystem; got {type(model).__name__}")
    if not model.linear_in_theta:
        raise OrrcValueError(
            f"model ({model.name}) is not affine in theta (∂f/∂θ depends on θ): least squares in θ does not "
            "apply; use orrc.estimation.edmd or a nonlinear least-squares method")
    D = transitions(X, U, W, n=model.n, m=model.m)
    N, n, p = D.N, model.n, model.n_params
    if N * n < p:
        raise OrrcValueError(f"N = {N} transitions give N·n = {N * n} equations for p = {p} parameters; at least "
                             f"N >= ceil(p/n) = {-(-p // n)} are needed (more when some rows of G vanish)")
    w = D.w if D.w is not None else np.zeros_like(D.x)
    f0, G = model.regressors(D.x, D.u, w)
    Phi = G.reshape(N * n, p)
    Y = (D.x_next - f0).reshape(N * n)
    theta, rank, cond = full_rank_solve(Phi, Y, "least_squares_parametric", "G (stacked over the transitions)",
                                        rank_deficient)
    residual = float(np.sqrt(np.sum((Y - Phi @ theta) ** 2) / N))
    error = None
    if true is not None:
        error = float(np.linalg.norm(theta - model.check_theta(true, "true")))
    method = ("least squares in θ with the disturbance record" if D.w is not None
              else "least squares in θ without the disturbances (w treated as noise)")
    return Estimate(theta=theta, N=N, rank=rank, rank_needed=p, residual=residual, condition=cond,
                    used_w=D.w is not None, error=error, method=method)
