"""Stage costs c_t(x, u) and their lower bound c_t(x, u) >= α_lo σ(x) (Assumption 2).

A stage cost is a *family* ``c(x, u; p)`` with a parameter vector ``p`` (possibly
empty). A time-varying, adversarial cost sequence c_1, c_2, ... is one family plus
a row of parameters per time step (:class:`CostSequence`): this is what lets the
CasADi solvers be built once and re-used at every step, and what the simulator
hands to a controller as its cost preview c_{t:t+M_c-1}.

* :class:`QuadraticCost` -- c(x, u) = xᵀQx + uᵀRu, σ(x) = ‖x‖², α_lo = λ_min(Q);
  its parameters are (vec Q, vec R), so :meth:`QuadraticCost.sequence` builds
  time-varying Q_t, R_t.
* :class:`Cost` -- any cost written with CasADi operations (non-convex allowed,
  as in the paper), with a user σ and α_lo.
"""
from __future__ import annotations

from typing import Callable

import casadi as ca
import numpy as np

from ._validate import OrrcValueError, as_array, as_float, as_int, as_square, check_psd, eigvalsh_tol


def _norm_sq(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(x @ x)


class StageCost:
    """A cost family c(x, u; p). Subclasses set n, m, n_params, default_params, alpha_lo."""

    n: int | None
    m: int | None
    n_params: int
    default_params: np.ndarray
    alpha_lo: float | None
    name: str

    def expr(self, x, u, p):  # pragma: no cover - abstract
        """CasADi expression of c(x, u; p)."""
        raise NotImplementedError

    def value(self, x, u, p=None) -> float:  # pragma: no cover - abstract
        """Numeric c(x, u; p) (p=None: the default parameters)."""
        raise NotImplementedError

    def __call__(self, x, u, p=None) -> float:
        return self.value(x, u, p)

    def sigma(self, x) -> float:
        """σ(x) of Assumption 2 (default ‖x‖²)."""
        return _norm_sq(x)

    def check_dims(self, n: int, m: int) -> None:
        if (self.n is not None and self.n != n) or (self.m is not None and self.m != m):
            raise OrrcValueError(
                f"the cost is for n={self.n} states and m={self.m} inputs; the system has n={n}, m={m}")

    def check_params(self, params) -> np.ndarray:
        """Validate a (L, n_params) array of per-step parameters."""
        params = as_array("cost params", params)
        if params.ndim == 1 and self.n_params > 0 and params.shape[0] == self.n_params:
            params = params[None, :]
        if params.ndim != 2 or params.shape[1] != self.n_params:
            raise OrrcValueError(
                f"cost params must have shape (L, {self.n_params}) for {self.name}; got shape {params.shape}")
        return params


class QuadraticCost(StageCost):
    """c(x, u) = xᵀQx + uᵀRu (σ(x) = ‖x‖², α_lo = λ_min(Q) unless given).

    Q must be symmetric positive semidefinite, R symmetric positive definite.
    Parameters p = (vec Q, vec R), so a time-varying sequence is
    :meth:`QuadraticCost.sequence` (Q_t, R_t).
    """

    def __init__(self, Q, R, alpha_lo: float | None = None, name: str = "quadratic cost"):
        Q = as_square("Q", Q)
        R = as_square("R", R)
        check_psd("Q", Q)
        check_psd("R", R, strict=True)
        self.Q, self.R = Q, R
        self.n, self.m = Q.shape[0], R.shape[0]
        self.n_params = self.n * self.n + self.m * self.m
        self.default_params = np.concatenate([Q.ravel(), R.ravel()])
        lam = float(np.linalg.eigvalsh(Q).min())
        self.alpha_lo = lam if alpha_lo is None else as_float("alpha_lo", alpha_lo, minimum=0.0)
        # λ_min(Q) is known to within its rounding error n·eps·‖Q‖₂ (eigvalsh_tol): a declared
        # alpha_lo above it by more than that is not a lower bound, at any scale of Q
        if self.alpha_lo > lam + eigvalsh_tol(Q):
            raise OrrcValueError(
                f"alpha_lo={self.alpha_lo} is not a valid lower bound: c(x,u) >= alpha_lo*|x|^2 "
                f"needs alpha_lo <= lambda_min(Q) = {lam:.6g}")
        self.name = name

    def unpack(self, p) -> tuple[np.ndarray, np.ndarray]:
        """(Q, R) from a parameter vector."""
        p = np.asarray(p, dtype=float)
        nn = self.n * self.n
        return p[:nn].reshape(self.n, self.n), p[nn:].reshape(self.m, self.m)

    def expr(self, x, u, p):
        nn = self.n * self.n
        Q = ca.reshape(p[:nn], self.n, self.n)
        R = ca.reshape(p[nn:], self.m, self.m)
        return ca.bilin(Q, x, x) + ca.bilin(R, u, u)

    def value(self, x, u, p=None) -> float:
        if p is None:
            Q, R = self.Q, self.R
        else:
            Q, R = self.unpack(p)
        return float(x @ Q @ x + u @ R @ u)

    def sequence(self, Qs, Rs=None) -> "CostSequence":
        """Time-varying costs c_t(x, u) = xᵀQ_t x + uᵀR_t u (Qs: (L, n, n), Rs: (L, m, m)).

        ``Rs=None`` keeps R fixed. Each Q_t is checked PSD, each R_t PD.
        """
        Qs = as_array("Qs", Qs)
        if Qs.ndim != 3 or Qs.shape[1:] != (self.n, self.n):
            raise OrrcValueError(f"Qs must have shape (L, {self.n}, {self.n}); got shape {Qs.shape}")
        Rs = np.broadcast_to(self.R, (len(Qs), self.m, self.m)) if Rs is None else as_array("Rs", Rs)
        if Rs.shape != (len(Qs), self.m, self.m):
            raise OrrcValueError(f"Rs must have shape ({len(Qs)}, {self.m}, {self.m}); got shape {Rs.shape}")
        for t in range(len(Qs)):
            check_psd(f"Qs[{t}]", Qs[t])
            check_psd(f"Rs[{t}]", Rs[t], strict=True)
        params = np.concatenate([Qs.reshape(len(Qs), -1), Rs.reshape(len(Rs), -1)], axis=1)
        alpha_lo = min(float(np.linalg.eigvalsh(Q).min()) for Q in Qs)
        return CostSequence(self, params, alpha_lo=alpha_lo)

    def scaled(self, scales) -> "CostSequence":
        """Time-varying costs c_t = s_t (xᵀQx) + uᵀRu, a simple adversarial family (s_t > 0)."""
        scales = as_array("scales", scales, ndim=1)
        if np.any(scales <= 0):
            raise OrrcValueError(f"scales must be positive; got minimum {scales.min():.3g}")
        return self.sequence(scales[:, None, None] * self.Q[None])

    def __repr__(self):
        return f"QuadraticCost(n={self.n}, m={self.m}, alpha_lo={self.alpha_lo:.4g})"


class Cost(StageCost):
    """A general stage cost written with CasADi operations.

    Parameters
    ----------
    fun : callable
        ``fun(x, u)`` (or ``fun(x, u, p)`` when ``n_params > 0``) returning a scalar
        CasADi expression. Non-convex costs are allowed, as in the paper.
    n, m : state and input dimensions.
    n_params : length of the per-step parameter vector p (0 for a fixed cost).
    default_params : p used when the cost is time-invariant.
    sigma : numeric σ(x) >= 0 of Assumption 2 (default ‖x‖²).
    alpha_lo : a constant with c(x, u; p) >= alpha_lo σ(x) for all x, u, p, if known.
    """

    def __init__(self, fun: Callable, n: int, m: int, n_params: int = 0, default_params=None,
                 sigma: Callable | None = None, alpha_lo: float | None = None, name: str = "cost"):
        if not callable(fun):
            raise OrrcValueError(f"fun must be callable; got {type(fun).__name__}")
        self.n = as_int("n", n, minimum=1)
        self.m = as_int("m", m, minimum=1)
        self.n_params = as_int("n_params", n_params, minimum=0)
        if default_params is None:
            default_params = np.zeros(self.n_params)
        self.default_params = as_array("default_params", default_params, (self.n_params,))
        self.alpha_lo = None if alpha_lo is None else as_float("alpha_lo", alpha_lo, minimum=0.0)
        self._sigma = sigma
        self.name = name
        self._fun = fun
        x, u, p = ca.SX.sym("x", self.n), ca.SX.sym("u", self.m), ca.SX.sym("p", self.n_params)
        try:
            out = ca.SX(self.expr(x, u, p))
        except Exception as exc:
            raise OrrcValueError(
                f"the cost function must be written with CasADi operations; tracing it failed with: {exc}"
            ) from exc
        if out.shape != (1, 1):
            raise OrrcValueError(f"the cost function must return a scalar; got shape {out.shape}")
        self.function = ca.Function("c", [x, u, p], [out])

    def expr(self, x, u, p):
        return self._fun(x, u, p) if self.n_params else self._fun(x, u)

    def value(self, x, u, p=None) -> float:
        p = self.default_params if p is None else p
        return float(self.function(x, u, p))

    def sigma(self, x) -> float:
        return _norm_sq(x) if self._sigma is None else float(self._sigma(np.asarray(x, dtype=float)))


class CostSequence:
    """A time-varying cost sequence c_0, c_1, ...: one family, one parameter row per step.

    ``params[t]`` are the parameters of c_t. Past the last row, the last cost is
    repeated (a controller whose preview runs past the end sees the final cost).
    """

    def __init__(self, stage: StageCost, params, alpha_lo: float | None = None):
        if not isinstance(stage, StageCost):
            raise OrrcValueError(f"stage must be a StageCost; got {type(stage).__name__}")
        self.stage = stage
        self.params = stage.check_params(params)
        if len(self.params) == 0:
            raise OrrcValueError("a cost sequence needs at least one step; got 0 rows of params")
        self.alpha_lo = stage.alpha_lo if alpha_lo is None else alpha_lo

    def __len__(self):
        return len(self.params)

    def window(self, t: int, length: int) -> np.ndarray:
        """Parameters of c_t, ..., c_{t+length-1} (the last row repeated past the end)."""
        idx = np.minimum(np.arange(t, t + length), len(self.params) - 1)
        return self.params[idx]

    def value(self, t: int, x, u) -> float:
        return self.stage.value(x, u, self.params[min(t, len(self.params) - 1)])

    def sigma(self, x) -> float:
        return self.stage.sigma(x)
