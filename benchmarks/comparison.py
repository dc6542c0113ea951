"""The comparison chapter's table from one command: ``python -m benchmarks.run --only comparison``.

Every controller of the comparison chapter on the book's scalar example x⁺ = 2x + u + w (c = x² + u²)
from x_0 = 0 under i.i.d., sinusoidal, bursty and worst-case disturbances (the worst case of LQR,
from ``orrc.certify.worst_case_attenuation``): total cost, attenuation ratio, R^p_T(γ) at γ = 1,
dynamic regret against the clairvoyant optimum, and the exact worst-case levels of the linear loops
(``orrc.comparison.compare``). Its check: the clairvoyant cost is not above any controller's.
"""
from __future__ import annotations

import numpy as np

import orrc
from orrc.comparison import compare

from .common import CheckFailed, Row, fmt_time, timed


def controllers(s, c, T, M):
    return {f"preview RHC, M = {M}": orrc.PreviewRHC(s, c, M),
            f"preview RHC, M = {M}, k = 2": orrc.PreviewRHC(s, c, M, preview_w=2),
            f"naive MPC (M = {M}, k = 0)": orrc.PreviewRHC(s, c, M, preview_w=0),
            "LQR": orrc.LQR(s, c), "H∞": orrc.HInfinity(s, c),
            f"H∞, preview {M}": orrc.HInfinity(s, c, preview=M),
            "GPC": orrc.GPC(s, c, H=5), f"regret-optimal (T = {T})": orrc.RegretOptimal(s, c, T)}


def run(T: int = 30, M: int = 10, gamma: float = 1.0):
    ex = orrc.examples.scalar_unstable()
    s, c = ex.system, ex.cost
    ctrls, build = timed(controllers, s, c, T, M)
    L = T + M
    worst = orrc.certify.worst_case_attenuation(s, ctrls["LQR"], T).w
    kinds = {"i.i.d. |w| <= 1": orrc.disturbances.uniform_ball(L, 1, 1.0, seed=0),
             "sinusoid": orrc.disturbances.sinusoid(L, 1, amplitude=1.0, period=12),
             "bursts": orrc.disturbances.bursts(L, 1, magnitude=1.0, every=max(T // 3, 2), seed=0),
             "worst case of LQR": np.vstack([worst, np.zeros((M, 1))])}
    rows = []
    for kind, w in kinds.items():
        result, secs = timed(compare, s, c, ctrls, w, T, gamma)
        clair = result[-1].cost
        for r in result:
            ok = clair <= r.cost * (1 + 1e-9) + 1e-12
            if not ok:
                raise CheckFailed(f"{kind}: the clairvoyant cost {clair:.6g} is above {r.name}'s {r.cost:.6g}")
            wc = ("—" if r.worst_attenuation is None else
                  f"worst γ_T {r.worst_attenuation:.4g}, worst regret {r.worst_regret:.4g}")
            rows.append(Row(f"comparison T={T}, {kind}", r.name, f"Σc {r.cost:.4g}", f"clairvoyant {clair:.4g}",
                            f"dyn. regret {r.dynamic_regret:.4g}", "clairvoyant <= Σc", None,
                            f"ratio {r.ratio:.4g}, R^p_T({gamma:g}) {r.regret_p:.4g}; {wc}",
                            data={"kind": kind, "row": r}))
        rows[-1].check += f" (table computed in {fmt_time(secs)})"
    rows[0].check += f"; controllers built in {fmt_time(build)}"
    return rows
