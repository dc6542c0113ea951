"""Dynamical systems x_{t+1} = f(x_t, u_t, w_t) (Eq. 1 of the paper, θ known).

Two kinds:

* :class:`LinearSystem` -- x_{t+1} = A x_t + B u_t + w_t, the additive-disturbance
  linear system used by every linear example (exact Riccati solvers apply);
* :class:`NonlinearSystem` -- a user function ``f(x, u, w)`` written with CasADi
  operations, so the same expression is simulated numerically and optimised
  symbolically by the receding-horizon solvers.

Both expose ``n`` (states), ``m`` (inputs), ``step(x, u, w)`` (numeric) and
``symbolic(x, u, w)`` (CasADi). The disturbance has the dimension of the state,
as in the paper.
"""
from __future__ import annotations

from typing import Callable

import casadi as ca
import numpy as np

from ._casadi import DropsBuffers, buffered
from ._validate import OrrcValueError, as_array, as_int, as_square, check_evaluates


def traced(f: Callable, args: tuple, n: int, signature: str):
    """``f(*args)`` traced on CasADi symbols: the next state as an (n, 1) SX, or a clear error naming
    ``signature`` when f is not CasADi-traceable or does not return n values.

    Parameters
    ----------
    f : the user's function.
    args : the CasADi symbols to call it with.
    n : the length of the next state.
    signature : how f is called, for the message (e.g. "f(x, u, w)").

    Returns
    -------
    casadi.SX
        (n, 1) the traced next state.

    Raises
    ------
    orrc.OrrcValueError
        When f fails on CasADi symbols or does not return n values.

    Examples
    --------
    >>> import casadi as ca
    >>> from orrc.systems import traced
    >>> x, u, w = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("w", 2)
    >>> traced(lambda x, u, w: x + w, (x, u, w), 2, "f(x, u, w)").shape
    (2, 1)
    """
    try:
        out = ca.vec(ca.SX(f(*args)))
    except Exception as exc:  # the user function is not CasADi-traceable
        raise OrrcValueError(
            f"{signature} must be written with CasADi operations (ca.sin, ca.vertcat, ...); "
            f"tracing it failed with: {exc}") from exc
    if out.shape != (n, 1):
        raise OrrcValueError(f"{signature} must return a vector of length n_states={n}; got shape {out.shape}")
    return out


class System:
    """Common interface; see :class:`LinearSystem` and :class:`NonlinearSystem`.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.double_integrator()
    >>> isinstance(ex.system, orrc.System), ex.system.n, ex.system.m
    (True, 2, 1)
    """

    n: int
    m: int
    name: str

    def symbolic(self, x, u, w):  # pragma: no cover - abstract
        raise NotImplementedError

    def step(self, x, u, w) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def check_step_args(self, x, u, w):
        x = as_array("x", x, (self.n,))
        u = as_array("u", u, (self.m,))
        w = as_array("w", w, (self.n,))
        return x, u, w


class LinearSystem(System):
    """x_{t+1} = A x_t + B u_t + w_t (Eq. 1 with f linear and w additive).

    Parameters
    ----------
    A : (n, n) array
    B : (n, m) array (a 1-D array is read as a single input column)
    name : optional label used in plots.

    Raises
    ------
    orrc.OrrcValueError
        When A is not square, B's rows do not match A, or an entry is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> sys = orrc.LinearSystem([[1.0, 0.1], [0.0, 1.0]], [[0.0], [0.1]])
    >>> sys.n, sys.m
    (2, 1)
    >>> sys.step(np.array([1.0, 0.0]), np.array([1.0]), np.zeros(2))   # A x + B u + w
    array([1. , 0.1])
    """

    def __init__(self, A, B, name: str = "linear system"):
        A = as_square("A", A)
        B = as_array("B", B)
        if B.ndim == 1:
            B = B.reshape(-1, 1)
        if B.ndim != 2 or B.shape[0] != A.shape[0] or B.shape[1] == 0:
            raise OrrcValueError(
                f"B must have shape ({A.shape[0]}, m) with m >= 1 to match A of shape {A.shape}; got shape {B.shape}")
        if not isinstance(name, str):
            raise OrrcValueError(f"name must be a string; got {type(name).__name__}")
        self.A, self.B = A, B
        self.n, self.m = B.shape
        self.name = name

    @classmethod
    def from_statespace(cls, sys, name: str | None = None) -> "LinearSystem":
        """Build from a discrete-time python-control ``StateSpace`` (uses its A and B).

        The disturbance enters additively on the state, as in the paper; the
        ``StateSpace``'s C and D are ignored (the state is observed).
        """
        import control

        if not isinstance(sys, control.StateSpace):
            raise OrrcValueError(f"sys must be a control.StateSpace; got {type(sys).__name__}")
        if not sys.isdtime(strict=True):
            raise OrrcValueError(
                "sys must be a discrete-time StateSpace (dt > 0 or True); got a continuous-time "
                "system: discretise it first, e.g. with control.sample_system(sys, Ts)")
        return cls(np.asarray(sys.A), np.asarray(sys.B), name=name or "linear system")

    def symbolic(self, x, u, w):
        return ca.mtimes(ca.DM(self.A), x) + ca.mtimes(ca.DM(self.B), u) + w

    def step(self, x, u, w) -> np.ndarray:
        """One step of the dynamics (validated); raises FloatingPointError if the result overflows."""
        x, u, w = self.check_step_args(x, u, w)
        with np.errstate(over="ignore", invalid="ignore"):
            out = self.A @ x + self.B @ u + w
        if not np.all(np.isfinite(out)):
            raise FloatingPointError(f"{self.name}: A x + B u + w is not finite at x={x}, u={u}, w={w} (overflow)")
        return out

    def __repr__(self):
        return f"LinearSystem(n={self.n}, m={self.m}, name={self.name!r})"


