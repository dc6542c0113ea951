"""Benchmark 2: the exact linear-quadratic closed loop.

T = 1000 closed-loop steps of Algorithm 1 with M = 50 on ``orrc.examples.two_mass_spring()``
(n = 4, m = 1), previewed disturbances w_t drawn from a ball:

* orrc: ``orrc.simulate(system, PreviewRHC(system, cost, M), x0, w, T)`` -- the exact LQ
  path (u_t = −K x_t − L vec(w_t..w_{t+M-1}), Lemma/closed form of ``orrc.solvers.lq``),
  which also records the stage costs c_t, σ(x_t) and V_M(x_t, w_{t:t+M-1}) of every step and
  enforces the preview information pattern. The costs and V_M do not feed back: they are computed
  after the loop, V_M = z_tᵀ H z_t for all t in one matrix product (``Controller.values_batch``); and the law is affine, so the simulator takes its affine fast path
  (``Controller.fast_affine``): the feed-forward −L vec W_t of every step's own window in one
  product, then the closed loop x_{t+1} = (A − BK) x_t + (B f_t + w_t), one product per step, and
  u_t after the loop;
* a bare numpy loop with the same precomputed law (K = rhc.law.K, L = rhc.law.L) and the
  dynamics x_{t+1} = A x_t + B u_t + w_t, in three versions:
  - "floor": only the law, written directly (u = −K x − L vec W), and the dynamics --
    the least work that produces the trajectory; the target is stated against it;
  - "fused floor": the same with K and L stacked into one product (a faster floor, reported);
  - "+ bookkeeping": the floor plus c_t = x_tᵀQx_t + u_tᵀRu_t and V_M = zᵀHz,
    z = [x_t; vec W_t], in the loop, i.e. the same outputs as orrc.

All trajectories must agree to 1e-12 (and costs/values to 1e-12 relative). The target:
orrc within 1.5× of the floor loop, and well under a second (< 0.5 s).
Repetitions are interleaved (orrc, floor, fused floor, bookkeeping, orrc, ...) so that a
load change on the machine hits all of them alike; medians are reported.
"""
from __future__ import annotations

import numpy as np

import orrc
from orrc.solvers import lq

from .common import CheckFailed, Row, fmt_time, timed, wall_median

TARGET_RATIO = 1.5
TARGET_SAME_OUTPUTS = 1.0  # orrc no slower than a numpy loop producing the same outputs
TARGET_SECONDS = 0.5
ATOL = 1e-12


def bare_loop(A, B, K, L, w_all, x0, T: int, M: int):
    """The floor: u_t = −K x_t − L vec(w_t..w_{t+M-1}), x_{t+1} = A x_t + B u_t + w_t."""
    n, m = B.shape
    X = np.empty((T + 1, n))
    U = np.empty((T, m))
    X[0] = x0
    for t in range(T):
        x = X[t]
        u = -K @ x - L @ w_all[t:t + M].reshape(-1)
        U[t] = u
        X[t + 1] = A @ x + B @ u + w_all[t]
    return X, U


def bare_loop_fused(A, B, KL, w_all, x0, T: int, M: int):
    """The floor with K and L fused: u_t = −[K L] [x_t; vec W_t], one product per step."""
    n, m = B.shape
    X = np.empty((T + 1, n))
    U = np.empty((T, m))
    X[0] = x0
    for t in range(T):
        x = X[t]
        u = KL @ np.concatenate((x, w_all[t:t + M].reshape(-1)))
        U[t] = u
        X[t + 1] = A @ x + B @ u + w_all[t]
    return X, U


def bare_loop_bookkeeping(A, B, K, L, H, Q, R, w_all, x0, T: int, M: int):
    """The floor plus the stage costs and V_M(x_t, W_t) = zᵀHz at every step."""
    n, m = B.shape
    X = np.empty((T + 1, n))
    U = np.empty((T, m))
    C = np.empty(T)
    V = np.empty(T)
    X[0] = x0
    for t in range(T):
        x = X[t]
        Wv = w_all[t:t + M].reshape(-1)
        u = -K @ x - L @ Wv
        U[t] = u
        C[t] = x @ Q @ x + u @ R @ u
        z = np.concatenate((x, Wv))
        V[t] = z @ (H @ z)
        X[t + 1] = A @ x + B @ u + w_all[t]
    return X, U, C, V


def bare_loop_batch(A, B, K, L, H, Q, R, w_all, x0, T: int, M: int):
    """The floor loop, then the stage costs and V_M = zᵀHz of every step in batch after it (numpy,
    each one product over the run): the same outputs as orrc, the fastest way numpy offers."""
    X, U = bare_loop(A, B, K, L, w_all, x0, T, M)
    C = np.einsum("ti,ti->t", X[:-1] @ Q, X[:-1]) + np.einsum("ti,ti->t", U @ R, U)
    n = len(x0)
    Z = np.empty((T, n + M * n))
    Z[:, :n] = X[:-1]
    Z[:, n:] = np.lib.stride_tricks.sliding_window_view(w_all, (M, n))[:T, 0].reshape(T, M * n)
    V = np.einsum("ti,ti->t", Z @ H, Z)
    return X, U, C, V


def build(sys, cost, M: int):
    """A PreviewRHC with its LQ law built (the law is built on first use; time it here)."""
    rhc = orrc.PreviewRHC(sys, cost, M)
    rhc.law
    return rhc


