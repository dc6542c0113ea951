"""Benchmark 3: nonlinear receding-horizon control in closed loop, SQP against IPOPT.

``orrc.simulate`` over T = 200 steps of Algorithm 1 on three problems, so that the speed is not
tuned to one of them:

* the pendulum of benchmark 1 (``orrc.examples.inverted_pendulum()``, M = 20, |u| <= 20) from
  (0.5, 0) under a disturbance drawn from a ball (radius 0.02); target: the whole run
  under 0.1 s of ``orrc.simulate`` CPU time (one BLAS thread; the wall time beside it);
* the Van der Pol oscillator (``orrc.examples.van_der_pol()``, M = 15, |u| <= 5) from (1.5, 0),
  disturbance radius 0.05;
* a non-convex, time-varying cost on the pendulum: c_t(x, u) = p_t (1 − cos θ) + ω² + 0.1 u² with
  p_t = 20 (1 + 0.5 sin(t/7)) previewed M = 20 steps ahead, from θ = 2.5 rad (the pendulum swings
  through the region where the cost's curvature cos θ is negative).

Each problem is run with ``PreviewRHC``'s default NLP path (SQP, IPOPT as the fallback) and, in the
same run and interleaved with it, with ``solver="ipopt"`` (the default solver of earlier releases). The check:
both runs reach the same closed loop (total cost to 1e-6 relative), no step fails, and the table says
how many steps each solver produced (where SQP fell back to IPOPT). Reported beside it: what the
warm start from the shifted plan buys, each step of the run re-solved from a cold start at the same
state (iterations and solve time per step).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

import orrc

from .common import CheckFailed, Row, fmt_time, timed, wall_median

TARGET_SECONDS = 0.1  # the pendulum, T = 200, M = 20
SAME_RTOL = 1e-6


def nonconvex_cost() -> orrc.Cost:
    """c(x, u; p) = p (1 − cos θ) + ω² + 0.1 u²: non-convex in θ, time-varying through p."""
    return orrc.Cost(lambda x, u, p: p[0] * (1 - ca.cos(x[0])) + x[1] ** 2 + 0.1 * u[0] ** 2,
                     n=2, m=1, n_params=1, default_params=[20.0], name="p (1 - cos θ) + ω² + 0.1 u²")


def problems(T: int):
    """(name, system, cost, M, input bounds, x0, w, cost sequence or None) of the three problems."""
    pend = orrc.examples.inverted_pendulum()
    vdp = orrc.examples.van_der_pol()
    nc = nonconvex_cost()
    p = 20 * (1 + 0.5 * np.sin(np.arange(T + 20) / 7.0))
    return [
        ("pendulum", pend.system, pend.cost, 20, pend.input_bounds, pend.x0,
         orrc.disturbances.uniform_ball(T + 20, 2, radius=0.02, seed=0), None),
        ("Van der Pol", vdp.system, vdp.cost, 15, vdp.input_bounds, vdp.x0,
         orrc.disturbances.uniform_ball(T + 15, 2, radius=0.05, seed=1), None),
        ("non-convex time-varying cost", pend.system, nc, 20, pend.input_bounds, np.array([2.5, 0.0]),
         orrc.disturbances.uniform_ball(T + 20, 2, radius=0.02, seed=0), orrc.CostSequence(nc, p[:, None])),
    ]


def _steps(traj, solver: str) -> str:
    t = [i for i, s in enumerate(traj.solver) if s == solver]
    return "" if not t else " (t = " + ", ".join(map(str, t[:8])) + (", ..." if len(t) > 8 else "") + ")"


def run(T: int = 200, reps: int = 7, reps_ipopt: int = 3) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if SQP's closed loop is not IPOPT's."""
    rows = []
    for name, system, cost, M, bounds, x0, w, seq in problems(T):
        rhc = orrc.PreviewRHC(system, cost, M, input_bounds=bounds)
        rhc_ip = orrc.PreviewRHC(system, cost, M, input_bounds=bounds, solver="ipopt")
        t_sqp, t_ip = [], []
        for i in range(max(reps, reps_ipopt)):  # interleaved: a load change hits both alike
            if i < reps:
                traj, t = timed(orrc.simulate, system, rhc, x0, w, T, costs=seq)
                t_sqp.append(t)
            if i < reps_ipopt:
                ref, t = timed(orrc.simulate, system, rhc_ip, x0, w, T, costs=seq)
                t_ip.append(t)
        ts, ti = float(np.median(t_sqp)), float(np.median(t_ip))
        J, J_ip = traj.costs.sum(), ref.costs.sum()
        gap = (J - J_ip) / abs(J_ip)
        if traj.n_failures or ref.n_failures or abs(gap) > SAME_RTOL:
            raise CheckFailed(f"closed loop, {name}: SQP's run (cost {J:.10g}, {traj.n_failures} failed steps) is not "
                              f"IPOPT's (cost {J_ip:.10g}, {ref.n_failures} failed steps; rel. gap {gap:.2e})")
        counts = traj.solver_counts
        n_sqp, n_ip = counts.get("sqp", 0), counts.get("ipopt", 0)
        target = name == "pendulum"
        bench = f"closed loop T={T}, M={M}, {name}"
        check = (f"steps by solver: SQP {n_sqp}, IPOPT {n_ip}{_steps(traj, 'ipopt')}; total cost {J:.6f}, "
                 f"IPOPT alone rel. gap {gap:+.1e}")
        rows.append(Row(bench, "orrc.simulate, default (SQP, IPOPT fallback); CPU (wall)",
                        f"{fmt_time(ts)} ({fmt_time(wall_median(t_sqp))})",
                        f"{fmt_time(ti)} (solver='ipopt')", f"{ti / ts:.0f}× faster than IPOPT",
                        f"< {TARGET_SECONDS * 1e3:.0f} ms" if target else "—", (ts < TARGET_SECONDS) if target else None,
                        check, dict(t_sqp=ts, t_ipopt=ti, n_sqp=n_sqp, n_ipopt=n_ip, gap=gap)))
        # what the warm start buys: each step re-solved cold at the same state (the controller's own plan)
        cold = [rhc.plan(traj.x[t], traj.w_all[t:t + M], None if seq is None else seq.window(t, M))
                for t in range(T)]
        it_c, tm_c = np.mean([p.iterations for p in cold]), float(np.median([p.solve_time for p in cold]))
        it_w, tm_w = float(traj.iterations.mean()), float(np.median(traj.solve_times))
        if not all(p.success for p in cold) or np.abs(traj.values - [p.value for p in cold]).max() > \
                SAME_RTOL * np.abs(traj.values).max():
            raise CheckFailed(f"closed loop, {name}: a cold re-solve does not reach the warm-started step's optimum")
        rows.append(Row(bench + ", warm vs cold", "each step re-solved cold at the same state",
                        f"{fmt_time(tm_w)}/step ({it_w:.2f} it.)", f"{fmt_time(tm_c)}/step ({it_c:.2f} it.) cold",
                        f"{tm_c / tm_w:.2f}× per step", "—", None,
                        f"IPOPT alone: {ref.iterations.mean():.2f} it./step, {fmt_time(float(np.median(ref.solve_times)))}/step",
                        dict(it_warm=it_w, it_cold=float(it_c), t_warm=tm_w, t_cold=tm_c)))
    return rows
