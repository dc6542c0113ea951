"""Benchmark 1: one receding-horizon step on the nonlinear pendulum.

The problem (Eq. 3 of the paper for ``orrc.examples.inverted_pendulum()``), M = 20, |u| <= 20:

    min_{u_0..u_{M-1}}  Σ_{j<M} 10 θ_j² + ω_j² + 0.1 u_j²      (no terminal cost)
    s.t.  θ_{j+1} = θ_j + dt ω_j + w_j[0],
          ω_{j+1} = ω_j + dt (g/l sin θ_j − friction ω_j + u_j) + w_j[1],   (θ_0, ω_0) = x.

solved by

* orrc: ``PreviewRHC(...).plan(x, W)`` on its default NLP path: CasADi multiple shooting solved by
  SQP (CasADi's ``sqpmethod`` with the QP solver ``qrqp``, exact derivatives; the NLP's functions and
  the acceptance checks compiled, ``orrc._jit``, as a controller does by itself after some solves),
  cold-started (zero inputs, the state held over the horizon); and, in the same run, the same problem with
  ``solver="ipopt"`` (IPOPT, the fallback rung and the default solver of earlier releases);
* python-control 0.10.2: ``control.optimal.solve_ocp`` on a discrete-time
  ``NonlinearIOSystem`` (dt = 0.05) whose update function is the same model written
  in numpy with the previewed disturbance folded in (w_k picked by the time index
  k = t/dt), the same input bounds (``input_range_constraint``), the time points
  0, dt, ..., M dt (python-control sums the cost over the first M of them), the
  default cold start (zero inputs) and ``minimize_method='SLSQP'`` (scipy's choice
  for a constrained problem anyway; it needed no other option to reach the optimum).

Times are CPU time (``process_time``) with one BLAS thread (``benchmarks/run.py``), the wall time
beside the target's. All input sequences are evaluated by one independent numpy rollout of the cost
(:func:`rollout`): orrc's SQP and IPOPT answers must agree to 1e-6 relative, and
solve_ocp's to 1e-4 (SLSQP with finite differences; measured 4e-10 to 5e-8). The target
is orrc's cold step at least 1000× faster than solve_ocp (median over repetitions,
same run). Reported beside it: IPOPT's cold step, the next RHC step
warm-started from the shifted plan against a cold solve of that same step (time and
iterations, SQP and IPOPT), and the one-off build of the CasADi solvers.
"""
from __future__ import annotations

import numpy as np

import orrc

from .common import CheckFailed, Row, Seconds, fmt_time, timed, wall_median

DT, G_OVER_L, FRICTION, U_MAX = 0.05, 9.81, 0.1, 20.0
Q_THETA, Q_OMEGA, R_U = 10.0, 1.0, 0.1
TARGET_SPEEDUP = 1000.0
VALUE_RTOL = 1e-4   # orrc against solve_ocp (SLSQP, finite differences)
SAME_RTOL = 1e-6    # orrc's SQP against its IPOPT


def step(x, u, w):
    """The pendulum update in numpy (independent of orrc's CasADi model; cross-checked)."""
    return np.array([x[0] + DT * x[1],
                     x[1] + DT * (G_OVER_L * np.sin(x[0]) - FRICTION * x[1] + u[0])]) + w


def stage_cost(x, u):
    return Q_THETA * x[0] ** 2 + Q_OMEGA * x[1] ** 2 + R_U * u[0] ** 2


def rollout(x0, U, W):
    """The states x_0..x_M (M+1, 2) and the cost Σ_{j<M} c(x_j, u_j) of inputs U (M, 1) under
    W (M, 2): the independent referee of both solvers' answers."""
    X = np.empty((len(U) + 1, 2))
    X[0] = x0
    total = 0.0
    for j, (u, w) in enumerate(zip(U, W)):
        total += stage_cost(X[j], u)
        X[j + 1] = step(X[j], u, w)
    return X, float(total)


def preview(M: int) -> np.ndarray:
    """The previewed disturbance: M + 1 rows (the warm-started second step needs one more)."""
    return orrc.disturbances.sinusoid(M + 1, 2, amplitude=0.02, period=15.0)


def _check_model(ex) -> None:
    rng = np.random.default_rng(0)
    for _ in range(5):
        x, u, w = rng.uniform(-2, 2, 2), rng.uniform(-20, 20, 1), rng.uniform(-0.1, 0.1, 2)
        err = np.abs(ex.system.step(x, u, w) - step(x, u, w)).max()
        if err > 1e-12:
            raise CheckFailed(f"the numpy pendulum differs from orrc's model by {err:.3g}")


