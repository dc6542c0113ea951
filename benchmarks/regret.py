"""Benchmark: the regret-optimal controller at the literature's scale, structured vs SDP.

``orrc.RegretOptimal`` by its structure (``method="structured"``: a causal factor of S, Arveson's
distance formula and Parrott's completion, ``orrc.solvers.regret``) at T = 30 with n = 3, m = 2 (the size
of published regret-optimal benchmarks; target a few seconds, < 5 s) and at T = 200 with n = 2, m = 1
(target < 60 s), CPU and wall time. The check at full size: the worst-case regret of the operator found,
‖S^½(Φ − Φ*)‖₂² computed from Φ with numpy, equals the method's optimal value (Arveson's distance²) to
1e-8, and Φ is strictly causal. Beside it, at the largest size the SDP takes (T(m + n) = 60: T = 12,
n = 3, m = 2), both methods in the same run: their times, and the same optimum to 1e-6 relative.
"""
from __future__ import annotations

import numpy as np

import orrc

from .common import CheckFailed, Row, cpu_and_wall, fmt_time


def problem(n: int, m: int, seed: int = 0):
    """A random open-loop-unstable linear-quadratic problem (A scaled to spectral radius 1.2)."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A *= 1.2 / max(abs(np.linalg.eigvals(A)))
    return orrc.LinearSystem(A, rng.normal(size=(n, m))), orrc.QuadraticCost(np.eye(n), 0.5 * np.eye(m))


def _causal(ro) -> bool:
    m, n = ro.system.m, ro.system.n
    return all(not ro.Phi[t * m:(t + 1) * m, t * n:].any() for t in range(ro.T))


def run(sizes=((30, 3, 2, 5.0), (200, 2, 1, 60.0)), sdp_size=(12, 3, 2)) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if an operator is not optimal or not causal."""
    rows = []
    for T, n, m, limit in sizes:
        s, c = problem(n, m)
        ro, cpu, wall = cpu_and_wall(orrc.RegretOptimal, s, c, T)
        gap = abs(ro.regret - ro.value) / ro.value
        if gap > 1e-8 or not _causal(ro):
            raise CheckFailed(f"RegretOptimal T={T}: regret {ro.regret:.10g} vs value {ro.value:.10g} (gap {gap:.1e}), "
                              f"causal: {_causal(ro)}")
        rows.append(Row(f"regret-optimal T={T}, n={n}, m={m}", "structured (Arveson + Parrott)",
                        f"{fmt_time(cpu)} ({fmt_time(wall)} wall)", "—", "—", f"< {limit:g} s (CPU)", cpu < limit,
                        f"worst-case regret {ro.regret:.6g} = optimal value to {gap:.0e}; Φ strictly causal",
                        dict(T=T, t_cpu=cpu, t_wall=wall, regret=ro.regret)))
    T, n, m = sdp_size
    s, c = problem(n, m, seed=1)
    (a, ca_, wa), (b, cb, wb) = cpu_and_wall(orrc.RegretOptimal, s, c, T), \
        cpu_and_wall(orrc.RegretOptimal, s, c, T, method="sdp")
    gap = (a.regret - b.regret) / b.regret
    if abs(gap) > 1e-6:
        raise CheckFailed(f"RegretOptimal T={T}: structured {a.regret:.10g} vs SDP {b.regret:.10g} (gap {gap:.1e})")
    rows.append(Row(f"regret-optimal T={T}, n={n}, m={m} (the SDP's largest size)", "structured vs SDP (Clarabel)",
                    f"{fmt_time(ca_)} ({fmt_time(wa)} wall)", f"{fmt_time(cb)} ({fmt_time(wb)} wall)",
                    f"{cb / ca_:.0f}× faster", "—", None, f"same worst-case regret: rel. gap {gap:+.1e}",
                    dict(t_structured=ca_, t_sdp=cb, gap=gap)))
    return rows
