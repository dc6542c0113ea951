"""The stage cost family c(x, u; p) and its lower bound c_t(x, u) >= α_lo σ(x) (Assumption 2).

:class:`StageCost` is the base of every cost of :mod:`orrc.costs`, which re-exports it and
documents it; the helpers here check a cost's name and its α_lo.
"""
from __future__ import annotations

import numpy as np

from ._validate import OrrcValueError, as_array, as_float, check_finite_result


def _norm_sq(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(x @ x)


def psd_factor(S: np.ndarray) -> np.ndarray:
    """A matrix F with FᵀF = S for a symmetric PSD S (a weight's square root: xᵀQx = ‖Fx‖²).

    Parameters
    ----------
    S : (n, n) symmetric positive semidefinite.

    Returns
    -------
    numpy.ndarray
        (n, n) F with FᵀF = S.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.costs import psd_factor
    >>> S = np.array([[4.0, 1.0], [1.0, 2.0]])
    >>> F = psd_factor(S)
    >>> bool(np.allclose(F.T @ F, S))
    True
    """
    lam, V = np.linalg.eigh(0.5 * (S + S.T))
    return np.sqrt(np.clip(lam, 0.0, None))[:, None] * V.T


def _name(name) -> str:
    if not isinstance(name, str):
        raise OrrcValueError(f"name must be a string; got {type(name).__name__}")
    return name


class StageCost:
    """A cost family c(x, u; p). Subclasses set n, m, n_params, default_params, alpha_lo.

    Examples
    --------
    >>> import orrc
    >>> cost = orrc.examples.double_integrator().cost
    >>> isinstance(cost, orrc.StageCost), cost.n, cost.m, cost.n_params
    (True, 2, 1, 5)
    """

    n: int | None
    m: int | None
    n_params: int
    default_params: np.ndarray
    alpha_lo: float | None
    name: str

    def expr(self, x, u, p):  # pragma: no cover - abstract
        """CasADi expression of c(x, u; p)."""
        raise NotImplementedError

    def _value(self, x, u, p) -> float:  # pragma: no cover - abstract
        """c(x, u; p) for arguments already checked (p=None: the default parameters)."""
        raise NotImplementedError

    def value(self, x, u, p=None) -> float:
        """Numeric c(x, u; p) (p=None: the default parameters); x, u and p are validated, and a
        value that overflows for these finite arguments is an error."""
        x, u, p = self._check_point(x, u, p)
        with np.errstate(over="ignore", invalid="ignore"):
            c = self._value(x, u, p)
        return check_finite_result(f"the stage cost c(x, u) of {self.name}", c, "x, u", "rescale x, u or the cost")

    def __call__(self, x, u, p=None) -> float:
        return self.value(x, u, p)

    def _check_point(self, x, u, p):
        x = as_array("x", x, None if self.n is None else (self.n,))
        u = as_array("u", u, None if self.m is None else (self.m,))
        if p is not None:
            P = self.check_params(p, "p") if self.n_params else as_array("p", p, (0,))[None]
            if P.shape[0] != 1:
                raise OrrcValueError(f"p must be one parameter vector of length {self.n_params}; got shape "
                                     f"{np.shape(p)}")
            p = P[0]
        return x, u, p

    def sigma(self, x) -> float:
        """σ(x) of Assumption 2 (default ‖x‖²)."""
        with np.errstate(over="ignore"):
            s = _norm_sq(as_array("x", x, None if self.n is None else (self.n,)))
        return check_finite_result("σ(x) = ‖x‖²", s, "x", "rescale x")

    def check_dims(self, n: int, m: int) -> None:
        if (self.n is not None and self.n != n) or (self.m is not None and self.m != m):
            raise OrrcValueError(
                f"the cost is for n={self.n} states and m={self.m} inputs; the system has n={n}, m={m}")

    def check_params(self, params, name: str = "cost_params") -> np.ndarray:
        """Validate a (L, n_params) array of per-step parameters (a single row may be 1-D).

        Each row must describe a valid cost of the family (:class:`QuadraticCost`: Q_t PSD and
        R_t PD); this is where cost data enter, so the solvers need not check them again.
        """
        params = as_array(name, params)
        if params.ndim == 1 and self.n_params > 0 and params.shape[0] == self.n_params:
            params = params[None, :]
        if params.ndim != 2 or params.shape[1] != self.n_params:
            raise OrrcValueError(
                f"{name} must have shape (L, {self.n_params}) for {self.name}; got shape {params.shape}")
        return params


def _alpha_lo(given, largest: float, what: str, tol: float = 0.0) -> float:
    """α_lo: ``largest`` (the best valid lower bound) unless a smaller one is given.

    ``tol``: the rounding error of ``largest`` (for λ_min(Q), n·eps·‖Q‖₂: :func:`eigvalsh_tol`);
    a given α_lo above ``largest`` by more than that is not a lower bound, at any scale of Q."""
    if given is None:
        return largest
    given = as_float("alpha_lo", given, minimum=0.0)
    if given > largest + tol:
        raise OrrcValueError(
            f"alpha_lo={given} is not a valid lower bound: c(x,u) >= alpha_lo*|x|^2 needs alpha_lo <= "
            f"{what} = {largest:.6g}")
    return given