def solve_ocp(x0, W, M: int):
    """Solve the same M-step problem with python-control; returns (U (M, 1), result)."""
    import control
    import control.optimal as opt

    def updfcn(t, x, u, params):
        k = int(round(t / DT))
        return step(x, u, W[k] if k < M else np.zeros(2))

    sys = control.NonlinearIOSystem(updfcn, None, inputs=1, states=2, dt=DT, name="pendulum")
    timepts = DT * np.arange(M + 1)
    res = opt.solve_ocp(sys, timepts, x0, stage_cost,
                        [opt.input_range_constraint(sys, [-U_MAX], [U_MAX])],
                        minimize_method="SLSQP", squeeze=False, print_summary=False)
    U = np.asarray(res.inputs)[0, :M].reshape(M, 1)
    return U, res


def _median_times(calls: dict, reps: dict) -> dict:
    """{name: (last result, median seconds)} of timed calls ``calls[name]()`` (zero-argument), repeated
    ``reps[name]`` times and interleaved round by round, so that a change of load on the machine hits
    every one of them alike."""
    times = {k: [] for k in calls}
    last = {}
    for i in range(max(reps.values())):
        for k, fn in calls.items():
            if i < reps[k]:
                last[k], t = timed(fn)
                times[k].append(t)
    return {k: (last[k], Seconds(float(np.median(times[k])), wall_median(times[k]))) for k in calls}


