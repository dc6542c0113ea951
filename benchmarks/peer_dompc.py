"""do-mpc on the closed loop of ``benchmarks/peers.py`` (run in do-mpc's own environment).

Reads the problem (JSON) on stdin, runs the closed loop ``argv[1]`` times, prints one JSON line:
the inputs of the last run, the median CPU and wall seconds of a run, do-mpc's version and the
BLAS pools threadpoolctl sees. Only numpy, casadi and do-mpc: nothing of orrc.
"""
import json
import sys
import time

import casadi as ca
import do_mpc
import numpy as np
from peer_models import dynamics, n_inputs, n_states, plant, weights
from threadpoolctl import threadpool_info


def build(prob):
    M, dt, n, nu = prob["M"], prob["dt"], n_states(prob), n_inputs(prob)
    umax = np.broadcast_to(np.asarray(prob["u_max"], float), (nu,)).reshape(-1, 1)
    q, r = weights(prob)
    model = do_mpc.model.Model("discrete")
    x = model.set_variable("_x", "x", shape=(n, 1))
    u = model.set_variable("_u", "u", shape=(nu, 1))
    w = model.set_variable("_tvp", "w", shape=(n, 1))
    model.set_rhs("x", dynamics(prob, x, u, w))
    model.setup()
    mpc = do_mpc.controller.MPC(model)
    mpc.settings.n_horizon, mpc.settings.t_step = M, dt
    mpc.settings.store_full_solution = False
    mpc.settings.nlpsol_opts = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": 0, "ipopt.tol": 1e-10}
    mpc.set_objective(mterm=0 * x[0], lterm=ca.dot(ca.DM(q), x ** 2) + ca.dot(ca.DM(r), u ** 2))
    mpc.bounds["lower", "_u", "u"], mpc.bounds["upper", "_u", "u"] = -umax, umax
    W = np.array(prob["w"])
    tvp = mpc.get_tvp_template()

    def tvp_fun(t_now):
        k0 = int(round(float(np.asarray(t_now).reshape(-1)[0]) / dt))
        for k in range(M + 1):
            tvp["_tvp", k, "w"] = W[k0 + k] if k0 + k < len(W) else np.zeros(n)
        return tvp

    mpc.set_tvp_fun(tvp_fun)
    mpc.setup()
    return mpc, W


def closed_loop(prob):
    mpc, W = build(prob)
    T, step, nu = prob["T"], plant(prob), n_inputs(prob)
    x = np.array(prob["x0"], float)
    mpc.x0 = x.reshape(-1, 1)
    mpc.set_initial_guess()
    U = []
    c0, t0 = time.process_time(), time.perf_counter()
    for t in range(T):
        u = np.asarray(mpc.make_step(x.reshape(-1, 1)), float).reshape(-1)
        U.append(u.tolist() if nu > 1 else float(u[0]))
        x = step(x, u, W[t])
    return U, time.process_time() - c0, time.perf_counter() - t0


def main():
    prob = json.loads(sys.stdin.read())
    runs = [closed_loop(prob) for _ in range(int(sys.argv[1]))]
    pools = ", ".join(sorted({f"{i['internal_api']}: {i['num_threads']}" for i in threadpool_info()})) or "none loaded"
    print(json.dumps(dict(U=runs[-1][0], cpu=float(np.median([r[1] for r in runs])),
                          wall=float(np.median([r[2] for r in runs])), version=do_mpc.__version__, threads=pools)))


if __name__ == "__main__":
    main()
