"""Systems with an unknown parameter θ: x_{t+1} = f(x_t, u_t, w_t; θ) (Section 4.2 of the paper).

* :class:`ParametricSystem` -- a user function ``f(x, u, w, theta)`` written with CasADi
  operations, θ ∈ R^p. The *same* model simulates with the true θ (:meth:`ParametricSystem.at`
  gives a :class:`~orrc.NonlinearSystem` to hand to :func:`orrc.simulate`) and is controlled with
  an estimate θ̂: :class:`~orrc.PreviewRHC` takes a ParametricSystem with ``theta=θ̂`` and passes
  θ to its CasADi NLP as a parameter, so a new estimate does not rebuild the solver
  (:meth:`~orrc.PreviewRHC.set_theta`).
* :class:`LinearParametricSystem` (``ParametricSystem.linear(n, m)``) -- x_{t+1} = A x_t + B u_t + w_t
  with θ = vec([A B]) (row by row, p = n(n+m)): the linear case of the paper's discussion, where
  :meth:`~LinearParametricSystem.at` gives a :class:`~orrc.LinearSystem` (the exact LQ path).

Systems linear in θ, x_{t+1} = x_t + f(x_t, u_t) + g(x_t, u_t) θ + w_t (the paper's second case),
are recognised symbolically (:attr:`ParametricSystem.linear_in_theta`) and expose the regressors
f₀ = f(x, u, w; 0) and G = ∂f/∂θ with f = f₀ + G θ (:meth:`ParametricSystem.regressors`), which
``orrc.estimation.least_squares_parametric`` stacks into one least-squares problem.
"""
from __future__ import annotations

import functools
from typing import Callable

import casadi as ca
import numpy as np

from ._validate import OrrcValueError, as_array, as_int, check_evaluates
from .systems import LinearSystem, NonlinearSystem, System, model_header, traced

__all__ = ["ParametricSystem", "LinearParametricSystem"]


