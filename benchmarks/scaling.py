"""Benchmark: how the cost of a closed-loop step grows with the horizon M and the state dimension n.

The closed loop of ``benchmarks/peers.py`` (same method: CPU time per step, one BLAS thread, each
peer in its own virtual environment, every tool's closed loop checked against orrc's) on two grids:

* the pendulum (``orrc.examples.inverted_pendulum()``, |u| <= 20, from (0.5, 0), disturbance radius
  0.02) for M in {10, 20, 50, 100, 200};
* a chain of k masses with nonlinear springs (``orrc.examples.mass_chain(k)``, n = 2k, |u| <= 2, every
  mass displaced by 0.5, disturbance radius 0.01) for n in {2, 4, 8, 12, 24} at M = 50;

each run by orrc (``orrc.simulate`` with ``PreviewRHC``'s default NLP path: SQP whose QP solver is qrqp,
or HPIPM from the horizon ``orrc.solvers.nlp_solvers.HPIPM_FROM`` on, IPOPT where an SQP step fails; compiled
by ``orrc._jit`` before the timed runs), the bare CasADi loop on the same NLP (``peers.BareCasadiLoop``: the floor of any
Python code calling it), acados (SQP, Gauss-Newton Hessian, HPIPM with partial condensing; and its
real-time iteration, one SQP iteration per step, which is a different controller: its closed loop is
reported with its cost gap, not checked equal) and do-mpc (IPOPT). orrc's and the bare loop's runs are
interleaved; a peer runs its repetitions in its own process. The referee is one independent numpy rollout
of each tool's inputs (the pendulum's of ``benchmarks/pendulum.py``, the chain's :func:`chain_rollout`):
its closed-loop cost must agree with orrc's to 1e-6 relative and its states to 1e-6 (the solvers stop at
KKT residuals of 1e-8 (orrc), 1e-9 (IPOPT's fallback), 1e-10 (acados, do-mpc), and a closed loop of T
steps adds up T such differences, each amplified by the loop's sensitivity).

Per tool and grid, the growth exponent is the slope of a least-squares line through (log size, log CPU
time per step). The targets (the issue's): orrc faster than acados (SQP) at every point, within 1.2x of
the bare loop, and its exponent in M at most acados's + 0.1. The exact LQ path is measured the same way
in ``benchmarks/scaling_lq.py``.
"""
from __future__ import annotations

import warnings

import numpy as np

import orrc

from . import peers
from .common import CheckFailed, Row, cpu_and_wall, fmt_time

PENDULUM_M = (10, 20, 50, 100, 200)
CHAIN_K = (1, 2, 4, 6, 12)     # n = 2, 4, 8, 12, 24
CHAIN_M = 50
TARGET_ACADOS = 1.0            # orrc / acados (SQP), CPU per step: below
TARGET_BARE = 1.2              # orrc / bare CasADi loop, CPU per step: at most
TARGET_EXPONENT = 0.1          # orrc's growth exponent in M: at most acados's + this
SAME_RTOL, STATE_ATOL = 1e-6, 1e-6
CHAIN = dict(dt=0.1, stiffness=1.0, cubic=1.0, damping=0.1, u_max=2.0)
#: the tools of the tables and plots, in their order: (key, label)
TOOLS = (("orrc", "orrc"), ("bare", "bare CasADi loop"), ("acados", "acados SQP"),
         ("acados_rti", "acados RTI"), ("dompc", "do-mpc"))


def chain_problem(k: int, T: int, M: int, seed: int = 0) -> dict:
    """The chain's closed-loop problem as plain numbers (for the peers' child processes)."""
    n = 2 * k
    w = orrc.disturbances.uniform_ball(T + M, n, radius=0.01, seed=seed)
    x0 = np.concatenate([np.full(k, 0.5), np.zeros(k)])
    return dict(model="chain", k=k, T=T, M=M, x0=x0.tolist(), w=w.tolist(), q=[1.0] * k + [0.1] * k, r=0.1,
                **CHAIN)


def chain_rollout(prob: dict, U, W):
    """The referee of the chain: the states (T+1, n) and the total stage cost of inputs U (T,) under W,
    in numpy (independent of orrc's CasADi model and of the peers')."""
    k, dt, ks, kc, c = prob["k"], prob["dt"], prob["stiffness"], prob["cubic"], prob["damping"]
    q, r = np.asarray(prob["q"]), prob["r"]
    U = np.asarray(U, float).reshape(-1)
    X = np.empty((len(U) + 1, 2 * k))
    X[0] = prob["x0"]
    J = 0.0
    for t, u in enumerate(U):
        x = X[t]
        J += float(q @ x ** 2 + r * u ** 2)
        p, v = x[:k], x[k:]
        d = np.diff(p, prepend=0.0)
        force = ks * d + kc * d ** 3
        a = np.append(force[1:], 0.0) - force - c * v
        a[-1] += u
        v = v + dt * a
        X[t + 1] = np.concatenate([p + dt * v, v]) + W[t]
    return X, J


