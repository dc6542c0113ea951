"""Benchmark: does a structure-exploiting QP solver pay inside CasADi's SQP, and from which horizon?

CasADi's ``sqpmethod`` solves one QP per iteration; the pinned wheel ships, besides the general sparse
``qrqp``, the Riccati-based interior-point solver HPIPM (``casadi.has_conic("hpipm")``) and FATROP. orrc's
NLP path takes HPIPM from the horizon ``orrc.solvers.nlp_solvers.HPIPM_FROM`` on (its variables then in stage
order, as HPIPM needs). This benchmark runs the pendulum's closed loop of ``benchmarks/peers.py`` (T steps,
``orrc.simulate``) with orrc's NLP and each QP solver named in ``solver_options`` (``"sqpmethod.qpsol"``),
interleaved, for M in {10, 20, 30, 50, 100, 200}: the measurement behind that threshold. The closed loops
must agree (total cost to 1e-8 relative, states to 1e-7: the same SQP iterations, QPs solved to about 1e-8
by either solver) and every step be solved by SQP. Beside it, FATROP (it detects the structure itself): its
time and how many steps fell back to IPOPT.
"""
from __future__ import annotations

import numpy as np

import orrc

from . import peers
from .common import CheckFailed, Row, cpu_and_wall, fmt_time

HORIZONS = (10, 20, 30, 50, 100, 200)
SAME_RTOL, STATE_ATOL = 1e-8, 1e-7
QP = {"qrqp": {"sqpmethod.qpsol": "qrqp",
               "sqpmethod.qpsol_options": {"print_iter": False, "print_header": False, "print_info": False}},
      # HPIPM with the options orrc gives it by itself (its speed mode: orrc.solvers.nlp_solvers)
      "hpipm": {"sqpmethod.qpsol": "hpipm", "sqpmethod.qpsol_options": {"hpipm": {"mode": "speed"}}},
      "fatrop": {"sqpmethod.qpsol": "fatrop"}}


def closed_loops(M: int, T: int, reps: int, solvers=("qrqp", "hpipm")) -> dict:
    """{QP solver: (trajectory, median CPU seconds per step)} of the pendulum's closed loop, interleaved."""
    ex = orrc.examples.inverted_pendulum()
    prob = peers.problem(T, M)
    x0, w = np.asarray(prob["x0"]), np.asarray(prob["w"])
    rhcs = {q: orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, solver_options=QP[q])
            for q in solvers}
    times, trajs = {q: [] for q in solvers}, {}
    for _ in range(reps):
        for q, rhc in rhcs.items():
            trajs[q], c, _ = cpu_and_wall(orrc.simulate, ex.system, rhc, x0, w, T)
            times[q].append(c / T)
    return {q: (trajs[q], float(np.median(times[q]))) for q in solvers}


def run(T: int = 100, Ms=HORIZONS, reps: int = 3, fatrop: bool = True) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the QP solvers' closed loops differ."""
    rows, bench = [], f"structure: SQP's QP solver, pendulum closed loop T={T} (orrc, per step, CPU)"
    for M in Ms:
        out = closed_loops(M, T, reps)
        (a, tq), (b, th) = out["qrqp"], out["hpipm"]
        gap = (b.costs.sum() - a.costs.sum()) / abs(a.costs.sum())
        if a.solver_counts != {"sqp": T} or b.solver_counts != {"sqp": T}:
            raise CheckFailed(f"structure M={M}: steps not solved by SQP (qrqp {a.solver_counts}, hpipm "
                              f"{b.solver_counts})")
        if abs(gap) > SAME_RTOL or np.abs(a.x - b.x).max() > STATE_ATOL:
            raise CheckFailed(f"structure M={M}: HPIPM's closed loop (cost {b.costs.sum():.10g}) is not qrqp's "
                              f"({a.costs.sum():.10g})")
        chosen = "hpipm" if M >= orrc.solvers.nlp_solvers.HPIPM_FROM else "qrqp"
        rows.append(Row(bench, f"M={M}: qrqp vs hpipm", fmt_time(tq), f"{fmt_time(th)} (hpipm)",
                        f"hpipm {tq / th:.2f}× faster" if th < tq else f"hpipm {th / tq:.2f}× slower", "—", None,
                        f"orrc's default at this M: {chosen}; same closed loop (rel. cost gap {gap:+.1e}); SQP it./step "
                        f"{a.iterations.mean():.2f} and {b.iterations.mean():.2f}",
                        dict(M=M, t_qrqp=tq, t_hpipm=th, gap=gap, default=chosen)))
    if fatrop:
        M = 50 if 50 in Ms else Ms[-1]
        out = closed_loops(M, T, 1, ("qrqp", "fatrop"))
        (a, tq), (f, tf) = out["qrqp"], out["fatrop"]
        gap = (f.costs.sum() - a.costs.sum()) / abs(a.costs.sum())
        rows.append(Row(bench, f"M={M}: qrqp vs fatrop", fmt_time(tq), f"{fmt_time(tf)} (fatrop)",
                        f"fatrop {tf / tq:.0f}× slower" if tf > tq else f"fatrop {tq / tf:.2f}× faster", "—", None,
                        f"steps by solver with fatrop: {dict(f.solver_counts)} (IPOPT: the fallback where SQP failed); "
                        f"rel. cost gap {gap:+.1e}",
                        dict(M=M, t_qrqp=tq, t_fatrop=tf, counts=dict(f.solver_counts), gap=gap)))
    return rows
