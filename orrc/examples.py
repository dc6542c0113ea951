"""Named example problems: those of the book's chapters, ready to use.

Each function returns an :class:`Example` bundling a system, a stage cost, an
initial state, input bounds (or None) and a suggested horizon M. All disturbances
are additive (x_{t+1} = f(x_t, u_t) + w_t), as in the paper's examples. Parameters are
validated: a time step dt <= 0, a negative weight, friction or stiffness, a bound u_max <= 0
raise :class:`~orrc.OrrcValueError` naming the parameter.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ._validate import OrrcValueError, as_float, as_int
from .costs import QuadraticCost, StageCost
from .systems import LinearSystem, NonlinearSystem, System


@dataclass
class Example:
    """A worked example of the book: a system of Eq. (1), a stage cost, a start and a horizon.

    Attributes
    ----------
    name : the constructor's name ("double_integrator", ...).
    system : the :class:`~orrc.System`.
    cost : the :class:`~orrc.StageCost` c(x, u).
    x0 : (n,) the initial state the book starts from.
    M : the preview horizon the book uses with it.
    input_bounds : (lo, hi) of the input set U, or None.
    description : one line for tables and titles.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.double_integrator()
    >>> ex.system, ex.x0, ex.M, ex.input_bounds
    (LinearSystem(n=2, m=1, name='double integrator'), array([1., 0.]), 10, None)
    """

    name: str
    system: System
    cost: StageCost
    x0: np.ndarray
    M: int
    input_bounds: tuple | None
    description: str

    def __repr__(self):
        return f"Example({self.name!r}: {self.description})"


def scalar_unstable(A: float = 2.0, B: float = 1.0, q: float = 1.0, r: float = 1.0, *,
                    a: float | None = None, b: float | None = None) -> Example:
    """The scalar system x_{t+1} = A x_t + B u_t + w_t, open-loop unstable when |A| > 1, with the
    stage cost c(x, u) = q x² + r u² (the paper's setting, Eqs. (1)-(2), with n = m = 1).

    ``A`` and ``B`` are the coefficients of the linear system x+ = A x + B u + w, as for any
    linear system (``LinearSystem(A, B)``); in the book ``a`` is only the paper's decay rate
    and ``b`` only Lemma 2's constant. The old keywords ``a`` and ``b`` for the coefficients
    are still accepted, with a :class:`DeprecationWarning`.

    Parameters
    ----------
    A, B : the coefficients of x+ = A x + B u + w (B != 0).
    q, r : the cost's weights, q >= 0 and r > 0.
    a, b : deprecated names of A and B.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Raises
    ------
    orrc.OrrcValueError
        When a coefficient is not finite, B = 0, q < 0 or r <= 0.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable(A=2.0, B=1.0)
    >>> ex.system.A, ex.system.B, ex.x0
    (array([[2.]]), array([[1.]]), array([1.]))
    """
    for old, new_name, given, default in (("a", "A", A, 2.0), ("b", "B", B, 1.0)):
        value = a if old == "a" else b
        if value is None:
            continue
        if given != default:
            raise OrrcValueError(f"scalar_unstable: give the coefficient as {new_name} only; got "
                                 f"{new_name}={given!r} and the old keyword {old}={value!r}")
        warnings.warn(f"scalar_unstable({old}=...) is deprecated: the coefficient of x+ = A x + "
                      f"B u + w is now the keyword {new_name} ({old} is the decay rate or "
                      f"Lemma 2's constant in the book)", DeprecationWarning, stacklevel=2)
        A, B = (value, B) if old == "a" else (A, value)
    A, B = as_float("A", A), as_float("B", B)
    if B == 0.0:
        raise OrrcValueError("B must be non-zero (with B = 0 the input has no effect); got 0.0")
    q, r = as_float("q", q, minimum=0.0), as_float("r", r, minimum=0.0, strict_min=True)
    return Example("scalar_unstable", LinearSystem([[A]], [[B]], name=f"x+ = {A:g}x + {B:g}u + w"),
                   QuadraticCost([[q]], [[r]]), np.array([1.0]), 5, None,
                   f"scalar system x+ = {A:g} x + {B:g} u + w, open-loop unstable")


def double_integrator(dt: float = 0.1, q_vel: float = 0.1, r: float = 0.1) -> Example:
    """Position/velocity of a unit mass pushed by u, sampled with period dt (exact ZOH).

    Parameters
    ----------
    dt : the sampling period, > 0.
    q_vel : the velocity's weight in Q = diag(1, q_vel).
    r : the input weight R.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.double_integrator(dt=0.1)
    >>> ex.system.A
    array([[1. , 0.1],
           [0. , 1. ]])
    """
    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    q_vel, r = as_float("q_vel", q_vel, minimum=0.0), as_float("r", r, minimum=0.0, strict_min=True)
    A = np.array([[1.0, dt], [0.0, 1.0]])
    B = np.array([[0.5 * dt * dt], [dt]])
    return Example("double_integrator", LinearSystem(A, B, name="double integrator"),
                   QuadraticCost(np.diag([1.0, q_vel]), [[r]]), np.array([1.0, 0.0]), 10, None,
                   f"double integrator, dt = {dt:g}")


def two_mass_spring(dt: float = 0.1, k: float = 1.0, c: float = 0.05) -> Example:
    """Two unit masses joined by a spring (k) and damper (c), force on the first: n = 4, m = 1.

    State (p1, p2, v1, v2); continuous dynamics discretised by ``control.sample_system`` (ZOH).

    Parameters
    ----------
    dt : the sampling period, > 0.
    k, c : the spring's stiffness and the damper's coefficient.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.two_mass_spring()
    >>> ex.system.n, ex.system.m, ex.x0
    (4, 1, array([ 1., -1.,  0.,  0.]))
    """
    import control

    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    k, c = as_float("k", k, minimum=0.0), as_float("c", c, minimum=0.0)
    Ac = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-k, k, -c, c], [k, -k, c, -c]], dtype=float)
    Bc = np.array([[0.0], [0.0], [1.0], [0.0]])
    sysd = control.sample_system(control.ss(Ac, Bc, np.eye(4), np.zeros((4, 1))), dt)
    Q = np.diag([1.0, 1.0, 0.1, 0.1])
    return Example("two_mass_spring", LinearSystem.from_statespace(sysd, name="two masses and a spring"),
                   QuadraticCost(Q, [[0.1]]), np.array([1.0, -1.0, 0.0, 0.0]), 20, None,
                   "two masses, spring and damper, force on one mass (n = 4)")


def inverted_pendulum(dt: float = 0.05, g_over_l: float = 9.81, friction: float = 0.1,
                      u_max: float = 20.0) -> Example:
    """Pendulum about its upright position φ = 0 (nonlinear, open-loop unstable), Euler-sampled:

        φ_{t+1} = φ_t + dt ω_t,   ω_{t+1} = ω_t + dt (g/l sin φ_t − friction ω_t + u_t),  plus w_t.

    Cost c = 10 φ² + ω² + 0.1 u², input bounds |u| <= u_max.

    Parameters
    ----------
    dt : the sampling period, > 0.
    g_over_l : g / l, the gravity term.
    friction : the viscous friction coefficient.
    u_max : the input bound |u| <= u_max.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.inverted_pendulum()
    >>> ex.system, ex.x0, ex.input_bounds
    (NonlinearSystem(n=2, m=1, name='inverted pendulum'), array([0.5, 0. ]), (-20.0, 20.0))
    """
    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    g_over_l = as_float("g_over_l", g_over_l, minimum=0.0)
    friction = as_float("friction", friction, minimum=0.0)
    u_max = as_float("u_max", u_max, minimum=0.0, strict_min=True)

    def f(x, u, w):
        return ca.vertcat(x[0] + dt * x[1],
                          x[1] + dt * (g_over_l * ca.sin(x[0]) - friction * x[1] + u[0])) + w

    return Example("inverted_pendulum", NonlinearSystem(f, 2, 1, name="inverted pendulum"),
                   QuadraticCost(np.diag([10.0, 1.0]), [[0.1]]), np.array([0.5, 0.0]), 20,
                   (-u_max, u_max), f"inverted pendulum (upright), dt = {dt:g}, |u| <= {u_max:g}")


def van_der_pol(dt: float = 0.1, mu: float = 1.0, u_max: float = 5.0,
                input_weight: float = 0.1) -> Example:
    """Van der Pol oscillator (unstable origin, stable limit cycle), Euler-sampled:

        x1+ = x1 + dt x2,  x2+ = x2 + dt (mu (1 − x1²) x2 − x1 + u),  plus w.

    Cost c = x1² + x2² + input_weight · u² (0.1 by default), |u| <= u_max.

    Parameters
    ----------
    dt : the sampling period, > 0.
    mu : the oscillator's nonlinearity.
    u_max : the input bound |u| <= u_max.
    input_weight : the weight of u² in the cost, > 0.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.van_der_pol()
    >>> ex.system, ex.x0, ex.M
    (NonlinearSystem(n=2, m=1, name='Van der Pol oscillator'), array([1.5, 0. ]), 15)
    >>> float(orrc.examples.van_der_pol(input_weight=0.01).cost.R[0, 0])
    0.01
    """
    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    mu = as_float("mu", mu, minimum=0.0)
    u_max = as_float("u_max", u_max, minimum=0.0, strict_min=True)
    input_weight = as_float("input_weight", input_weight, minimum=0.0, strict_min=True)

    def f(x, u, w):
        return ca.vertcat(x[0] + dt * x[1],
                          x[1] + dt * (mu * (1 - x[0] ** 2) * x[1] - x[0] + u[0])) + w

    return Example("van_der_pol", NonlinearSystem(f, 2, 1, name="Van der Pol oscillator"),
                   QuadraticCost(np.eye(2), [[input_weight]]), np.array([1.5, 0.0]), 15,
                   (-u_max, u_max), f"Van der Pol oscillator, mu = {mu:g}, dt = {dt:g}, |u| <= {u_max:g}")


#: the most masses :func:`mass_chain` builds (its symbolic model grows linearly with them)
MAX_MASSES = 10_000


def mass_chain(k: int = 2, dt: float = 0.1, stiffness: float = 1.0, cubic: float = 1.0, damping: float = 0.1,
               u_max: float = 2.0) -> Example:
    """A chain of k unit masses joined by nonlinear (hardening) springs, the first tied to a wall, a force on
    the last: n = 2k, m = 1, any k (the scalable nonlinear example). Semi-implicit Euler:

        v_{t+1} = v_t + dt (a(p_t) − damping v_t + e_k u_t),   p_{t+1} = p_t + dt v_{t+1},   plus w_t,

    with state x = (p_1..p_k, v_1..v_k), the springs' stretches d_1 = p_1, d_i = p_i − p_{i−1}, the spring
    force F(d) = stiffness d + cubic d³ and the accelerations a_i = F(d_{i+1}) − F(d_i) (no spring after the
    last mass). Its linearisation at the origin is the linear chain (F(d) = stiffness d); without input and
    disturbance the energy ½‖v‖² + Σ_i (stiffness d_i²/2 + cubic d_i⁴/4) is dissipated by the damping.
    Cost c = ‖p‖² + 0.1 ‖v‖² + 0.1 u², input bounds |u| <= u_max, start p = 0.5 (every mass), v = 0.

    Parameters
    ----------
    k : the number of masses, an integer in [1, MAX_MASSES] (the state dimension is n = 2k).
    dt : the sampling period, > 0.
    stiffness : the springs' linear coefficient, >= 0.
    cubic : the springs' cubic coefficient, >= 0 (0: the linear chain).
    damping : the viscous damping of each mass, >= 0.
    u_max : the input bound |u| <= u_max, > 0.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.mass_chain(k=3)
    >>> ex.system
    NonlinearSystem(n=6, m=1, name='chain of 3 masses')
    >>> ex.x0, ex.input_bounds
    (array([0.5, 0.5, 0.5, 0. , 0. , 0. ]), (-2.0, 2.0))
    """
    k = as_int("k", k, minimum=1, maximum=MAX_MASSES)
    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    stiffness = as_float("stiffness", stiffness, minimum=0.0)
    cubic = as_float("cubic", cubic, minimum=0.0)
    damping = as_float("damping", damping, minimum=0.0)
    u_max = as_float("u_max", u_max, minimum=0.0, strict_min=True)

    def f(x, u, w):
        p, v = x[:k], x[k:]
        d = ca.vertcat(p[0], p[1:] - p[:-1]) if k > 1 else p[0]
        force = stiffness * d + cubic * d ** 3
        a = (ca.vertcat(force[1:], 0) if k > 1 else 0) - force - damping * v
        a[k - 1] += u[0]
        v_next = v + dt * a
        return ca.vertcat(p + dt * v_next, v_next) + w

    Q = np.diag([1.0] * k + [0.1] * k)
    masses = f"{k} mass{'es' if k > 1 else ''}"
    return Example("mass_chain", NonlinearSystem(f, 2 * k, 1, name=f"chain of {masses}"),
                   QuadraticCost(Q, [[0.1]]), np.concatenate([np.full(k, 0.5), np.zeros(k)]), 20,
                   (-u_max, u_max), f"chain of {masses}, nonlinear springs (n = {2 * k}), |u| <= {u_max:g}")


def quadrotor(dt: float = 0.05, mass: float = 1.0, inertia=(0.02, 0.02, 0.04), gravity: float = 9.81,
              thrust_max: float = 5.0, torque_max: float = 0.5) -> Example:
    """A quadrotor about hover (nonlinear, n = 12, m = 4), Euler-sampled with step dt:

        ṗ = v,   v̇ = (g + u_1 / mass) R(η) e_3 − g e_3,   η̇ = E(η) ω,   ω̇ = J⁻¹ (u_{2:4} − ω × J ω),

    plus w_t, with state x = (p, v, η, ω): the position p and velocity v in the world frame, the Euler angles
    η = (φ, θ, ψ) (roll, pitch, yaw; R(η) = R_z(ψ) R_y(θ) R_x(φ) the body-to-world rotation, E(η) the map of
    the body rates ω to the angles' rates) and the body rates ω; the inputs are the thrust's deviation from
    hover u_1 (the total thrust is mass·g + u_1) and the body torques u_{2:4}; J = diag(inertia). The hover
    x = 0, u = 0 is an equilibrium; linearised there, the model is four chains of integrators (the horizontal
    accelerations g θ and −g φ, the vertical one u_1 / mass). Cost c = ‖p‖² + 0.1 ‖v‖² + 0.1 ‖η‖² +
    0.01 ‖ω‖² + 0.1 u_1² + u_{2:4}ᵀ u_{2:4}, input bounds |u_1| <= thrust_max, |u_{2:4}| <= torque_max,
    start p = (0.5, −0.5, 0.3), at rest and level.

    Parameters
    ----------
    dt : the sampling period, > 0.
    mass : the mass, > 0.
    inertia : the principal moments of inertia (J_x, J_y, J_z), each > 0.
    gravity : g, >= 0.
    thrust_max : the bound on the thrust's deviation from hover, > 0 and below mass·g (the thrust stays positive).
    torque_max : the bound on each torque, > 0.

    Returns
    -------
    Example
        ``system``, ``cost``, ``x0``, ``M``, ``input_bounds`` and a ``description``.

    Raises
    ------
    orrc.OrrcValueError
        When a parameter is out of its range (the message names it).

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> ex = orrc.examples.quadrotor()
    >>> ex.system
    NonlinearSystem(n=12, m=4, name='quadrotor')
    >>> x, u, w = np.zeros(12), np.zeros(4), np.zeros(12)
    >>> bool(np.allclose(ex.system.step(x, u, w), 0))   # hover is an equilibrium
    True
    >>> A, B = ex.system.linearize()
    >>> # pitch and roll tilt the thrust: g dt and -g dt
    >>> print(f"{A[3, 7]:.4f} {A[4, 6]:.4f}")
    0.4905 -0.4905
    """
    dt = as_float("dt", dt, minimum=0.0, strict_min=True)
    mass = as_float("mass", mass, minimum=0.0, strict_min=True)
    try:
        moments = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        moments = None
    if moments is None or moments.shape != (3,) or not np.all(np.isfinite(moments)) or np.any(moments <= 0):
        raise OrrcValueError(f"inertia must be three finite moments of inertia > 0 (J_x, J_y, J_z); got {inertia!r}")
    inertia = moments
    gravity = as_float("gravity", gravity, minimum=0.0)
    thrust_max = as_float("thrust_max", thrust_max, minimum=0.0, strict_min=True)
    if gravity > 0 and thrust_max >= mass * gravity:
        raise OrrcValueError(f"thrust_max must be below mass·gravity = {mass * gravity:g} (the thrust stays "
                             f"positive); got {thrust_max:g}")
    torque_max = as_float("torque_max", torque_max, minimum=0.0, strict_min=True)
    Jx, Jy, Jz = (float(j) for j in inertia)

    def f(x, u, w):
        v, eta, om = x[3:6], x[6:9], x[9:12]
        phi, theta, psi = eta[0], eta[1], eta[2]
        cf, sf, ct, st, cp, sp = ca.cos(phi), ca.sin(phi), ca.cos(theta), ca.sin(theta), ca.cos(psi), ca.sin(psi)
        thrust_axis = ca.vertcat(cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct)   # R(η) e_3
        acc = (gravity + u[0] / mass) * thrust_axis - ca.vertcat(0, 0, gravity)
        eta_dot = ca.vertcat(om[0] + (sf * om[1] + cf * om[2]) * st / ct, cf * om[1] - sf * om[2],
                             (sf * om[1] + cf * om[2]) / ct)
        om_dot = ca.vertcat((u[1] - (Jz - Jy) * om[1] * om[2]) / Jx, (u[2] - (Jx - Jz) * om[2] * om[0]) / Jy,
                            (u[3] - (Jy - Jx) * om[0] * om[1]) / Jz)
        return x + dt * ca.vertcat(v, acc, eta_dot, om_dot) + w

    Q = np.diag([1.0] * 3 + [0.1] * 3 + [0.1] * 3 + [0.01] * 3)
    R = np.diag([0.1, 1.0, 1.0, 1.0])
    bound = np.array([thrust_max] + [torque_max] * 3)
    x0 = np.zeros(12)
    x0[:3] = [0.5, -0.5, 0.3]
    return Example("quadrotor", NonlinearSystem(f, 12, 4, name="quadrotor"), QuadraticCost(Q, R), x0, 20,
                   (-bound, bound), f"quadrotor about hover (n = 12, m = 4), |thrust| <= {thrust_max:g}, "
                   f"|torques| <= {torque_max:g}")


ALL = {f.__name__: f for f in (scalar_unstable, double_integrator, two_mass_spring,
                               inverted_pendulum, van_der_pol, mass_chain, quadrotor)}
