"""The models of the peer benchmarks in CasADi, for the peers' own environments (no orrc there).

``dynamics(prob)`` is the CasADi expression x_{t+1} = f(x_t, u_t) + w_t of the problem a peer script reads
on stdin: ``prob["model"]`` is ``"pendulum"`` (the default; ``benchmarks/pendulum.py``) or ``"chain"`` (k
unit masses joined by springs F(d) = stiffness d + cubic d³, the first tied to a wall, a force on the
last, damping on each, semi-implicit Euler; ``orrc.examples.mass_chain``). ``weights(prob)``: the
diagonal state weights q (n,) and the input weight r of the cost Σ_j q·x_j² + r u_j².
"""
import casadi as ca
import numpy as np


def n_states(prob) -> int:
    return 2 * int(prob["k"]) if prob.get("model", "pendulum") == "chain" else 2


def dynamics(prob, x, u, w):
    """f(x, u) + w in CasADi operations (x, w: n symbols, u: 1 symbol)."""
    dt = prob["dt"]
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
    """(q (n,), r): the cost Σ_j Σ_i q_i x_{j,i}² + r u_j²."""
    return np.asarray(prob["q"], float), float(prob["r"])


def plant(prob):
    """The plant (x, u, w) -> f(x, u) + w in numpy (the same model as :func:`dynamics`), for the closed loop."""
    dt = prob["dt"]
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
