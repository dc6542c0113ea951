"""Stage costs c_t(x, u) and their lower bound c_t(x, u) >= α_lo σ(x) (Assumption 2).

A stage cost is a *family* ``c(x, u; p)`` with a parameter vector ``p`` (possibly
empty). A time-varying, adversarial cost sequence c_1, c_2, ... is one family plus
a row of parameters per time step (:class:`CostSequence`): this is what lets the
CasADi solvers be built once and re-used at every step, and what the simulator
hands to a controller as its cost preview c_{t:t+M_c-1}.

* :class:`QuadraticCost` -- c(x, u) = xᵀQx + uᵀRu, σ(x) = ‖x‖², α_lo = λ_min(Q);
  its parameters are (vec Q, vec R), so :meth:`QuadraticCost.sequence` builds
  time-varying Q_t, R_t.
* :class:`L1Cost` -- c(x, u) = Σ q_i |x_i| + uᵀRu, σ(x) = ‖x‖₁: Lipschitz in x (the unknown-system
  chapters use it: a wrong model then costs in proportion to its error, not to its square);
* :class:`Cost` -- any cost written with CasADi operations (non-convex allowed,
  as in the paper), with a user σ and α_lo.
"""
from __future__ import annotations

from typing import Callable

import casadi as ca
import numpy as np

from ._casadi import DropsBuffers, buffered
from ._stage_cost import StageCost, _alpha_lo, _name, _norm_sq, psd_factor
from ._validate import (OrrcValueError, _describe, as_array, as_float, as_int, as_square, check_evaluates,
                        check_psd, eigvalsh_tol, probe_points)

__all__ = ["psd_factor", "StageCost", "QuadraticCost", "Cost", "CostSequence", "L1Cost"]


class QuadraticCost(StageCost):
    """c(x, u) = xᵀQx + uᵀRu (σ(x) = ‖x‖², α_lo = λ_min(Q) unless given).

    Q must be symmetric positive semidefinite, R symmetric positive definite.
    Parameters p = (vec Q, vec R), so a time-varying sequence is
    :meth:`QuadraticCost.sequence` (Q_t, R_t).

    Parameters
    ----------
    Q : (n, n) symmetric positive semidefinite state weight (a scalar for n = 1).
    R : (m, m) symmetric positive definite input weight (a scalar for m = 1).
    alpha_lo : a constant with c(x, u) >= alpha_lo ‖x‖² (default λ_min(Q)).
    name : a label for plots.

    Raises
    ------
    orrc.OrrcValueError
        When Q is not PSD, R not PD, or their shapes do not match.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> cost = orrc.QuadraticCost(np.diag([1.0, 0.1]), 0.1)
    >>> cost.value(np.array([1.0, 2.0]), np.array([1.0])), cost.alpha_lo
    (1.5, 0.1)
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
        self.alpha_lo = _alpha_lo(alpha_lo, float(np.linalg.eigvalsh(Q).min()), "lambda_min(Q)", eigvalsh_tol(Q))
        self.name = _name(name)

    def _rows(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(Q_t, R_t) stacks (L, n, n), (L, m, m) from checked parameter rows (L, n_params)."""
        nn = self.n * self.n
        return P[:, :nn].reshape(-1, self.n, self.n), P[:, nn:].reshape(-1, self.m, self.m)

    def check_params(self, params, name: str = "cost_params") -> np.ndarray:
        """Validate (L, n_params) rows (vec Q_t, vec R_t): each Q_t symmetric PSD, each R_t symmetric PD."""
        P = super().check_params(params, name)
        Qs, Rs = self._rows(P)
        check_psd(f"{name}: every Q_t", Qs)
        check_psd(f"{name}: every R_t", Rs, strict=True)
        return P

    def unpack(self, p) -> tuple[np.ndarray, np.ndarray]:
        """(Q, R) from a parameter vector (vec Q, vec R) of length n_params."""
        p = as_array("p", p, (self.n_params,))
        nn = self.n * self.n
        return p[:nn].reshape(self.n, self.n), p[nn:].reshape(self.m, self.m)

    def expr(self, x, u, p):
        nn = self.n * self.n
        Q = ca.reshape(p[:nn], self.n, self.n)
        R = ca.reshape(p[nn:], self.m, self.m)
        return ca.bilin(Q, x, x) + ca.bilin(R, u, u)

    def _value(self, x, u, p) -> float:
        if p is None:
            Q, R = self.Q, self.R
        else:
            nn = self.n * self.n
            Q, R = p[:nn].reshape(self.n, self.n), p[nn:].reshape(self.m, self.m)
        return float(x @ Q @ x + u @ R @ u)

    def sequence(self, Qs, Rs=None) -> "CostSequence":
        """Time-varying costs c_t(x, u) = xᵀQ_t x + uᵀR_t u (Qs: (L, n, n), Rs: (L, m, m)).

        ``Rs=None`` keeps R fixed. Each Q_t is checked PSD, each R_t PD (by :class:`CostSequence`),
        and α_lo of the sequence is min_t λ_min(Q_t).
        """
        Qs = as_array("Qs", Qs)
        if Qs.ndim != 3 or Qs.shape[1:] != (self.n, self.n) or len(Qs) == 0:
            raise OrrcValueError(f"Qs must have shape (L, {self.n}, {self.n}) with L >= 1; got shape {Qs.shape}")
        Rs = np.broadcast_to(self.R, (len(Qs), self.m, self.m)) if Rs is None else as_array("Rs", Rs)
        if Rs.shape != (len(Qs), self.m, self.m):
            raise OrrcValueError(f"Rs must have shape ({len(Qs)}, {self.m}, {self.m}); got shape {Rs.shape}")
        check_psd("Qs: every Q_t", Qs)
        check_psd("Rs: every R_t", Rs, strict=True)
        params = np.concatenate([Qs.reshape(len(Qs), -1), Rs.reshape(len(Rs), -1)], axis=1)
        return CostSequence(self, params)

    def scaled(self, scales) -> "CostSequence":
        """Time-varying costs c_t = s_t (xᵀQx) + uᵀRu, a simple adversarial family (s_t > 0)."""
        scales = as_array("scales", scales, ndim=1, allow_empty=False)
        if np.any(scales <= 0):
            raise OrrcValueError(f"scales must be positive; got minimum {scales.min():.3g}")
        return self.sequence(scales[:, None, None] * self.Q[None])

    def __repr__(self):
        return f"QuadraticCost(n={self.n}, m={self.m}, alpha_lo={self.alpha_lo:.4g})"


