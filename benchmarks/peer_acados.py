"""acados on the closed loop of ``benchmarks/peers.py`` (run in acados's own environment).

SQP with the Gauss-Newton Hessian of the least-squares stage cost and the QP solver HPIPM (partial
condensing), through acados's Python API (``acados_template``: code generated and compiled once,
before the timed runs). Reads the problem (JSON) on stdin, runs the closed loop ``argv[1]`` times,
prints one JSON line: the inputs of the last run, the median CPU and wall seconds of a run, the
version and the BLAS pools threadpoolctl sees. Only numpy, casadi and acados: nothing of orrc.
"""
import json
import os
import sys
import tempfile
import time
from importlib.metadata import version

import acados
import numpy as np

os.environ.setdefault("ACADOS_SOURCE_DIR", acados.DIR)
os.environ.setdefault("ACADOS_PYTHON_INTERFACE_PATH", acados.TEMPLATE_DIR)
os.environ.setdefault("TERA_PATH", acados.TERA_PATH)

import ctypes  # noqa: E402

for _lib in ("libblasfeo.so", "libhpipm.so", "libqpOASES_e.so.3.1", "libacados.so"):  # the wheel sets no rpath
    ctypes.CDLL(os.path.join(acados.LIB_DIR, _lib), mode=ctypes.RTLD_GLOBAL)

import casadi as ca  # noqa: E402
from acados.acados_template import AcadosModel, AcadosOcp, AcadosOcpSolver  # noqa: E402
from peer_models import dynamics, n_inputs, n_states, plant, weights  # noqa: E402
from threadpoolctl import threadpool_info  # noqa: E402


def build(prob, where):
    """The acados solver of the problem: SQP (or its real-time iteration, ``prob["rti"]``), Gauss-Newton
    Hessian of the least-squares cost, HPIPM with partial condensing."""
    M, dt, n, nu = prob["M"], prob["dt"], n_states(prob), n_inputs(prob)
    umax = np.broadcast_to(np.asarray(prob["u_max"], float), (nu,))
    q, r = weights(prob)
    x, u, w = ca.SX.sym("x", n), ca.SX.sym("u", nu), ca.SX.sym("w", n)
    model = AcadosModel()
    model.name, model.x, model.u, model.p = prob.get("model", "pendulum"), x, u, w
    model.disc_dyn_expr = dynamics(prob, x, u, w)
    ocp = AcadosOcp()
    ocp.model = model
    ocp.dims.N = M
    ocp.parameter_values = np.zeros(n)
    ocp.cost.cost_type, ocp.cost.cost_type_e = "LINEAR_LS", "LINEAR_LS"
    ocp.cost.Vx, ocp.cost.Vu = np.vstack([np.eye(n), np.zeros((nu, n))]), np.vstack([np.zeros((n, nu)), np.eye(nu)])
    ocp.cost.W, ocp.cost.yref = 2 * np.diag(np.append(q, r)), np.zeros(n + nu)   # acados: ½‖y‖²_W
    ocp.cost.Vx_e, ocp.cost.W_e, ocp.cost.yref_e = np.eye(n), np.zeros((n, n)), np.zeros(n)  # no terminal cost
    ocp.constraints.x0 = np.array(prob["x0"], float)
    ocp.constraints.lbu, ocp.constraints.ubu, ocp.constraints.idxbu = -umax, umax.copy(), np.arange(nu)
    opts = ocp.solver_options
    opts.tf, opts.integrator_type = M * dt, "DISCRETE"
    opts.nlp_solver_type = "SQP_RTI" if prob.get("rti") else "SQP"
    opts.hessian_approx, opts.qp_solver = "GAUSS_NEWTON", "PARTIAL_CONDENSING_HPIPM"
    opts.nlp_solver_max_iter, opts.qp_solver_iter_max = 200, 100
    opts.nlp_solver_tol_stat = opts.nlp_solver_tol_eq = opts.nlp_solver_tol_ineq = opts.nlp_solver_tol_comp = 1e-10
    opts.print_level = 0
    ocp.code_export_directory = os.path.join(where, "c_generated_code")
    return AcadosOcpSolver(ocp, json_file=os.path.join(where, "acados_ocp.json"), verbose=False)


def closed_loop(solver, prob):
    T, M, n, nu = prob["T"], prob["M"], n_states(prob), n_inputs(prob)
    step = plant(prob)
    W = np.array(prob["w"])
    x = np.array(prob["x0"], float)
    for k in range(M + 1):  # a cold start: zero inputs, the state held
        solver.set(k, "x", x)
        if k < M:
            solver.set(k, "u", np.zeros(nu))
    U = []
    c0, t0 = time.process_time(), time.perf_counter()
    for t in range(T):
        solver.set(0, "lbx", x)
        solver.set(0, "ubx", x)
        for k in range(M):
            solver.set(k, "p", W[t + k])
        status = solver.solve()
        if status != 0 and not (prob.get("rti") and status == 2):   # RTI: one iteration, "max. iterations" is its end
            raise RuntimeError(f"acados failed at t={t} with status {status}")
        u = np.array(solver.get(0, "u"), float).reshape(-1)
        U.append(u.tolist() if nu > 1 else float(u[0]))
        x = step(x, u, W[t])
    return U, time.process_time() - c0, time.perf_counter() - t0


def main():
    prob = json.loads(sys.stdin.read())
    with tempfile.TemporaryDirectory() as where:
        cwd = os.getcwd()
        os.chdir(where)
        try:
            solver = build(prob, where)
            runs = [closed_loop(solver, prob) for _ in range(int(sys.argv[1]))]
        finally:
            os.chdir(cwd)
    pools = ", ".join(sorted({f"{i['internal_api']}: {i['num_threads']}" for i in threadpool_info()})) or "none loaded"
    print(json.dumps(dict(U=runs[-1][0], cpu=float(np.median([r[1] for r in runs])),
                          wall=float(np.median([r[2] for r in runs])),
                          version=version("comma-deps-acados"), threads=pools)))


if __name__ == "__main__":
    main()
