"""Benchmark: does a structure-exploiting QP solver pay inside CasADi's SQP, and at which horizon?

CasADi's ``sqpmethod`` solves one QP per iteration; the pinned wheel ships, besides the general sparse
``qrqp`` that orrc uses, the Riccati-based interior-point solver HPIPM (``casadi.has_conic("hpipm")``) and
FATROP. HPIPM needs the variables of the NLP in the stage order of an optimal control problem (u_0, x_1,
u_1, x_2, ...; CasADi's interface checks the sparsity against the stage dimensions it is given), which
orrc's transcription ([vec U; vec X], ``orrc.solvers.nlp.ShootingNLP``) is not. So this benchmark builds
the pendulum's M-step problem of ``benchmarks/peers.py`` in stage order by hand, and runs the same closed
loop (T steps, warm-started from the shifted solution, the exact Hessian convexified by ``eigen-clip``,
tolerances 1e-8 as orrc's) with ``qpsol="qrqp"`` and with ``qpsol="hpipm"``, interleaved, for M in {10,
20, 50, 100, 200}. The closed-loop costs (the numpy referee of ``benchmarks/pendulum.py``) must agree to
1e-6 relative. Beside it, orrc's own NLP with ``sqpmethod.qpsol="fatrop"`` (FATROP detects the structure
itself; orrc's ordering is accepted): its time and how many steps fell back to IPOPT.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

import orrc

from . import peers, pendulum
from .common import CheckFailed, Row, cpu_and_wall, fmt_time

HORIZONS = (10, 20, 50, 100, 200)
SAME_RTOL = 1e-6
_QRQP = {"print_iter": False, "print_header": False, "print_info": False, "error_on_fail": False}


def stage_ordered_solver(M: int, qpsol: str):
    """CasADi's SQP on the pendulum's M-step problem with the variables in stage order (u_j, x_{j+1}),
    QP solver ``qpsol`` ("qrqp" or "hpipm"); returns (solver, lbz, ubz)."""
    dt, gl, fr, umax = pendulum.DT, pendulum.G_OVER_L, pendulum.FRICTION, pendulum.U_MAX
    x0, W = ca.SX.sym("x0", 2), ca.SX.sym("W", 2, M)
    z, g, J, lb, ub, xj = [], [], 0, [], [], x0
    for j in range(M):
        u, xn = ca.SX.sym(f"u{j}"), ca.SX.sym(f"x{j + 1}", 2)
        z += [u, xn]
        lb += [-umax, -np.inf, -np.inf]
        ub += [umax, np.inf, np.inf]
        J += pendulum.Q_THETA * xj[0] ** 2 + pendulum.Q_OMEGA * xj[1] ** 2 + pendulum.R_U * u ** 2
        g.append(ca.vertcat(xj[0] + dt * xj[1], xj[1] + dt * (gl * ca.sin(xj[0]) - fr * xj[1] + u)) + W[:, j] - xn)
        xj = xn
    qp_opts = dict(_QRQP) if qpsol == "qrqp" else dict(N=M, nx=[0] + [2] * M, nu=[1] * M + [0], ng=[0] * (M + 1),
                                                       error_on_fail=False)
    opts = dict(qpsol=qpsol, qpsol_options=qp_opts, hessian_approximation="exact", convexify_strategy="eigen-clip",
                tol_pr=1e-8, tol_du=1e-8, max_iter=50, print_header=False, print_iteration=False, print_status=False,
                print_time=False)
    prob = {"x": ca.vertcat(*z), "f": J, "g": ca.vertcat(*g), "p": ca.vertcat(x0, ca.vec(W))}
    return ca.nlpsol(f"stage_{qpsol}", "sqpmethod", prob, opts), np.array(lb), np.array(ub)


def closed_loop(solver, lbz, ubz, x0, w, T: int, M: int):
    """The warm-started closed loop of the stage-ordered solver: (U (T, 1), iterations per step)."""
    x = np.asarray(x0, float)
    z = np.tile(np.concatenate([[0.0], x]), M)
    U, its = np.empty((T, 1)), []
    for t in range(T):
        r = solver(x0=z, p=np.concatenate([x, w[t:t + M].reshape(-1)]), lbx=lbz, ubx=ubz, lbg=0, ubg=0)
        st = solver.stats()
        if not st["success"]:
            raise CheckFailed(f"SQP with {solver.name()} failed at t={t}: {st['return_status']}")
        its.append(st["iter_count"])
        zz = np.asarray(r["x"]).reshape(-1)
        U[t] = zz[0]
        z = np.concatenate([zz[3:], zz[-3:]])   # shifted by one stage
        x = pendulum.step(x, U[t], w[t])
    return U, float(np.mean(its))


def run(T: int = 100, Ms=HORIZONS, reps: int = 3, fatrop: bool = True) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the QP solvers' closed loops differ."""
    rows, bench = [], f"structure: SQP's QP solver, pendulum closed loop T={T} (per step, CPU)"
    for M in Ms:
        prob = peers.problem(T, M)
        x0, w = np.asarray(prob["x0"]), np.asarray(prob["w"])
        solvers = {q: stage_ordered_solver(M, q) for q in ("qrqp", "hpipm")}
        times, out = {q: [] for q in solvers}, {}
        for _ in range(reps):   # interleaved
            for q, (S, lb, ub) in solvers.items():
                out[q], c, _ = cpu_and_wall(closed_loop, S, lb, ub, x0, w, T, M)
                times[q].append(c / T)
        (Xq, Jq), (Xh, Jh) = (peers.closed_loop_cost(x0, out[q][0], w[:T]) for q in ("qrqp", "hpipm"))
        gap = (Jh - Jq) / abs(Jq)
        if abs(gap) > SAME_RTOL or np.abs(Xh - Xq).max() > 1e-6:
            raise CheckFailed(f"structure M={M}: HPIPM's closed loop (cost {Jh:.10g}) is not qrqp's ({Jq:.10g})")
        tq, th = float(np.median(times["qrqp"])), float(np.median(times["hpipm"]))
        rows.append(Row(bench, f"M={M}: stage order, qrqp vs hpipm", fmt_time(tq), f"{fmt_time(th)} (hpipm)",
                        f"hpipm {tq / th:.2f}× faster" if th < tq else f"hpipm {th / tq:.2f}× slower", "—", None,
                        f"same closed loop (rel. cost gap {gap:+.1e}); SQP it./step qrqp {out['qrqp'][1]:.2f}, "
                        f"hpipm {out['hpipm'][1]:.2f}",
                        dict(M=M, t_qrqp=tq, t_hpipm=th, gap=gap)))
    if fatrop:
        M = Ms[len(Ms) // 2]
        prob = peers.problem(T, M)
        ex = orrc.examples.inverted_pendulum()
        x0, w = np.asarray(prob["x0"]), np.asarray(prob["w"])
        res = {}
        for name, opts in (("qrqp", None), ("fatrop", {"sqpmethod.qpsol": "fatrop"})):
            rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, solver_options=opts)
            traj, c, _ = cpu_and_wall(orrc.simulate, ex.system, rhc, x0, w, T)
            res[name] = (c / T, dict(traj.solver_counts), traj.costs.sum())
        gap = (res["fatrop"][2] - res["qrqp"][2]) / abs(res["qrqp"][2])
        rows.append(Row(bench, f"M={M}: orrc's NLP, qrqp vs fatrop", fmt_time(res["qrqp"][0]),
                        f"{fmt_time(res['fatrop'][0])} (fatrop)", f"fatrop {res['fatrop'][0] / res['qrqp'][0]:.0f}× slower"
                        if res["fatrop"][0] > res["qrqp"][0] else f"fatrop {res['qrqp'][0] / res['fatrop'][0]:.2f}× faster",
                        "—", None, f"steps by solver: qrqp {res['qrqp'][1]}, fatrop {res['fatrop'][1]} (IPOPT: the "
                        f"fallback where SQP failed); rel. cost gap {gap:+.1e}",
                        dict(M=M, t_qrqp=res["qrqp"][0], t_fatrop=res["fatrop"][0], counts=res["fatrop"][1], gap=gap)))
    return rows