class ParametricSystem(System):
    """x_{t+1} = f(x_t, u_t, w_t; θ) with ``f(x, u, w, theta)`` written in CasADi operations.

    Parameters
    ----------
    f : callable f(x, u, w, theta) receiving CasADi column vectors (x, w of length ``n_states``,
        u of length ``n_inputs``, theta of length ``n_params``) and returning the next state.
    n_states, n_inputs, n_params : n, m and p = dim θ.
    name : a label for plots.
    param_names : optional names of the p entries of θ (for tables and plots).

    A ParametricSystem has no θ of its own: simulate ``model.at(theta_true)`` and control with
    ``orrc.PreviewRHC(model, cost, M, theta=theta_hat)``.

    Examples
    --------
    x_{t+1} = θ_0 x_t + θ_1 u_t + w_t, simulated at θ = (2, 1):

    >>> import numpy as np
    >>> import orrc
    >>> model = orrc.ParametricSystem(lambda x, u, w, th: th[0] * x + th[1] * u + w,
    ...                               1, 1, 2)
    >>> true = model.at([2.0, 1.0])
    >>> true.step(np.array([1.0]), np.array([0.5]), np.zeros(1))
    array([2.5])
    """

    def __init__(self, f: Callable, n_states: int, n_inputs: int, n_params: int,
                 name: str = "parametric system", param_names=None):
        self.n, self.m, self.name = model_header(f, "f(x, u, w, theta)", n_states, n_inputs, name)
        self.n_params = as_int("n_params", n_params, minimum=1)
        if param_names is None:
            param_names = [f"theta[{i}]" for i in range(self.n_params)]
        param_names = [str(s) for s in param_names]
        if len(param_names) != self.n_params:
            raise OrrcValueError(f"param_names must list n_params={self.n_params} names; got {len(param_names)}")
        self.param_names = param_names
        self._f = f
        x, u, w = ca.SX.sym("x", self.n), ca.SX.sym("u", self.m), ca.SX.sym("w", self.n)
        th = ca.SX.sym("theta", self.n_params)
        out = traced(f, (x, u, w, th), self.n, "f(x, u, w, theta)")
        self._sym = (x, u, w, th, out)
        self.function = ca.Function("f", [x, u, w, th], [out], ["x", "u", "w", "theta"], ["x_next"])
        th_probe = np.full(self.n_params, 0.5)   # a generic θ (θ = 0 may be special, e.g. a zero inertia)
        check_evaluates("f", "f(x, u, w, theta)", lambda x_, u_: self.function(x_, u_, np.zeros(self.n), th_probe),
                        self.n, self.m)

    # -- the model -----------------------------------------------------------------------------
    def check_theta(self, theta, name: str = "theta") -> np.ndarray:
        """θ as a float vector of length p (validated)."""
        return as_array(name, theta, (self.n_params,))

    def symbolic(self, x, u, w, theta=None):
        """f(x, u, w; θ) on CasADi arguments (θ symbolic or numeric; required)."""
        if theta is None:
            raise OrrcValueError(f"{self.name}: a ParametricSystem needs theta; pass f(x, u, w, theta)")
        return self.function(x, u, w, theta)

    def step(self, x, u, w, theta=None) -> np.ndarray:
        """One numeric step x_{t+1} = f(x, u, w; θ) (validated).

        ``theta`` is required: a ParametricSystem has no θ of its own. To simulate the true
        system, pass ``model.at(theta_true)`` to :func:`orrc.simulate`.
        """
        if theta is None:
            raise OrrcValueError(
                f"{self.name} is a ParametricSystem without a θ of its own: simulate model.at(theta) "
                "(a NonlinearSystem with θ fixed), or call step(x, u, w, theta)")
        x, u, w = self.check_step_args(x, u, w)
        theta = self.check_theta(theta)
        out = np.asarray(self.function(x, u, w, theta)).ravel()
        if not np.all(np.isfinite(out)):
            raise FloatingPointError(f"{self.name}: f(x, u, w; θ) is not finite at x={x}, u={u}, θ={theta}")
        return out

    def at(self, theta, name: str | None = None) -> System:
        """The system with θ fixed: a :class:`~orrc.NonlinearSystem` (the same f) for :func:`orrc.simulate`."""
        theta = self.check_theta(theta)
        th = ca.DM(theta)
        return NonlinearSystem(lambda x, u, w: self.function(x, u, w, th), self.n, self.m,
                               name=name or f"{self.name} (θ fixed)")

    # -- linearity in θ ---------------------------------------------------------------------------
    @functools.cached_property
    def linear_in_theta(self) -> bool:
        """True when f is affine in θ (f = f₀(x, u, w) + G(x, u, w) θ), checked symbolically:
        the Jacobian ∂f/∂θ does not depend on θ. The paper's second case
        x+ = x + f(x, u) + g(x, u) θ + w is of this kind; so is the linear system with θ = vec[A B]."""
        x, u, w, th, out = self._sym
        return not bool(ca.depends_on(ca.jacobian(out, th), th))

    @functools.cached_property
    def _regressor_fn(self):
        x, u, w, th, out = self._sym
        G = ca.jacobian(out, th)
        f0 = ca.substitute(out, th, ca.SX.zeros(self.n_params))
        return ca.Function("regressors", [x, u, w], [f0, G])

    def regressors(self, X, U, W) -> tuple[np.ndarray, np.ndarray]:
        """f₀ (k, n) and G (k, n, p) with f(x_i, u_i, w_i; θ) = f₀_i + G_i θ, for k points at once.

        Needs :attr:`linear_in_theta` (else raises). ``X`` (k, n), ``U`` (k, m), ``W`` (k, n).
        """
        if not self.linear_in_theta:
            raise OrrcValueError(
                f"{self.name}: f is not affine in theta (∂f/∂θ depends on θ), so it has no regressors "
                "f = f0 + G theta; estimate it with EDMD or a nonlinear least-squares method")
        k = X.shape[0]
        F = self._regressor_fn.map(k)
        f0, G = F(X.T, U.T, W.T)
        f0 = np.asarray(f0).T.reshape(k, self.n)
        G = np.asarray(G).reshape(self.n, k, self.n_params).transpose(1, 0, 2)  # map: [G_1 ... G_k]
        return f0, G

    @classmethod
    def linear(cls, n: int, m: int, name: str = "linear system, (A, B) unknown") -> "LinearParametricSystem":
        """x_{t+1} = A x_t + B u_t + w_t with θ = vec([A B]) unknown (row by row, p = n(n+m))."""
        return LinearParametricSystem(n, m, name=name)

    def __repr__(self):
        return f"ParametricSystem(n={self.n}, m={self.m}, p={self.n_params}, name={self.name!r})"

    def __reduce__(self):
        """Pickled as its constructor's arguments (CasADi symbols do not pickle; they are traced again), so
        that a model travels to the worker processes of :func:`orrc.sweep` (``f`` itself must pickle:
        cloudpickle sends a function defined in a notebook by value)."""
        return ParametricSystem, (self._f, self.n, self.m, self.n_params, self.name, self.param_names)


