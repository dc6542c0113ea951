"""Benchmark: the exact LQ path as the state dimension grows, against a numpy Riccati loop.

The linear chain of masses (``orrc.examples.mass_chain(k, cubic=0)`` linearised at the origin: exactly the
linear chain, n = 2k, m = 1; cost ‖p‖² + 0.1‖v‖² + 0.1u²) for n in {4, 12, 24, 50, 100}, preview M = 20, T = 200
steps under a disturbance drawn from a ball (radius 0.01), by

* orrc: ``orrc.simulate(system, PreviewRHC(system, cost, M), x0, w, T)`` (the exact LQ path: the law
  u = −K x − L vec W built once, then the closed loop; it also records the stage costs and V_M);
* a numpy Riccati loop written from the textbook, independent of orrc: the gains K_j and Riccati matrices
  P_j of the M-step problem computed once by the backward recursion (P_M = 0), then at every step the
  feed-forward of the preview by the backward recursion s_j = (A − B K_j)ᵀ(P_{j+1} w_j + s_{j+1}) and
  u = −K_0 x − (R + BᵀP_1B)⁻¹Bᵀ(P_1 w_0 + s_1), the plant x+ = A x + B u + w, and the stage cost.

Both closed loops must agree: states and inputs to 1e-9 relative to their size (two exact computations of
the same law in floating point; the Riccati matrices' condition numbers here stay below 1e4). CPU time per
step, one BLAS thread, interleaved repetitions; the build (orrc's law, the numpy gains) reported beside it.
"""
from __future__ import annotations

import numpy as np

import orrc

from .common import CheckFailed, Row, cpu_and_wall, fmt_time
from .scaling import exponent

LQ_N = (4, 12, 24, 50, 100)
RTOL = 1e-9


def linear_chain(n: int):
    """(system, cost, x0) of the linear chain with n = 2k states."""
    ex = orrc.examples.mass_chain(k=n // 2, cubic=0.0)
    A, B = ex.system.linearize()
    return orrc.LinearSystem(A, B, name=f"linear chain, n = {n}"), ex.cost, ex.x0


def riccati_gains(A, B, Q, R, M: int):
    """The backward Riccati recursion of the M-step problem (no terminal cost): per stage j < M the gain K_j,
    the closed-loop matrix (A − B K_j)ᵀ, G_j⁻¹Bᵀ and P_{j+1}."""
    n = A.shape[0]
    P = np.zeros((n, n))
    out = []
    for _ in range(M):
        G = R + B.T @ P @ B
        GiBt = np.linalg.solve(G, B.T)
        K = GiBt @ P @ A
        out.append((K, (A - B @ K).T, GiBt, P))
        P = Q + A.T @ P @ (A - B @ K)
        P = (P + P.T) / 2
    return out[::-1]   # stage 0 first


def riccati_loop(A, B, Q, R, gains, x0, w, T: int, M: int):
    """The closed loop of the numpy Riccati loop: (X (T+1, n), U (T, m), stage costs (T,))."""
    n, m = B.shape
    X, U, C = np.empty((T + 1, n)), np.empty((T, m)), np.empty(T)
    X[0] = x0
    K0, _, GiBt0, P1 = gains[0]
    for t in range(T):
        x, W = X[t], w[t:t + M]
        s = np.zeros(n)
        for j in range(M - 1, 0, -1):   # s_j = (A − B K_j)ᵀ (P_{j+1} w_j + s_{j+1})
            _, AclT, _, P = gains[j]
            s = AclT @ (P @ W[j] + s)
        u = -K0 @ x - GiBt0 @ (P1 @ W[0] + s)
        U[t], C[t] = u, x @ Q @ x + u @ R @ u
        X[t + 1] = A @ x + B @ u + W[0]
    return X, U, C


def run(ns=LQ_N, M: int = 20, T: int = 200, reps: int = 5, seed: int = 0) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if the loops disagree."""
    rows, pts = [], []
    bench = f"scaling, exact LQ path, n grows, M={M}, T={T} (closed loop per step, CPU)"
    for n in ns:
        system, cost, x0 = linear_chain(n)
        A, B, Q, R = system.A, system.B, cost.Q, cost.R
        w = orrc.disturbances.uniform_ball(T + M, n, radius=0.01, seed=seed)
        rhc, c_build, _ = cpu_and_wall(lambda: orrc.PreviewRHC(system, cost, M))
        _, c_law, _ = cpu_and_wall(lambda: rhc.law)
        gains, c_gains, _ = cpu_and_wall(riccati_gains, A, B, Q, R, M)
        if rhc.solver != "lq":
            raise CheckFailed(f"expected the exact LQ path at n={n}, got solver {rhc.solver!r}")
        t_o, t_r = [], []
        for _ in range(reps):   # interleaved
            traj, c, _ = cpu_and_wall(orrc.simulate, system, rhc, x0, w, T)
            t_o.append(c)
            (X, U, C), c, _ = cpu_and_wall(riccati_loop, A, B, Q, R, gains, x0, w, T, M)
            t_r.append(c)
        dx = max(np.abs(traj.x - X).max() / np.abs(X).max(), np.abs(traj.u - U).max() / max(np.abs(U).max(), 1e-300))
        dc = np.abs(traj.costs - C).max() / np.abs(C).max()
        if not (dx <= RTOL and dc <= RTOL):
            raise CheckFailed(f"LQ scaling n={n}: orrc and the numpy Riccati loop disagree (states/inputs {dx:.1e} rel., "
                              f"stage costs {dc:.1e} rel.)")
        to, tr = float(np.median(t_o)) / T, float(np.median(t_r)) / T
        pts.append((n, to, tr))
        rows.append(Row(bench, f"n={n}: orrc.simulate vs numpy Riccati loop", fmt_time(to), fmt_time(tr),
                        f"{tr / to:.1f}× faster", "—", None,
                        f"x, u agree to {dx:.0e} rel., c_t to {dc:.0e}; build: orrc {fmt_time(c_build + c_law)}, "
                        f"numpy gains {fmt_time(c_gains)}",
                        dict(grid="lq", size=n, t_orrc=to, t_peer=tr, ratio=to / tr, dx=dx, dc=dc,
                             t_build_orrc=c_build + c_law, t_build_numpy=c_gains)))
    if len(pts) >= 2:
        sizes, to, tr = zip(*pts)
        eo, er = exponent(sizes, to), exponent(sizes, tr)
        rows.append(Row(bench, "growth exponent in n (log-log slope of CPU per step)", f"{eo:.2f}", f"{er:.2f}",
                        f"{eo - er:+.2f}", "—", None, "orrc (the law applied, costs and V_M recorded) vs the numpy "
                        "Riccati loop (a backward recursion over the preview at each step)",
                        dict(grid="lq", exponents={"orrc": eo, "numpy": er}, sizes=list(sizes))))
    return rows