def referee(prob: dict, U):
    """(states, closed-loop cost) of the inputs U, by the numpy rollout of the problem's model."""
    W = np.asarray(prob["w"])[:prob["T"]]
    if prob.get("model", "pendulum") == "chain":
        return chain_rollout(prob, U, W)
    return peers.closed_loop_cost(prob["x0"], U, W)


def example(prob: dict) -> orrc.examples.Example:
    if prob.get("model", "pendulum") == "chain":
        return orrc.examples.mass_chain(k=prob["k"], **CHAIN)
    return orrc.examples.inverted_pendulum(dt=prob["dt"], g_over_l=prob["g_over_l"], friction=prob["friction"],
                                           u_max=prob["u_max"])


def _compare(what: str, prob: dict, ref, U, check: bool = True):
    """(relative cost gap, max state difference) of inputs U against orrc's referee result ``ref``; raises
    :class:`CheckFailed` beyond the tolerances where ``check``."""
    X, J = referee(prob, U)
    gap, dx = (J - ref[1]) / abs(ref[1]), float(np.abs(X - ref[0]).max())
    if check and (abs(gap) > SAME_RTOL or dx > STATE_ATOL):
        raise CheckFailed(f"{what}: closed-loop cost {J:.10g} against orrc's {ref[1]:.10g} (rel. gap {gap:.1e}), "
                          f"states differ by {dx:.1e}: not the same closed loop")
    return gap, dx


