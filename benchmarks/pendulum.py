"""Benchmark 1 (issue 2, "Performance"): one receding-horizon step on the nonlinear pendulum.

The problem (Eq. 3 of the paper for ``orrc.examples.inverted_pendulum()``), M = 20, |u| <= 20:

    min_{u_0..u_{M-1}}  Σ_{j<M} 10 θ_j² + ω_j² + 0.1 u_j²      (no terminal cost)
    s.t.  θ_{j+1} = θ_j + dt ω_j + w_j[0],
          ω_{j+1} = ω_j + dt (g/l sin θ_j − friction ω_j + u_j) + w_j[1],   (θ_0, ω_0) = x.

solved by

* orrc: ``PreviewRHC(...).plan(x, W)`` (CasADi multiple shooting + IPOPT, exact
  derivatives), cold-started (zero inputs, the state held over the horizon);
* python-control 0.10.2: ``control.optimal.solve_ocp`` on a discrete-time
  ``NonlinearIOSystem`` (dt = 0.05) whose update function is the same model written
  in numpy with the previewed disturbance folded in (w_k picked by the time index
  k = t/dt), the same input bounds (``input_range_constraint``), the time points
  0, dt, ..., M dt (python-control sums the cost over the first M of them), the
  default cold start (zero inputs) and ``minimize_method='SLSQP'`` (scipy's choice
  for a constrained problem anyway; it needed no other option to reach the optimum).

Both input sequences are evaluated by one independent numpy rollout of the cost
(:func:`rollout`), and the values must agree within 1e-4 relative. The target
is orrc's cold step at least 50× faster (median over repetitions, same run). The
warm-started orrc step (the next RHC step, warm-started from the shifted plan) and
the one-off build time of the CasADi solver are reported separately.
"""
from __future__ import annotations

import numpy as np

import orrc

from .common import CheckFailed, Row, fmt_time, timed

DT, G_OVER_L, FRICTION, U_MAX = 0.05, 9.81, 0.1, 20.0
Q_THETA, Q_OMEGA, R_U = 10.0, 1.0, 0.1
TARGET_SPEEDUP = 50.0
VALUE_RTOL = 1e-4


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


def run(M: int = 20, thetas=(0.2, 0.5, 1.0), reps_orrc: int = 21, reps_peer: int = 5) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the two solvers disagree."""
    ex = orrc.examples.inverted_pendulum(dt=DT, g_over_l=G_OVER_L, friction=FRICTION, u_max=U_MAX)
    _check_model(ex)
    W_all = preview(M)
    W = W_all[:M]
    builds = []
    for _ in range(3):
        rhc, t_build = timed(orrc.PreviewRHC, ex.system, ex.cost, M, input_bounds=ex.input_bounds)
        builds.append(t_build)
    bench = f"pendulum M={M}"
    rows = []
    for theta in thetas:
        x0 = np.array([theta, 0.0])
        cold = [timed(rhc.plan, x0, W) for _ in range(reps_orrc)]
        plan = cold[-1][0]
        t_orrc = float(np.median([t for _, t in cold]))
        peer = [timed(solve_ocp, x0, W, M) for _ in range(reps_peer)]
        (U_ct, res), t_peer = peer[-1][0], float(np.median([t for _, t in peer]))
        # the referee: one independent rollout for both answers
        (_, J_orrc), (X_ref, J_ct) = rollout(x0, plan.inputs, W), rollout(x0, U_ct, W)
        gap = (J_ct - J_orrc) / abs(J_orrc)
        viol = max(0.0, float(np.abs(U_ct).max() - U_MAX), float(np.abs(plan.inputs).max() - U_MAX))
        X_ct = np.asarray(res.states)
        problems = []
        if not (plan.success and res.success):
            problems.append(f"solver failure (orrc {plan.status!r}, solve_ocp {res.message!r})")
        if abs(gap) > VALUE_RTOL:
            problems.append(f"values differ: orrc {J_orrc:.8g}, solve_ocp {J_ct:.8g} (rel. gap {gap:.2e})")
        if abs(plan.value - J_orrc) > 1e-8 * max(1.0, abs(J_orrc)):
            problems.append(f"orrc's reported V_M {plan.value:.10g} != its rollout {J_orrc:.10g}")
        if np.abs(X_ct.T - X_ref).max() > 1e-9:
            problems.append("python-control's state trajectory is not the numpy rollout "
                            "(the disturbance was not folded in as intended)")
        if viol > 1e-6:
            problems.append(f"an input bound is violated by {viol:.2e}")
        if problems:
            raise CheckFailed(f"{bench}, θ0={theta:g}: " + "; ".join(problems))
        speedup = t_peer / t_orrc
        check = (f"J: orrc {J_orrc:.6f}, solve_ocp {J_ct:.6f}, rel. gap {gap:+.1e} "
                 f"(IPOPT {plan.iterations} it., SLSQP {res.problem.cost_evaluations} cost evals)")
        rows.append(Row(bench + ", one RHC step, cold", f"θ0={theta:g}", fmt_time(t_orrc),
                        f"{fmt_time(t_peer)} (solve_ocp)", f"{speedup:.0f}× faster",
                        f"≥ {TARGET_SPEEDUP:.0f}×", speedup >= TARGET_SPEEDUP, check,
                        dict(theta0=theta, t_orrc=t_orrc, t_peer=t_peer, J_orrc=J_orrc, J_peer=J_ct,
                             gap=gap, speedup=speedup)))
        # the next RHC step, warm-started from the shifted plan (what the controller does)
        x1 = step(x0, plan.inputs[0], W[0])
        W1 = W_all[1:M + 1]
        warm = [timed(rhc.plan, x1, W1, warm_start=plan) for _ in range(reps_orrc)]
        wplan, t_warm = warm[-1][0], float(np.median([t for _, t in warm]))
        J_warm_cold = rollout(x1, rhc.plan(x1, W1).inputs, W1)[1]
        J_warm = rollout(x1, wplan.inputs, W1)[1]
        if not wplan.success or abs(J_warm - J_warm_cold) > VALUE_RTOL * abs(J_warm_cold):
            raise CheckFailed(f"{bench}, θ0={theta:g}: the warm-started step ({J_warm:.8g}, "
                              f"{wplan.status}) differs from a cold solve ({J_warm_cold:.8g})")
        rows.append(Row(bench + ", next step, warm-started", f"θ0={theta:g}", fmt_time(t_warm), "—",
                        f"{t_peer / t_warm:.0f}× vs cold solve_ocp", "—", None,
                        f"same optimum as a cold solve (IPOPT {wplan.iterations} it.)",
                        dict(theta0=theta, t_warm=t_warm)))
    t_build = float(np.median(builds))
    incl = [r.data["t_peer"] / (r.data["t_orrc"] + t_build) for r in rows if r.ok is not None]
    rows.append(Row(bench + ", solver build (once per controller)", "—", fmt_time(t_build), "—",
                    f"build + cold step: {min(incl):.0f}–{max(incl):.0f}× faster than solve_ocp", "—", None,
                    "PreviewRHC(...) construction: CasADi transcription + nlpsol",
                    dict(t_build=t_build, speedup_incl_build=incl)))
    return rows