def run(T: int = 1000, M: int = 50, reps: int = 15, seed: int = 0) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the loops disagree."""
    ex = orrc.examples.two_mass_spring()
    sys, cost = ex.system, ex.cost
    A, B, Q, R = sys.A, sys.B, cost.Q, cost.R
    w = orrc.disturbances.uniform_ball(T + M - 1, sys.n, radius=0.05, seed=seed)  # T+M-1 rows: all that the loops read
    builds = []
    for _ in range(3):
        rhc, t_build = timed(build, sys, cost, M)
        builds.append(t_build)
    if rhc.solver != "lq":
        raise CheckFailed(f"expected the exact LQ path, got solver {rhc.solver!r}")
    K, L, H = rhc.law.K, rhc.law.L, rhc.law.H
    KL = -np.hstack([K, L])
    t_o, t_f, t_k, t_b, t_v = [], [], [], [], []
    for _ in range(reps):
        traj, t = timed(orrc.simulate, sys, rhc, ex.x0, w, T)
        t_o.append(t)
        (Xf, Uf), t = timed(bare_loop, A, B, K, L, w, ex.x0, T, M)
        t_f.append(t)
        (Xk, Uk), t = timed(bare_loop_fused, A, B, KL, w, ex.x0, T, M)
        t_k.append(t)
        (Xb, Ub, Cb, Vb), t = timed(bare_loop_bookkeeping, A, B, K, L, H, Q, R, w, ex.x0, T, M)
        t_b.append(t)
        (Xv, Uv, Cv, Vv), t = timed(bare_loop_batch, A, B, K, L, H, Q, R, w, ex.x0, T, M)
        t_v.append(t)
    dx = max(np.abs(traj.x - Xf).max(), np.abs(traj.u - Uf).max(), np.abs(Xb - Xf).max(),
             np.abs(Xk - Xf).max(), np.abs(Xv - Xf).max())
    dc = max(np.abs(traj.costs - Cb).max(), np.abs(Cv - Cb).max()) / np.abs(Cb).max()
    dv = max(np.abs(traj.values - Vb).max(), np.abs(Vv - Vb).max()) / np.abs(Vb).max()
    if not (dx <= ATOL and dc <= ATOL and dv <= ATOL):
        raise CheckFailed(f"LQ path T={T}, M={M}: orrc and the bare loop disagree (states/inputs "
                          f"{dx:.2e}, costs {dc:.2e} rel., V_M {dv:.2e} rel.)")
    # an independent check that the trajectory is the receding-horizon one: u_0 is the
    # first input of the M-step optimum solved from scratch by the Riccati recursion
    U0 = lq.solve(A, B, np.broadcast_to(Q, (M,) + Q.shape), np.broadcast_to(R, (M,) + R.shape),
                               ex.x0, w[:M])[0][0]
    if np.abs(U0 - traj.u[0]).max() > 1e-8 * max(1.0, np.abs(U0).max()):
        raise CheckFailed(f"u_0 = {traj.u[0]} is not the first input of the M-step optimum {U0}")
    to, tf, tk, tb, tv = (float(np.median(v)) for v in (t_o, t_f, t_k, t_b, t_v))
    wo, wf, wv = wall_median(t_o), wall_median(t_f), wall_median(t_v)
    bench = f"LQ path T={T}, M={M}, n={sys.n}"
    check = f"max abs. diff. of x, u: {dx:.1e}; of c_t, V_M: {max(dc, dv):.1e} rel."
    return [
        Row(bench, "orrc.simulate vs floor loop (law + dynamics); CPU (wall)", f"{fmt_time(to)} ({fmt_time(wo)})",
            f"{fmt_time(tf)} ({fmt_time(wf)})", f"{to / tf:.2f}× the floor (wall {wo / wf:.2f}×)",
            f"≤ {TARGET_RATIO:g}×, orrc < {TARGET_SECONDS:g} s (CPU)",
            bool(to / tf <= TARGET_RATIO and to < TARGET_SECONDS), check,
            dict(t_orrc=to, t_floor=tf, ratio=to / tf, t_orrc_wall=wo, t_floor_wall=wf)),
        Row(bench, "orrc.simulate vs floor loop, K and L fused", fmt_time(to), fmt_time(tk),
            f"{to / tk:.2f}× the fused floor", "—", None, "u_t = −[K L][x_t; vec W_t]: one product per step",
            dict(t_orrc=to, t_fused=tk, ratio=to / tk)),
        Row(bench, "orrc.simulate vs floor loop + costs, V_M in batch; CPU (wall)", f"{fmt_time(to)} ({fmt_time(wo)})",
            f"{fmt_time(tv)} ({fmt_time(wv)})", f"{to / tv:.2f}× (wall {wo / wv:.2f}×)",
            f"≤ {TARGET_SAME_OUTPUTS:g}× (CPU)", bool(to / tv <= TARGET_SAME_OUTPUTS),
            "same outputs as orrc (x, u, c_t, V_M), the costs and V_M after the loop in one product each",
            dict(t_orrc=to, t_batch=tv, ratio=to / tv)),
        Row(bench, "orrc.simulate vs loop + costs + V_M at each step", fmt_time(to), fmt_time(tb),
            f"{to / tb:.2f}×", "—", None, "same outputs as orrc (x, u, c_t, V_M)",
            dict(t_orrc=to, t_book=tb, ratio=to / tb)),
        Row(bench + ", build (once per controller)", "PreviewRHC(...) and its LQPreviewLaw K, L, H",
            fmt_time(float(np.median(builds))), "—", "—", "—", None, "",
            dict(t_build=float(np.median(builds)))),
    ]