class LinearParametricSystem(ParametricSystem):
    """x_{t+1} = A x_t + B u_t + w_t with θ = vec([A B]) (row by row): θ_{i(n+m)+j} = [A B]_{ij}.

    :meth:`at` returns a :class:`~orrc.LinearSystem`, so a controller built on an estimate takes
    the exact LQ path; :meth:`pack` / :meth:`unpack` convert between (A, B) and θ. The norm of
    θ̂ - θ is the Frobenius norm of [Â - A, B̂ - B] (the paper's ‖θ̂ - θ‖_F of Section 5.2).

    Parameters
    ----------
    n, m : the state and input dimensions; θ has n(n + m) entries.
    name : a label for plots.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> model = orrc.ParametricSystem.linear(2, 1)
    >>> theta = model.pack(np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.0], [0.1]]))
    >>> theta
    array([1. , 0.1, 0. , 0. , 1. , 0.1])
    >>> model.at(theta)
    LinearSystem(n=2, m=1, name='linear system (θ fixed)')
    """

    def __init__(self, n: int, m: int, name: str = "linear system, (A, B) unknown"):
        n = as_int("n", n, minimum=1)
        m = as_int("m", m, minimum=1)
        names = [f"{'A' if j < n else 'B'}[{i},{j if j < n else j - n}]" for i in range(n) for j in range(n + m)]

        def f(x, u, w, th):
            AB = ca.reshape(th, n + m, n).T  # CasADi reshapes column-major: θ row by row
            return ca.mtimes(AB, ca.vertcat(x, u)) + w

        super().__init__(f, n, m, n * (n + m), name=name, param_names=names)

    def unpack(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(A, B) from θ = vec([A B]) (row by row)."""
        AB = self.check_theta(theta).reshape(self.n, self.n + self.m)
        return AB[:, :self.n].copy(), AB[:, self.n:].copy()

    def pack(self, A, B) -> np.ndarray:
        """θ = vec([A B]) (row by row) from (A, B)."""
        A = as_array("A", A, (self.n, self.n))
        B = as_array("B", np.asarray(B, dtype=float).reshape(self.n, -1) if np.ndim(B) == 1 else B,
                     (self.n, self.m))
        return np.hstack([A, B]).ravel()

    def at(self, theta, name: str | None = None) -> LinearSystem:
        """The linear system x+ = A x + B u + w with (A, B) from θ (a :class:`~orrc.LinearSystem`)."""
        A, B = self.unpack(theta)
        return LinearSystem(A, B, name=name or "linear system (θ fixed)")

    def __repr__(self):
        return f"LinearParametricSystem(n={self.n}, m={self.m}, p={self.n_params})"

    def __reduce__(self):
        return LinearParametricSystem, (self.n, self.m, self.name)