def measure(prob: dict, reps: int, tools=("acados", "acados_rti", "dompc"), compile: bool = True) -> dict:
    """One grid point: {tool: {"cpu", "wall" (per step), "gap", "dx", ...} or {"skipped": reason}}, plus
    "info" (orrc's solver counts, compile status, build time). Raises :class:`CheckFailed` where a tool's
    closed loop (other than RTI's) is not orrc's. ``compile``: orrc's SQP solver compiled (``orrc._jit``) before
    the timed runs, as a long run does by itself (False: interpreted, for a smoke run)."""
    ex, T, M = example(prob), prob["T"], prob["M"]
    x0, w = np.asarray(prob["x0"], float), np.asarray(prob["w"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", orrc.SizeWarning)   # the chain's largest NLP: a few seconds to build
        rhc, c_build, _ = cpu_and_wall(orrc.PreviewRHC, ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    compiled, _, t_compile = cpu_and_wall(rhc.compile, wait=True) if compile else (False, 0.0, 0.0)
    bare = peers.BareCasadiLoop(rhc)
    times, bare_failed = {"orrc": [], "bare": []}, None
    for _ in range(reps):   # interleaved: a load change hits both alike
        traj, c, t = cpu_and_wall(orrc.simulate, ex.system, rhc, x0, w, T)
        times["orrc"].append((c, t))
        if bare_failed is None:
            try:
                (_, Ub), c, t = cpu_and_wall(bare, x0, w, T)
                times["bare"].append((c, t))
            except RuntimeError as exc:   # an SQP solve failed (error_on_fail): the bare loop has no other rung
                bare_failed = f"the bare loop's SQP solve failed ({str(exc).strip().splitlines()[-1][:160]})"
                times.pop("bare")
    ref = referee(prob, traj.u)
    if np.abs(ref[0] - traj.x).max() > 1e-9 * max(1.0, np.abs(traj.x).max()):
        raise CheckFailed(f"{prob.get('model', 'pendulum')} M={M}: orrc's trajectory is not the referee's rollout "
                          "of its inputs (the models differ)")
    out = {k: dict(cpu=float(np.median([c for c, _ in v])) / T, wall=float(np.median([t for _, t in v])) / T)
           for k, v in times.items()}
    if traj.n_failures:
        raise CheckFailed(f"orrc's closed loop had {traj.n_failures} failed steps ({traj.solver_counts})")
    counts = dict(traj.solver_counts)
    if bare_failed:
        out["bare"] = dict(skipped=bare_failed)
    elif set(counts) == {"sqp"}:   # the bare loop solves every step by the same SQP: the same closed loop
        out["bare"]["gap"], out["bare"]["dx"] = _compare("the bare CasADi loop", prob, ref, Ub)
    else:   # orrc's SQP step failed and its ladder took IPOPT: the bare loop (SQP only) has no such rung
        out["bare"]["gap"], out["bare"]["dx"] = _compare("the bare CasADi loop", prob, ref, Ub, check=False)
    out["orrc"].update(gap=0.0, dx=0.0)
    for tool in tools:
        name, p = ("acados", dict(prob, rti=True)) if tool == "acados_rti" else (tool, prob)
        report, reason = peers.run_peer(name, p, reps)
        if report is None:
            out[tool] = dict(skipped=reason)
            continue
        gap, dx = _compare(tool, prob, ref, report["U"], check=tool != "acados_rti")
        out[tool] = dict(cpu=report["cpu"] / T, wall=report["wall"] / T, gap=gap, dx=dx, version=report["version"],
                         threads=report["threads"])
    out["info"] = dict(counts=counts, J=ref[1], compiled=bool(compiled), t_compile=t_compile, t_build=c_build,
                       compile_error=None if compiled else (rhc.compile_error() if compile else "not asked for"),
                       iterations=float(traj.iterations.mean()))
    return out


def exponent(sizes, seconds) -> float:
    """The growth exponent: the slope of the least-squares line through (log size, log seconds)."""
    return float(np.polyfit(np.log(np.asarray(sizes, float)), np.log(np.asarray(seconds, float)), 1)[0])


def _rows(grid: str, sizes, results, size_name: str, target_exponent: bool) -> list[Row]:
    """The table's rows of one grid: per point orrc against each tool, then the exponents."""
    rows = []
    bench = f"scaling, {grid} (closed loop per step; CPU, wall in parentheses)"
    for size, res in zip(sizes, results):
        o, info = res["orrc"], res["info"]
        case = f"{size_name}={size}"
        how = ", ".join(f"{k} {v}" for k, v in sorted(info["counts"].items()))
        for tool, label in TOOLS[1:]:
            if tool not in res:   # not asked for
                continue
            r = res[tool]
            if "cpu" not in r:
                rows.append(Row(bench, f"{case}: orrc vs {label}", f"{fmt_time(o['cpu'])} ({fmt_time(o['wall'])})",
                                "skipped", "—", "—", None, r["skipped"],
                                dict(grid=grid, size=size, tool=tool, skipped=r["skipped"])))
                continue
            ratio = o["cpu"] / r["cpu"]
            if tool == "bare":
                target, ok = f"≤ {TARGET_BARE:g}× (CPU)", ratio <= TARGET_BARE
                text = f"{ratio:.2f}× the bare loop"
            elif tool == "acados":
                target, ok = f"< {TARGET_ACADOS:g}× (CPU)", ratio < TARGET_ACADOS
                text = f"{ratio:.2f}× acados ({1 / ratio:.2f}× faster)"
            else:
                target, ok = "—", None
                text = f"{ratio:.2f}× {label} ({1 / ratio:.2f}× faster)"
            equal = "not checked: RTI is another controller" if tool == "acados_rti" else "checked equal"
            check = (f"orrc's steps by solver: {how}; {info['iterations']:.2f} SQP it./step; J = {info['J']:.8g}; "
                     f"{label}: rel. cost gap {r['gap']:+.1e}, states {r['dx']:.0e} ({equal})")
            rows.append(Row(bench, f"{case}: orrc vs {label}", f"{fmt_time(o['cpu'])} ({fmt_time(o['wall'])})",
                            f"{fmt_time(r['cpu'])} ({fmt_time(r['wall'])})", text, target, ok, check,
                            dict(grid=grid, size=size, tool=tool, t_orrc=o["cpu"], t_orrc_wall=o["wall"],
                                 t_peer=r["cpu"], t_peer_wall=r["wall"], ratio=ratio, gap=r["gap"], dx=r["dx"],
                                 counts=info["counts"], compiled=info["compiled"], t_compile=info["t_compile"],
                                 t_build=info["t_build"], compile_error=info["compile_error"],
                                 **({"peer": label.split()[0], "version": r["version"]} if "version" in r else {}))))
    slopes = {}
    for tool, label in TOOLS:
        pts = [(s, res[tool]["cpu"]) for s, res in zip(sizes, results) if "cpu" in res.get(tool, {})]
        if len(pts) >= 2:
            slopes[tool] = exponent(*zip(*pts))
    if "orrc" in slopes:
        peer = slopes.get("acados")
        ok = (slopes["orrc"] <= peer + TARGET_EXPONENT) if (target_exponent and peer is not None) else None
        others = "; ".join(f"{label} {slopes[t]:.2f}" for t, label in TOOLS[1:] if t in slopes)
        rows.append(Row(bench, f"growth exponent in {size_name} (log-log slope of CPU per step)",
                        f"{slopes['orrc']:.2f}", "—" if peer is None else f"{peer:.2f} (acados SQP)",
                        "—" if peer is None else f"{slopes['orrc'] - peer:+.2f}",
                        f"≤ acados + {TARGET_EXPONENT:g}" if target_exponent else "—", ok, others,
                        dict(grid=grid, exponents=slopes, sizes=list(sizes))))
    return rows


def run(T: int = 100, Ms=PENDULUM_M, ks=CHAIN_K, M_chain: int = CHAIN_M, reps: int = 3,
        tools=("acados", "acados_rti", "dompc"), compile: bool = True) -> list[Row]:
    """Run both grids; raises :class:`CheckFailed` if a tool's closed loop is not orrc's."""
    pend = [measure(peers.problem(T, M), reps, tools, compile) for M in Ms]
    chain = [measure(chain_problem(k, T, M_chain), reps, tools, compile) for k in ks]
    return (_rows("pendulum, M grows", list(Ms), pend, "M", True)
            + _rows(f"chain of masses, n grows, M={M_chain}", [2 * k for k in ks], chain, "n", False))