def run(M: int = 20, thetas=(0.2, 0.5, 1.0), reps_orrc: int = 21, reps_peer: int = 5) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the solvers disagree."""
    ex = orrc.examples.inverted_pendulum(dt=DT, g_over_l=G_OVER_L, friction=FRICTION, u_max=U_MAX)
    _check_model(ex)
    W_all = preview(M)
    W = W_all[:M]
    builds = []
    for _ in range(3):
        rhc, t_build = timed(orrc.PreviewRHC, ex.system, ex.cost, M, input_bounds=ex.input_bounds)
        builds.append(t_build)
    # the SQP solver and checks compiled (orrc._jit; what a controller does by itself after some solves):
    # asked for before the timed solves, a one-off cached per machine, reported with the build
    compiled, t_compile = timed(rhc.compile, wait=True)
    rhc_ip = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds, solver="ipopt")
    bench = f"pendulum M={M}"
    rows = []
    for theta in thetas:
        x0 = np.array([theta, 0.0])
        out = _median_times({"sqp": lambda: rhc.plan(x0, W), "ipopt": lambda: rhc_ip.plan(x0, W),
                             "peer": lambda: solve_ocp(x0, W, M)},
                            {"sqp": reps_orrc, "ipopt": max(3, reps_orrc // 3), "peer": reps_peer})
        (plan, t_orrc), (plan_ip, t_ip), ((U_ct, res), t_peer) = out["sqp"], out["ipopt"], out["peer"]
        # the referee: one independent rollout for every answer
        (_, J_orrc), (_, J_ip), (X_ref, J_ct) = (rollout(x0, plan.inputs, W), rollout(x0, plan_ip.inputs, W),
                                               rollout(x0, U_ct, W))
        gap, gap_ip = (J_ct - J_orrc) / abs(J_orrc), (J_ip - J_orrc) / abs(J_orrc)
        viol = max(0.0, float(np.abs(U_ct).max() - U_MAX), float(np.abs(plan.inputs).max() - U_MAX),
                   float(np.abs(plan_ip.inputs).max() - U_MAX))
        X_ct = np.asarray(res.states)
        problems = []
        if not (plan.success and plan_ip.success and res.success):
            problems.append(f"solver failure (orrc {plan.status!r}, IPOPT {plan_ip.status!r}, solve_ocp {res.message!r})")
        if plan.solver != "sqp":
            problems.append(f"the default path's step was not solved by SQP ({plan.solver}: {plan.status})")
        if abs(gap) > VALUE_RTOL:
            problems.append(f"values differ: orrc {J_orrc:.8g}, solve_ocp {J_ct:.8g} (rel. gap {gap:.2e})")
        if abs(gap_ip) > SAME_RTOL:
            problems.append(f"SQP and IPOPT differ: {J_orrc:.10g} vs {J_ip:.10g} (rel. gap {gap_ip:.2e})")
        for p_, J_ in ((plan, J_orrc), (plan_ip, J_ip)):
            if abs(p_.value - J_) > 1e-8 * max(1.0, abs(J_)):
                problems.append(f"orrc's reported V_M {p_.value:.10g} != its rollout {J_:.10g} ({p_.solver})")
        if np.abs(X_ct.T - X_ref).max() > 1e-9:
            problems.append("python-control's state trajectory is not the numpy rollout "
                            "(the disturbance was not folded in as intended)")
        if viol > 1e-6:
            problems.append(f"an input bound is violated by {viol:.2e}")
        if problems:
            raise CheckFailed(f"{bench}, θ0={theta:g}: " + "; ".join(problems))
        speedup = t_peer / t_orrc
        check = (f"J: orrc {J_orrc:.6f}, IPOPT rel. gap {gap_ip:+.1e}, solve_ocp {gap:+.1e} "
                 f"(SQP {plan.iterations} it., IPOPT {plan_ip.iterations} it., SLSQP {res.problem.cost_evaluations} "
                 "cost evals)")
        rows.append(Row(bench + ", one RHC step, cold (SQP); CPU (wall)", f"θ0={theta:g}",
                        f"{fmt_time(t_orrc)} ({fmt_time(t_orrc.wall)})",
                        f"{fmt_time(t_peer)} ({fmt_time(t_peer.wall)}) (solve_ocp)",
                        f"{speedup:.0f}× faster (wall {t_peer.wall / t_orrc.wall:.0f}×)",
                        f"≥ {TARGET_SPEEDUP:.0f}× (CPU)", speedup >= TARGET_SPEEDUP, check,
                        dict(theta0=theta, t_orrc=t_orrc, t_ipopt=t_ip, t_peer=t_peer, J_orrc=J_orrc, J_ipopt=J_ip,
                             J_peer=J_ct, gap=gap, gap_ipopt=gap_ip, speedup=speedup)))
        rows.append(Row(bench + ", one RHC step, cold (IPOPT)", f"θ0={theta:g}", fmt_time(t_ip),
                        f"{fmt_time(t_peer)} (solve_ocp)", f"{t_peer / t_ip:.0f}× faster", "—", None,
                        f"SQP is {t_ip / t_orrc:.0f}× faster than IPOPT on this step",
                        dict(theta0=theta, t_ipopt=t_ip, t_peer=t_peer)))
        # the next RHC step, warm-started from the shifted plan (what the controller does), against
        # a cold solve of the same step, for both solvers
        x1 = step(x0, plan.inputs[0], W[0])
        W1 = W_all[1:M + 1]
        effort = {}
        for name, r, first in (("SQP", rhc, plan), ("IPOPT", rhc_ip, plan_ip)):
            reps = reps_orrc if name == "SQP" else max(3, reps_orrc // 3)
            out = _median_times({"warm": lambda: r.plan(x1, W1, warm_start=first), "cold": lambda: r.plan(x1, W1)},
                                {"warm": reps, "cold": reps})
            (wplan, t_warm), (cplan, t_cold) = out["warm"], out["cold"]
            J_warm, J_cold = rollout(x1, wplan.inputs, W1)[1], rollout(x1, cplan.inputs, W1)[1]
            if not (wplan.success and cplan.success) or abs(J_warm - J_cold) > SAME_RTOL * abs(J_cold):
                raise CheckFailed(f"{bench}, θ0={theta:g}: the warm-started {name} step ({J_warm:.10g}, "
                                  f"{wplan.status}) differs from a cold solve ({J_cold:.10g}, {cplan.status})")
            effort[name] = (t_warm, wplan.iterations, t_cold, cplan.iterations)
        (tw, iw, tc, ic), (tw2, iw2, tc2, ic2) = effort["SQP"], effort["IPOPT"]
        rows.append(Row(bench + ", next step, warm vs cold", f"θ0={theta:g}", f"{fmt_time(tw)} ({iw} it.)",
                        f"{fmt_time(tc)} ({ic} it.) cold", f"{tc / tw:.2f}× (warm saves {ic - iw} it.)", "—", None,
                        f"IPOPT: warm {fmt_time(tw2)} ({iw2} it.), cold {fmt_time(tc2)} ({ic2} it.); same optimum",
                        dict(theta0=theta, t_warm=tw, t_cold=tc, it_warm=iw, it_cold=ic,
                             t_warm_ipopt=tw2, t_cold_ipopt=tc2, it_warm_ipopt=iw2, it_cold_ipopt=ic2)))
    t_build = float(np.median(builds))
    cold = [r for r in rows if r.ok is not None]
    incl = [r.data["t_peer"] / (r.data["t_orrc"] + t_build) for r in cold]
    rows.append(Row(bench + ", solver build (once per controller)", "—", fmt_time(t_build), "—",
                    f"build + cold step: {min(incl):.0f}–{max(incl):.0f}× faster than solve_ocp", "—", None,
                    "PreviewRHC(...) construction: CasADi transcription + SQP and IPOPT solvers; "
                    + (f"then the SQP solver and checks compiled (orrc._jit; "
                       f"{'loaded from the cache' if all(j.from_cache for j in rhc._nlp._jit.values()) else 'built'} "
                       f"in {fmt_time(t_compile.wall)} wall)"
                       if compiled else f"not compiled ({rhc.compile_error()})"),
                    dict(t_build=t_build, speedup_incl_build=incl, t_compile=t_compile, compiled=compiled)))
    return rows
