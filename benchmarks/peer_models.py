"""The models of the peer benchmarks in CasADi, for the peers' own environments (no orrc there).

``dynamics(prob)`` is the CasADi expression x_{t+1} = f(x_t, u_t) + w_t of the problem a peer script reads
on stdin: ``prob["model"]`` is ``"pendulum"`` (the default; ``benchmarks/pendulum.py``) or ``"chain"`` (k
unit masses joined by springs F(d) = stiffness d + cubic d³, the first tied to a wall, a force on the
last, damping on each, semi-implicit Euler; ``orrc.examples.mass_chain``) or ``"quadrotor"`` (12 states:
position, velocity, roll-pitch-yaw angles, body rates; 4 inputs: the thrust's deviation from hover and the
body torques; Euler-sampled; ``orrc.examples.quadrotor``). ``weights(prob)``: the diagonal state weights q (n,)
and input weights r (m,) of the cost Σ_j q·x_j² + r·u_j².
"""
import casadi as ca
import numpy as np


def n_states(prob) -> int:
    model = prob.get("model", "pendulum")
    return 2 * int(prob["k"]) if model == "chain" else 12 if model == "quadrotor" else 2


def n_inputs(prob) -> int:
    return 4 if prob.get("model", "pendulum") == "quadrotor" else 1


def _quadrotor_rates(prob, x, u, cos, sin, stack):
    """ẋ of the quadrotor (``orrc.examples.quadrotor``) with the given cos, sin and stack (CasADi or numpy)."""
    g, mass = prob["gravity"], prob["mass"]
    Jx, Jy, Jz = prob["inertia"]
    v, om = [x[i] for i in range(3, 6)], [x[i] for i in range(9, 12)]
    cf, sf, ct, st, cp, sp = cos(x[6]), sin(x[6]), cos(x[7]), sin(x[7]), cos(x[8]), sin(x[8])
    a = g + u[0] / mass
    acc = [a * (cf * st * cp + sf * sp), a * (cf * st * sp - sf * cp), a * cf * ct - g]
    r = sf * om[1] + cf * om[2]
    eta = [om[0] + r * st / ct, cf * om[1] - sf * om[2], r / ct]
    om_dot = [(u[1] - (Jz - Jy) * om[1] * om[2]) / Jx, (u[2] - (Jx - Jz) * om[2] * om[0]) / Jy,
              (u[3] - (Jy - Jx) * om[0] * om[1]) / Jz]
    return stack(v + acc + eta + om_dot)


def dynamics(prob, x, u, w):
    """f(x, u) + w in CasADi operations (x, w: n symbols, u: m symbols)."""
    dt = prob["dt"]
    if prob.get("model") == "quadrotor":
        return x + dt * _quadrotor_rates(prob, x, u, ca.cos, ca.sin, lambda e: ca.vertcat(*e)) + w
    if prob.get("model", "pendulum") == "pendulum":
        return ca.vertcat(x[0] + dt * x[1], x[1] + dt * (prob["g_over_l"] * ca.sin(x[0]) - prob["friction"] * x[1]
                                                          + u[0])) + w
    k, ks, kc, c = int(prob["k"]), prob["stiffness"], prob["cubic"], prob["damping"]
    p, v = x[:k], x[k:]
    d = ca.vertcat(p[0], p[1:] - p[:-1]) if k > 1 else p[0]
    force = ks * d + kc * d ** 3
    a = (ca.vertcat(force[1:], 0) if k > 1 else 0) - force - c * v
    a = a + ca.vertcat(ca.DM.zeros(k - 1, 1), u[0]) if k > 1 else a + u[0]
    v_next = v + dt * a
    return ca.vertcat(p + dt * v_next, v_next) + w


def weights(prob):
    """(q (n,), r (m,)): the cost Σ_j Σ_i q_i x_{j,i}² + Σ_i r_i u_{j,i}²."""
    return np.asarray(prob["q"], float), np.asarray(prob["r"], float).reshape(-1)


def plant(prob):
    """The plant (x, u, w) -> f(x, u) + w in numpy (the same model as :func:`dynamics`), for the closed loop."""
    dt = prob["dt"]
    if prob.get("model") == "quadrotor":
        return lambda x, u, w: x + dt * _quadrotor_rates(prob, x, u, np.cos, np.sin, np.array) + w
    if prob.get("model", "pendulum") == "pendulum":
        gl, fr = prob["g_over_l"], prob["friction"]
        return lambda x, u, w: np.array([x[0] + dt * x[1], x[1] + dt * (gl * np.sin(x[0]) - fr * x[1] + u[0])]) + w
    k, ks, kc, c = int(prob["k"]), prob["stiffness"], prob["cubic"], prob["damping"]

    def step(x, u, w):
        p, v = x[:k], x[k:]
        d = np.diff(p, prepend=0.0)
        force = ks * d + kc * d ** 3
        a = np.append(force[1:], 0.0) - force - c * v
        a[-1] += u[0]
        v_next = v + dt * a
        return np.concatenate([p + dt * v_next, v_next]) + w

    return step