class Cost(DropsBuffers, StageCost):
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

    Raises
    ------
    orrc.OrrcValueError
        When ``fun`` does not return a finite scalar at construction (e.g. ``math.sin`` applied to a
        CasADi symbol).

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> import orrc
    >>> cost = orrc.Cost(lambda x, u: x[0] ** 2 + 1 - ca.cos(x[1]) + u[0] ** 2, n=2, m=1)
    >>> print(cost.value(np.array([1.0, 0.0]), np.array([2.0])))
    5.0
    """

    def __init__(self, fun: Callable, n: int, m: int, n_params: int = 0, default_params=None,
                 sigma: Callable | None = None, alpha_lo: float | None = None, name: str = "cost"):
        if not callable(fun):
            raise OrrcValueError(f"fun must be callable; got {type(fun).__name__}")
        if sigma is not None and not callable(sigma):
            raise OrrcValueError(f"sigma must be None or a callable sigma(x) >= 0; got {type(sigma).__name__}")
        self.n = as_int("n", n, minimum=1)
        self.m = as_int("m", m, minimum=1)
        self.n_params = as_int("n_params", n_params, minimum=0)
        if default_params is None:
            default_params = np.zeros(self.n_params)
        self.default_params = as_array("default_params", default_params, (self.n_params,))
        self.alpha_lo = None if alpha_lo is None else as_float("alpha_lo", alpha_lo, minimum=0.0)
        self._sigma = sigma
        self.name = _name(name)
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
        check_evaluates("fun", "the cost c(x, u; default_params)",
                        lambda x, u: self.function(x, u, self.default_params), self.n, self.m)
        for x0, _ in probe_points(self.n, self.m):
            self.sigma(x0)  # σ must be a finite number >= 0 (raises otherwise)

    def expr(self, x, u, p):
        return self._fun(x, u, p) if self.n_params else self._fun(x, u)

    def _value(self, x, u, p) -> float:
        call = buffered(self, "c", lambda: self.function)  # numpy buffers: no CasADi matrices per call
        call(x, u, self.default_params if p is None else p)
        return float(call.res[0][0])

    def sigma(self, x) -> float:
        """σ(x) of Assumption 2: the user's function (default ‖x‖²); refused unless a finite number >= 0."""
        if self._sigma is None:
            return _norm_sq(x)
        x = as_array("x", x, (self.n,))
        out = self._sigma(x)
        try:
            s = float(np.asarray(out, dtype=float).reshape(()))
        except (TypeError, ValueError) as exc:
            raise OrrcValueError(f"sigma(x) must return one real number; at x={x} it gave {_describe(out)}") from exc
        if not (s >= 0.0 and np.isfinite(s)):
            raise OrrcValueError(f"sigma(x) must be a finite number >= 0 (Assumption 2); at x={x} it is {s}")
        return s


