"""Benchmark: how the cost of a closed-loop step grows with the horizon M and the state dimension n.

The closed loop of ``benchmarks/peers.py`` (same method: CPU time per step, one BLAS thread, each
peer in its own virtual environment, every tool's closed loop checked against orrc's) on two grids:

* the pendulum (``orrc.examples.inverted_pendulum()``, |u| <= 20, from (0.5, 0), disturbance radius
  0.02) for M in {10, 20, 50, 100, 200};
* a chain of k masses with nonlinear springs (``orrc.examples.mass_chain(k)``, n = 2k, |u| <= 2, every
  mass displaced by 0.5, disturbance radius 0.01) for n in {2, 4, 8, 12, 24} at M = 50;
* a quadrotor about hover (``orrc.examples.quadrotor()``, n = 12, m = 4, from the position (0.5, -0.5, 0.3)
  at rest, disturbance radius 0.005) at M = 50;

each run by orrc (``orrc.simulate`` with ``PreviewRHC``'s default NLP path: SQP whose QP solver is qrqp,
or HPIPM from the horizon ``orrc.solvers.nlp_solvers.HPIPM_FROM`` on, with the exact Hessian of the Lagrangian
or, from ``orrc.solvers.nlp_solvers.GAUSS_NEWTON_FROM`` variables per stage on, the Gauss-Newton Hessian; IPOPT
where an SQP step fails; compiled by ``orrc._jit`` before the timed runs where the NLP's C code is within
``orrc._jit.CODE_LIMIT``), the bare CasADi loop on the same NLP (``peers.BareCasadiLoop``: the floor of any
Python code calling it; always with CasADi's exact Hessian, so where orrc takes the Gauss-Newton one the
comparison is of two Hessians on the same NLP, whose closed loops are checked equal; beside it, informational,
the bare loop with orrc's own Hessian), acados (SQP, Gauss-Newton Hessian, HPIPM with partial condensing; and its
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

from . import peer_models, peers
from .common import CheckFailed, Row, cpu_and_wall, fmt_time

PENDULUM_M = (10, 20, 50, 100, 200)
CHAIN_K = (1, 2, 4, 6, 12)     # n = 2, 4, 8, 12, 24
CHAIN_M = 50
TARGET_ACADOS = 1.0            # orrc / acados (SQP), CPU per step: below
TARGET_BARE = 1.2              # orrc / bare CasADi loop, CPU per step: at most
TARGET_EXPONENT = 0.1          # orrc's growth exponent in M: at most acados's + this
SAME_RTOL, STATE_ATOL = 1e-6, 1e-6
CHAIN = dict(dt=0.1, stiffness=1.0, cubic=1.0, damping=0.1, u_max=2.0)
QUADROTOR_M = 50
QUADROTOR = dict(dt=0.05, mass=1.0, inertia=[0.02, 0.02, 0.04], gravity=9.81)
QUADROTOR_U = dict(thrust_max=5.0, torque_max=0.5)
#: the tools of the tables and plots, in their order: (key, label)
TOOLS = (("orrc", "orrc"), ("bare", "bare CasADi loop"), ("bare_own", "bare loop, orrc's Hessian"),
         ("acados", "acados SQP"), ("acados_rti", "acados RTI"), ("dompc", "do-mpc"))


def chain_problem(k: int, T: int, M: int, seed: int = 0) -> dict:
    """The chain's closed-loop problem as plain numbers (for the peers' child processes)."""
    n = 2 * k
    w = orrc.disturbances.uniform_ball(T + M, n, radius=0.01, seed=seed)
    x0 = np.concatenate([np.full(k, 0.5), np.zeros(k)])
    return dict(model="chain", k=k, T=T, M=M, x0=x0.tolist(), w=w.tolist(), q=[1.0] * k + [0.1] * k, r=0.1,
                **CHAIN)


def quadrotor_problem(T: int, M: int, seed: int = 0) -> dict:
    """The quadrotor's closed-loop problem as plain numbers (for the peers' child processes)."""
    ex = orrc.examples.quadrotor(**QUADROTOR, **QUADROTOR_U)
    w = orrc.disturbances.uniform_ball(T + M, 12, radius=0.005, seed=seed)
    return dict(model="quadrotor", T=T, M=M, x0=ex.x0.tolist(), w=w.tolist(), q=np.diag(ex.cost.Q).tolist(),
                r=np.diag(ex.cost.R).tolist(), u_max=ex.input_bounds[1].tolist(), **QUADROTOR)


def quadrotor_rollout(prob: dict, U, W):
    """The referee of the quadrotor: the states (T+1, 12) and the total stage cost of inputs U (T, 4) under W,
    in numpy (``peer_models.plant``: independent of orrc's CasADi model)."""
    step, (q, r) = peer_models.plant(prob), peer_models.weights(prob)
    U = np.asarray(U, float).reshape(-1, 4)
    X = np.empty((len(U) + 1, 12))
    X[0] = prob["x0"]
    J = 0.0
    for t, u in enumerate(U):
        J += float(q @ X[t] ** 2 + r @ u ** 2)
        X[t + 1] = step(X[t], u, W[t])
    return X, J


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
    if prob.get("model") == "quadrotor":
        return quadrotor_rollout(prob, U, W)
    return peers.closed_loop_cost(prob["x0"], U, W)


def example(prob: dict) -> orrc.examples.Example:
    if prob.get("model", "pendulum") == "chain":
        return orrc.examples.mass_chain(k=prob["k"], **CHAIN)
    if prob.get("model") == "quadrotor":
        return orrc.examples.quadrotor(**{k: prob[k] for k in QUADROTOR}, thrust_max=prob["u_max"][0],
                                       torque_max=prob["u_max"][1])
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
    hessian = rhc.nlp.hessian
    loops = {"bare": rhc}   # the bare loop: CasADi's exact Hessian on the same NLP; beside it orrc's own Hessian
    if hessian != "exact":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", orrc.SizeWarning)
            exact = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds,
                                    solver_options={"sqpmethod.hessian_approximation": "exact"})
        if compile:
            exact.compile(wait=True)
        loops = {"bare": exact, "bare_own": rhc}
    bares = {k: peers.BareCasadiLoop(r) for k, r in loops.items()}
    times, failed, Ubs = {"orrc": [], **{k: [] for k in bares}}, {}, {}
    for _ in range(reps):   # interleaved: a load change hits both alike
        traj, c, t = cpu_and_wall(orrc.simulate, ex.system, rhc, x0, w, T)
        times["orrc"].append((c, t))
        for key, bare in bares.items():
            if key in failed:
                continue
            try:
                (_, Ubs[key]), c, t = cpu_and_wall(bare, x0, w, T)
                times[key].append((c, t))
            except RuntimeError as exc:   # an SQP solve failed (error_on_fail): the bare loop has no other rung
                failed[key] = f"the bare loop's SQP solve failed ({str(exc).strip().splitlines()[-1][:160]})"
                times.pop(key)
    ref = referee(prob, traj.u)
    if np.abs(ref[0] - traj.x).max() > 1e-9 * max(1.0, np.abs(traj.x).max()):
        raise CheckFailed(f"{prob.get('model', 'pendulum')} M={M}: orrc's trajectory is not the referee's rollout "
                          "of its inputs (the models differ)")
    out = {k: dict(cpu=float(np.median([c for c, _ in v])) / T, wall=float(np.median([t for _, t in v])) / T)
           for k, v in times.items()}
    if traj.n_failures:
        raise CheckFailed(f"orrc's closed loop had {traj.n_failures} failed steps ({traj.solver_counts})")
    counts = dict(traj.solver_counts)
    for key in bares:
        if key in failed:
            out[key] = dict(skipped=failed[key])
        else:   # where every step of orrc's is SQP's, the bare loop's closed loop must be orrc's (both Hessians)
            out[key]["gap"], out[key]["dx"] = _compare(f"the bare CasADi loop ({key})", prob, ref, Ubs[key],
                                                       check=set(counts) == {"sqp"})
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
                       hessian=hessian,
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
                                dict(grid=grid, size=size, size_name=size_name, tool=tool, skipped=r["skipped"])))
                continue
            ratio = o["cpu"] / r["cpu"]
            if tool == "bare":
                target, ok = f"≤ {TARGET_BARE:g}× (CPU)", ratio <= TARGET_BARE
                text = f"{ratio:.2f}× the bare loop"
                if info.get("hessian", "exact") != "exact":
                    text += " (exact Hessian; orrc Gauss-Newton, same NLP, same closed loop)"
            elif tool == "bare_own":
                target, ok = "—", None
                text = f"{ratio:.2f}× the bare loop with orrc's Hessian"
            elif tool == "acados":
                target, ok = f"< {TARGET_ACADOS:g}× (CPU)", ratio < TARGET_ACADOS
                text = f"{ratio:.2f}× acados ({1 / ratio:.2f}× faster)"
            else:
                target, ok = "—", None
                text = f"{ratio:.2f}× {label} ({1 / ratio:.2f}× faster)"
            equal = "not checked: RTI is another controller" if tool == "acados_rti" else "checked equal"
            check = (f"orrc's steps by solver: {how}; {info['iterations']:.2f} SQP it./step "
                     f"({info.get('hessian', 'exact')} Hessian); J = {info['J']:.8g}; "
                     f"{label}: rel. cost gap {r['gap']:+.1e}, states {r['dx']:.0e} ({equal})")
            rows.append(Row(bench, f"{case}: orrc vs {label}", f"{fmt_time(o['cpu'])} ({fmt_time(o['wall'])})",
                            f"{fmt_time(r['cpu'])} ({fmt_time(r['wall'])})", text, target, ok, check,
                            dict(grid=grid, size=size, size_name=size_name, tool=tool, t_orrc=o["cpu"],
                                 t_orrc_wall=o["wall"],
                                 t_peer=r["cpu"], t_peer_wall=r["wall"], ratio=ratio, gap=r["gap"], dx=r["dx"],
                                 counts=info["counts"], compiled=info["compiled"], t_compile=info["t_compile"],
                                 t_build=info["t_build"], compile_error=info["compile_error"],
                                 hessian=info.get("hessian"),
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
        tools=("acados", "acados_rti", "dompc"), compile: bool = True, M_quadrotor: int | None = QUADROTOR_M) -> list[Row]:
    """Run the grids (and the quadrotor's point, unless ``M_quadrotor`` is None); raises :class:`CheckFailed` if
    a tool's closed loop is not orrc's."""
    pend = [measure(peers.problem(T, M), reps, tools, compile) for M in Ms]
    chain = [measure(chain_problem(k, T, M_chain), reps, tools, compile) for k in ks]
    rows = (_rows("pendulum, M grows", list(Ms), pend, "M", True)
            + _rows(f"chain of masses, n grows, M={M_chain}", [2 * k for k in ks], chain, "n", False))
    if M_quadrotor is not None:
        quad = measure(quadrotor_problem(T, M_quadrotor), reps, tools, compile)
        rows += _rows(f"quadrotor, n=12, m=4, M={M_quadrotor}", [12], [quad], "n", False)
    return rows
