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
from threadpoolctl import threadpool_info  # noqa: E402


def build(prob, where):
    dt, gl, fr, umax, (qt, qo), r, M = (prob[k] for k in ("dt", "g_over_l", "friction", "u_max", "q", "r", "M"))
    x, u, w = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("w", 2)
    model = AcadosModel()
    model.name, model.x, model.u, model.p = "pendulum", x, u, w
    model.disc_dyn_expr = ca.vertcat(x[0] + dt * x[1], x[1] + dt * (gl * ca.sin(x[0]) - fr * x[1] + u[0])) + w
    ocp = AcadosOcp()
    ocp.model = model
    ocp.dims.N = M
    ocp.parameter_values = np.zeros(2)
    ocp.cost.cost_type, ocp.cost.cost_type_e = "LINEAR_LS", "LINEAR_LS"
    ocp.cost.Vx, ocp.cost.Vu = np.vstack([np.eye(2), np.zeros((1, 2))]), np.array([[0.0], [0.0], [1.0]])
    ocp.cost.W, ocp.cost.yref = 2 * np.diag([qt, qo, r]), np.zeros(3)   # acados: ½‖y‖²_W
    ocp.cost.Vx_e, ocp.cost.W_e, ocp.cost.yref_e = np.eye(2), np.zeros((2, 2)), np.zeros(2)  # no terminal cost
    ocp.constraints.x0 = np.array(prob["x0"], float)
    ocp.constraints.lbu, ocp.constraints.ubu, ocp.constraints.idxbu = np.array([-umax]), np.array([umax]), np.array([0])
    opts = ocp.solver_options
    opts.tf, opts.integrator_type, opts.nlp_solver_type = M * dt, "DISCRETE", "SQP"
    opts.hessian_approx, opts.qp_solver = "GAUSS_NEWTON", "PARTIAL_CONDENSING_HPIPM"
    opts.nlp_solver_max_iter, opts.qp_solver_iter_max = 200, 100
    opts.nlp_solver_tol_stat = opts.nlp_solver_tol_eq = opts.nlp_solver_tol_ineq = opts.nlp_solver_tol_comp = 1e-10
    opts.print_level = 0
    ocp.code_export_directory = os.path.join(where, "c_generated_code")
    return AcadosOcpSolver(ocp, json_file=os.path.join(where, "acados_ocp.json"), verbose=False)


def closed_loop(solver, prob):
    dt, gl, fr, T, M = prob["dt"], prob["g_over_l"], prob["friction"], prob["T"], prob["M"]
    W = np.array(prob["w"])
    x = np.array(prob["x0"], float)
    for k in range(M + 1):  # a cold start: zero inputs, the state held
        solver.set(k, "x", x)
        if k < M:
            solver.set(k, "u", np.zeros(1))
    U = []
    c0, t0 = time.process_time(), time.perf_counter()
    for t in range(T):
        solver.set(0, "lbx", x)
        solver.set(0, "ubx", x)
        for k in range(M):
            solver.set(k, "p", W[t + k])
        status = solver.solve()
        if status != 0:
            raise RuntimeError(f"acados failed at t={t} with status {status}")
        u = float(solver.get(0, "u")[0])
        U.append(u)
        x = np.array([x[0] + dt * x[1], x[1] + dt * (gl * np.sin(x[0]) - fr * x[1] + u)]) + W[t]
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