class CostSequence:
    """A time-varying cost sequence c_0, c_1, ...: one family, one parameter row per step.

    ``params[t]`` are the parameters of c_t. Past the last row, the last cost is
    repeated (a controller whose preview runs past the end sees the final cost).

    Parameters
    ----------
    stage : the cost family c(x, u; p) (a :class:`StageCost`).
    params : (T, n_params) one row of parameters per step.
    alpha_lo : a constant with c_t(x, u) >= alpha_lo σ(x) for every t (default: the family's bound
        over the rows, e.g. min_t λ_min(Q_t) for a quadratic family).

    Examples
    --------
    Q_t = 1 + t for three steps, built by :meth:`QuadraticCost.sequence`:

    >>> import numpy as np
    >>> import orrc
    >>> cost = orrc.QuadraticCost(1.0, 1.0)
    >>> seq = cost.sequence([np.eye(1) * (1 + t) for t in range(3)], [np.eye(1)] * 3)
    >>> isinstance(seq, orrc.CostSequence), seq.alpha_lo
    (True, 1.0)
    """

    def __init__(self, stage: StageCost, params, alpha_lo: float | None = None):
        if not isinstance(stage, StageCost):
            raise OrrcValueError(f"stage must be a StageCost; got {type(stage).__name__}")
        self.stage = stage
        self.params = stage.check_params(params, "params")  # every row checked (Q_t PSD, R_t PD)
        if len(self.params) == 0:
            raise OrrcValueError("a cost sequence needs at least one step; got 0 rows of params")
        self.params.flags.writeable = False
        # α_lo of the SEQUENCE: min_t λ_min(Q_t) for quadratic costs; a general family's declared
        # α_lo holds for every p (Cost's contract), so it holds for the sequence
        own, tol = stage.alpha_lo, 0.0
        if isinstance(stage, QuadraticCost):
            lam = np.linalg.eigvalsh(stage._rows(self.params)[0])       # (L, n)
            own, tol = float(lam[:, 0].min()), stage.n * float(np.finfo(float).eps) * float(np.abs(lam).max())
        self.alpha_lo = _alpha_lo(alpha_lo, own, "min_t lambda_min(Q_t)", tol) if own is not None else (
            None if alpha_lo is None else as_float("alpha_lo", alpha_lo, minimum=0.0))

    def __len__(self):
        return len(self.params)

    def window(self, t: int, length: int) -> np.ndarray:
        """Parameters of c_t, ..., c_{t+length-1} (the last row repeated past the end)."""
        t = as_int("t", t, minimum=0)
        length = as_int("length", length, minimum=0)
        idx = np.minimum(np.arange(t, t + length), len(self.params) - 1)
        return self.params[idx]

    def value(self, t: int, x, u) -> float:
        """c_t(x, u) (the last cost past the end of the sequence)."""
        t = as_int("t", t, minimum=0)
        return self.stage.value(x, u, self.params[min(t, len(self.params) - 1)])

    def sigma(self, x) -> float:
        return self.stage.sigma(x)


class L1Cost(StageCost):
    """c(x, u) = Σ_i q_i |x_i| + uᵀRu: a Lipschitz cost in x (Assumption 2 asks for Lipschitz costs),
    convex, strongly convex in u (Section 5.2, Assumption (vii)); σ(x) = ‖x‖₁, α_lo = min_i q_i.

    On a :class:`~orrc.LinearSystem`, :class:`~orrc.PreviewRHC` solves its M-step problem exactly as
    a quadratic program (``orrc.solvers.qp``); elsewhere the CasADi path uses |x| (``fabs``), which is
    not smooth at 0. Time invariant (no parameters).

    Parameters
    ----------
    q : (n,) positive weights of |x_i| (a scalar is used for every i).
    R : (m, m) symmetric positive definite input weight.
    name : a label for plots.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> cost = orrc.L1Cost([1.0, 0.5], 0.1)
    >>> print(cost.value(np.array([1.0, -2.0]), np.array([1.0])), cost.alpha_lo)
    2.1 0.5
    """

    def __init__(self, q, R, name: str = "l1 cost"):
        q = as_array("q", q)
        q = q.reshape(-1) if q.ndim <= 1 else q
        if q.ndim != 1 or q.size == 0 or np.any(q <= 0):
            raise OrrcValueError(f"q must be a vector of positive weights; got {q!r}")
        R = as_square("R", R)
        check_psd("R", R, strict=True)
        self.q, self.R = q, R
        self.n, self.m = q.size, R.shape[0]
        self.n_params = 0
        self.default_params = np.zeros(0)
        self.alpha_lo = float(q.min())
        self.name = name

    def expr(self, x, u, p=None):
        return ca.dot(ca.DM(self.q), ca.fabs(x)) + ca.bilin(ca.DM(self.R), u, u)

    def _value(self, x, u, p=None) -> float:
        return float(self.q @ np.abs(x) + u @ self.R @ u)

    def sigma(self, x) -> float:
        """σ(x) = ‖x‖₁ (x checked; a sum past the float range is inf, which ``orrc.simulate`` reports
        with a NonFiniteWarning, as it does an overflowed ‖x‖² of the other costs)."""
        with np.errstate(over="ignore"):
            return float(np.sum(np.abs(as_array("x", x, (self.n,)))))

    def __repr__(self):
        return f"L1Cost(n={self.n}, m={self.m}, alpha_lo={self.alpha_lo:.4g})"