def model_header(f, call: str, n_states, n_inputs, name) -> tuple[int, int, str]:
    """(n, m, name) of a model given by a user's function ``f`` (called as ``call``, e.g. "f(x, u, w)"),
    checked: f callable, the dimensions integers >= 1, the name a string.

    Parameters
    ----------
    f : the user's function.
    call : how f is called (e.g. "f(x, u, w)").
    n_states, n_inputs : the dimensions.
    name : the model's label.

    Returns
    -------
    tuple
        (n, m, name), checked.

    Raises
    ------
    orrc.OrrcValueError
        When f is not callable, a dimension is not an integer >= 1, or the name is not a string.

    Examples
    --------
    >>> from orrc.systems import model_header
    >>> model_header(lambda x, u, w: x, "f(x, u, w)", 2, 1, "my model")
    (2, 1, 'my model')
    """
    if not callable(f):
        raise OrrcValueError(f"f must be callable {call}; got {type(f).__name__}")
    if not isinstance(name, str):
        raise OrrcValueError(f"name must be a string; got {type(name).__name__}")
    return as_int("n_states", n_states, minimum=1), as_int("n_inputs", n_inputs, minimum=1), name


class NonlinearSystem(DropsBuffers, System):
    """x_{t+1} = f(x_t, u_t, w_t) with ``f`` written in CasADi operations.

    ``f(x, u, w)`` receives CasADi column vectors (``x`` of length ``n_states``,
    ``u`` of length ``n_inputs``, ``w`` of length ``n_states``) and returns the next
    state, e.g. ``ca.vertcat(x[0] + dt * x[1], x[1] + dt * (ca.sin(x[0]) + u[0])) + w``.
    It is traced once into a ``casadi.Function``; numeric steps evaluate that function.
    At construction ``f`` is evaluated once (at the origin, or at a generic point if it is not
    finite there) and refused when the result is not finite: ``math.sin`` or numpy applied to a
    CasADi symbol traces to NaN everywhere instead of failing.

    Parameters
    ----------
    f : the update f(x, u, w) in CasADi operations, returning the next state (length ``n_states``).
    n_states, n_inputs : n and m.
    name : a label for plots.

    Raises
    ------
    orrc.OrrcValueError
        When ``f`` fails on CasADi symbols, returns the wrong length, or is not finite at the point
        where it is evaluated.

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> import orrc
    >>> def f(x, u, w):   # a pendulum, Euler-sampled with dt = 0.05
    ...     return ca.vertcat(x[0] + 0.05 * x[1],
    ...                       x[1] + 0.05 * (9.81 * ca.sin(x[0]) + u[0])) + w
    >>> pend = orrc.NonlinearSystem(f, n_states=2, n_inputs=1)
    >>> pend.step(np.array([0.1, 0.0]), np.array([0.0]), np.zeros(2))
    array([0.1       , 0.04896829])
    """

    def __init__(self, f: Callable, n_states: int, n_inputs: int, name: str = "nonlinear system"):
        self.n, self.m, self.name = model_header(f, "f(x, u, w)", n_states, n_inputs, name)
        self._f = f
        x, u, w = ca.SX.sym("x", self.n), ca.SX.sym("u", self.m), ca.SX.sym("w", self.n)
        out = traced(f, (x, u, w), self.n, "f(x, u, w)")
        self.function = ca.Function("f", [x, u, w], [out], ["x", "u", "w"], ["x_next"])
        check_evaluates("f", "f(x, u, w)", lambda x, u: self.function(x, u, np.zeros(self.n)), self.n, self.m)

    def symbolic(self, x, u, w):
        return self.function(x, u, w)

    def step(self, x, u, w) -> np.ndarray:
        """One step of the dynamics (validated); raises if the result is not finite."""
        x, u, w = self.check_step_args(x, u, w)
        out = self._step(x, u, w)
        if not np.all(np.isfinite(out)):
            raise FloatingPointError(
                f"{self.name}: f(x, u, w) is not finite at x={x}, u={u}, w={w} (the state diverged)")
        return out

    def _step(self, x, u, w) -> np.ndarray:
        """One step for arguments already checked (the simulator's hot path; it checks the states after
        the run), evaluated on numpy buffers (:mod:`orrc._casadi`: 2 µs instead of 35 µs per call)."""
        call = buffered(self, "f", lambda: self.function)
        call(x, u, w)
        return call.res[0].copy()

    def linearize(self, x=None, u=None):
        """Jacobians (A, B) of f at (x, u, w=0), default the origin: the local linear model."""
        x = np.zeros(self.n) if x is None else as_array("x", x, (self.n,))
        u = np.zeros(self.m) if u is None else as_array("u", u, (self.m,))
        xs, us, ws = ca.SX.sym("x", self.n), ca.SX.sym("u", self.m), ca.SX.sym("w", self.n)
        fx = self.function(xs, us, ws)
        jac = ca.Function("jacobians", [xs, us, ws], [ca.jacobian(fx, xs), ca.jacobian(fx, us)])  # "jac" is reserved by CasADi
        A, B = jac(x, u, np.zeros(self.n))
        A, B = np.asarray(A), np.asarray(B)
        if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B))):
            raise OrrcValueError(f"{self.name}: the Jacobians of f at x={x}, u={u} are not finite; "
                                 "linearize at another point (x=..., u=...)")
        return A, B

    def __repr__(self):
        return f"NonlinearSystem(n={self.n}, m={self.m}, name={self.name!r})"
