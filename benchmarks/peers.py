"""Benchmark: the pendulum's closed loop against the tools a user would pick.

The problem of ``benchmarks/pendulum.py`` (``orrc.examples.inverted_pendulum()``, M = 20, |u| <= 20)
run in closed loop for T = 200 steps from (0.5, 0) under a disturbance drawn from a ball (radius
0.02), each step warm-started from the previous one, by

* orrc: ``orrc.simulate(system, PreviewRHC(system, cost, M), x0, w, T)`` (SQP with ``qrqp``, the
  acceptance checks, the failure ladder and the per-step record), its SQP solver and checks compiled
  (``orrc._jit``: asked for before the timed runs, as a long run does by itself; a one-off, cached per
  machine, reported beside the ratio; interpreted where no C compiler is found);
* a bare CasADi loop on the *same* NLP (the transcription and solver options orrc built,
  ``ShootingNLP.problem``, and orrc's compiled library where orrc compiled it) called through
  ``Function.buffer`` on numpy arrays, with the previous
  solution shifted as the guess and the dynamics evaluated the same way: the floor of what any
  Python code calling this NLP can do;
* do-mpc (CasADi + IPOPT; w a time-varying parameter), and acados (SQP, Gauss-Newton, HPIPM; its
  Python API), each in its own virtual environment built from ``benchmarks/requirements-peers.txt``
  (``tests/fresh_env.py``; a peer that cannot be installed is skipped with the reason);
* python-control's ``solve_ocp`` (SLSQP), one cold step at states of the closed loop (a whole loop
  would take minutes), one per round between orrc's runs: per step.

Every tool gets one BLAS thread (threadpoolctl here; the environment variables of
``common.ONE_THREAD_ENV`` in a child process, which reports its own pools). Times are CPU time
(``process_time``) per closed-loop step, wall time beside it; runs are interleaved round by round
and medians reported. The referee: one independent numpy rollout (``pendulum.rollout``) of each
tool's inputs from x0 under w, whose closed-loop cost must agree with orrc's to 1e-6 relative, and
the states to 1e-6.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np

import orrc

from . import pendulum
from .common import ONE_THREAD_ENV, CheckFailed, Row, blas_threads, cpu_and_wall, fmt_time

HERE = Path(__file__).resolve().parent
REQUIREMENTS = HERE / "requirements-peers.txt"
TARGET_BARE = 1.1        # orrc / bare CasADi loop, CPU per step
TARGET_CONTROL = 1000.0  # python-control / orrc, CPU per step
SAME_RTOL = 1e-6
STATE_ATOL = 1e-6


def problem(T: int, M: int, radius: float = 0.02, seed: int = 0) -> dict:
    """The closed-loop problem every tool solves (plain numbers, for the peers' child processes)."""
    w = orrc.disturbances.uniform_ball(T + M, 2, radius=radius, seed=seed)
    return dict(T=T, M=M, x0=[0.5, 0.0], w=w.tolist(), dt=pendulum.DT, g_over_l=pendulum.G_OVER_L,
                friction=pendulum.FRICTION, u_max=pendulum.U_MAX, q=[pendulum.Q_THETA, pendulum.Q_OMEGA],
                r=pendulum.R_U)


def closed_loop_cost(x0, U, W):
    """The independent referee: the states (T+1, 2) and the total stage cost of inputs U under W."""
    return pendulum.rollout(np.asarray(x0, float), np.asarray(U, float).reshape(-1, 1), np.asarray(W, float))


class BareCasadiLoop:
    """The floor: orrc's own NLP (``rhc``'s transcription and SQP options) called by ``Function.buffer``
    on numpy arrays, the previous solution shifted as the guess (cold first step: zero inputs, the
    state held), the plant ``system.function`` on a buffer as well; built once, like the controller."""

    def __init__(self, rhc: orrc.PreviewRHC):
        nlp = self.nlp = rhc._nlp
        M, n, m = self.M, self.n, self.m = nlp.M, nlp.n, nlp.m
        compiled = nlp.compiled("sqp")   # orrc's NLP compiled (orrc._jit): the same library here
        self.solver = (compiled.fn if compiled is not None else
                       ca.nlpsol("bare", "sqpmethod", nlp.problem, nlp.solver_options["sqp"]))
        self.buf, self.evaluate = self.solver.buffer()
        nz, ng = M * (n + m), M * n
        self.z0, self.p = np.zeros(nz), np.zeros(nlp.problem["p"].numel())
        self.args = (self.z0, self.p, nlp.lbz.copy(), nlp.ubz.copy(), np.zeros(ng), np.zeros(ng), np.zeros(nz),
                     np.zeros(ng))
        self.z, self.res = np.zeros(nz), (np.zeros(1), np.zeros(ng), np.zeros(nz), np.zeros(ng), np.zeros(len(self.p)))
        for i, a in enumerate(self.args):
            self.buf.set_arg(i, memoryview(a))
        for i, r in enumerate((self.z,) + self.res):
            self.buf.set_res(i, memoryview(r))
        # the shift of the guess in the solver's order, where the NLP's variables are in stage order (HPIPM)
        self.shift = None
        if nlp.order is not None:
            nu = M * m
            shift = np.r_[m:nu, nu - m:nu, nu + n:nu + M * n, nu + (M - 1) * n:nu + M * n]
            self.shift = np.argsort(nlp.order)[shift[nlp.order]]
        self.fbuf, self.fevaluate = rhc.system.function.buffer()
        self.fx, self.fu, self.fw, self.fout = np.zeros(n), np.zeros(m), np.zeros(n), np.zeros(n)
        for i, a in enumerate((self.fx, self.fu, self.fw)):
            self.fbuf.set_arg(i, memoryview(a))
        self.fbuf.set_res(0, memoryview(self.fout))
        self.p[n + M * n:] = np.broadcast_to(rhc.cost.default_params, (M, rhc.cost.n_params)).reshape(-1)

    def __call__(self, x0, w, T: int, read_status: bool = False):
        """The closed loop of T steps: (X (T+1, n), U (T, m)). ``read_status``: also read each solve's
        status and iteration count (``FunctionBuffer.stats()``), the least a loop that knows whether a
        step was solved must do (the bare floor does not)."""
        M, n, m, z, z0, p = self.M, self.n, self.m, self.z, self.z0, self.p
        X, U = np.empty((T + 1, n)), np.empty((T, m))
        X[0] = x0
        z0[self.nlp.iu], z0[self.nlp.ix] = 0.0, np.tile(x0, M)
        for t in range(T):
            x = X[t]
            p[:n] = x
            p[n:n + M * n] = w[t:t + M].reshape(-1)
            self.evaluate()
            if read_status:
                stats = self.buf.stats()
                if not stats["success"]:
                    raise CheckFailed(f"the bare loop's solve failed at t={t}: {stats['return_status']}")
            U[t] = z[:m]   # (the first input, in either order)
            # the guess of the next step: the solution shifted by one step
            if self.shift is not None:
                z0[:] = z[self.shift]
            else:
                z0[:(M - 1) * m], z0[(M - 1) * m:M * m] = z[m:M * m], z[(M - 1) * m:M * m]
                z0[M * m:M * m + (M - 1) * n], z0[M * m + (M - 1) * n:] = z[M * m + n:], z[-n:]
            self.fx[:], self.fu[:], self.fw[:] = x, z[:m], w[t]
            self.fevaluate()
            X[t + 1] = self.fout
        return X, U


def _requirements(name: str) -> list[str]:
    """The lines "NAME: requirement" of ``requirements-peers.txt`` for peer ``name``."""
    lines = [ln.split("#")[0].strip() for ln in REQUIREMENTS.read_text().splitlines()]
    return [ln.split(":", 1)[1].strip() for ln in lines if ln.startswith(f"{name}:")]


def peer_python(name: str):
    """(the Python of the peer's virtual environment, None), built once per its requirements by
    ``tests/fresh_env.py``; or (None, the reason) where it cannot be built (no network, no wheel
    for this Python, a failed install)."""
    sys.path.insert(0, str(HERE.parent))
    try:
        from tests.fresh_env import fresh_env
    finally:
        sys.path.pop(0)
    try:
        python = Path(fresh_env(f"peer-{name}", _requirements(name)))
        over = _requirements(f"{name}-casadi")  # acados: casadi for this Python over the vendored one
        if over and subprocess.run([str(python), "-c", "import casadi"], capture_output=True).returncode:
            subprocess.run([str(python), "-m", "pip", "install", "--quiet", "--force-reinstall", "--no-deps", *over],
                           check=True, capture_output=True, text=True, timeout=600)
        return python, None
    except Exception as exc:
        text = (getattr(exc, "stderr", None) or str(exc) or type(exc).__name__).strip().splitlines()
        return None, f"{type(exc).__name__}: {text[-1][:300] if text else ''}"


def run_peer(name: str, prob: dict, reps: int, timeout: float = 900.0):
    """Run ``benchmarks/peer_<name>.py`` in the peer's environment: (its report, None) or (None, reason)."""
    python, reason = peer_python(name)
    if python is None:
        return None, f"{name} could not be installed ({reason})"
    env = dict(os.environ, **ONE_THREAD_ENV)
    env.pop("PYTHONPATH", None)
    try:
        out = subprocess.run([str(python), str(HERE / f"peer_{name}.py"), str(reps)], input=json.dumps(prob),
                             capture_output=True, text=True, timeout=timeout, env=env, cwd=python.parent)
    except subprocess.TimeoutExpired:
        return None, f"{name} did not finish within {timeout:.0f} s"
    if out.returncode != 0:
        return None, f"{name} failed: {(out.stderr.strip().splitlines() or ['?'])[-1][:300]}"
    return json.loads(out.stdout.strip().splitlines()[-1]), None


def _check(name: str, ref_J: float, ref_X, x0, U, W):
    X, J = closed_loop_cost(x0, U, W)
    gap = (J - ref_J) / abs(ref_J)
    dx = float(np.abs(X - ref_X).max())
    if abs(gap) > SAME_RTOL or dx > STATE_ATOL:
        raise CheckFailed(f"closed loop of {name}: cost {J:.10g} against orrc's {ref_J:.10g} (rel. gap {gap:.1e}), "
                          f"states differ by {dx:.1e}: not the same closed loop")
    return gap, dx


def run(T: int = 200, M: int = 20, reps: int = 7, reps_control: int = 6, peers=("dompc", "acados")) -> list[Row]:
    """Run the benchmark; raises :class:`CheckFailed` if a tool's closed loop is not orrc's. python-control's
    ``reps_control`` cold steps, at the states t = 0, T/4, T/2 of orrc's loop in turn (two at each by
    default), are timed one per round, interleaved with orrc's runs like the bare loops."""
    ex = orrc.examples.inverted_pendulum(dt=pendulum.DT, g_over_l=pendulum.G_OVER_L, friction=pendulum.FRICTION,
                                         u_max=pendulum.U_MAX)
    prob = problem(T, M)
    x0, w = np.array(prob["x0"]), np.array(prob["w"])
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    # orrc compiles its SQP solver and checks (orrc._jit) after some solves, or when asked: asked here, so
    # that every timed run uses them (a one-off, cached per machine); the bare loop calls the same library
    compiled, t_compile = cpu_and_wall(rhc.compile, wait=True)[::2]
    cached = all(job.from_cache for job in rhc._nlp._jit.values())
    how = (f"orrc's NLP compiled (orrc._jit; {'loaded from the cache' if cached else 'built'} in "
           f"{fmt_time(t_compile)} wall)" if compiled else
           f"orrc's NLP interpreted ({rhc.compile_error()})")
    bare = BareCasadiLoop(rhc)
    times = {"orrc": [], "bare": [], "status": []}
    control_at = [(0, T // 4, T // 2)[i % 3] for i in range(max(1, reps_control))]
    c_cpu, c_wall, c_out = [], [], []
    for i in range(max(reps, len(control_at))):  # interleaved: a load change hits every tool alike
        if i < reps:
            traj, c, t = cpu_and_wall(orrc.simulate, ex.system, rhc, x0, w, T)
            times["orrc"].append((c, t))
            (Xb, Ub), c, t = cpu_and_wall(bare, x0, w, T)
            times["bare"].append((c, t))
            _, c, t = cpu_and_wall(bare, x0, w, T, read_status=True)
            times["status"].append((c, t))
        if i < len(control_at):   # python-control: one cold step at a state of orrc's closed loop
            t = control_at[i]
            out, c, wall = cpu_and_wall(pendulum.solve_ocp, traj.x[t], traj.w_all[t:t + M], M)
            c_cpu.append(c)
            c_wall.append(wall)
            c_out.append((t, out))
    if traj.n_failures or set(traj.solver) != {"sqp"}:
        raise CheckFailed(f"orrc's closed loop had failed steps or steps not solved by SQP: {traj.solver_counts}")
    X_ref, J_ref = closed_loop_cost(x0, traj.u, w[:T])
    if np.abs(X_ref - traj.x).max() > 1e-9 or abs(J_ref - traj.costs.sum()) > 1e-9 * J_ref:
        raise CheckFailed("orrc's recorded trajectory is not the rollout of its inputs")
    gap_b, dx_b = _check("the bare CasADi loop", J_ref, X_ref, x0, Ub, w[:T])
    threads = blas_threads()
    med = {k: (float(np.median([c for c, _ in v])) / T, float(np.median([t for _, t in v])) / T)
           for k, v in times.items()}
    o_cpu, o_wall = med["orrc"]
    bench = f"pendulum closed loop T={T}, M={M} (per step; CPU, wall in parentheses)"
    rows = [Row(bench, "orrc.simulate vs bare CasADi loop, same NLP", f"{fmt_time(o_cpu)} ({fmt_time(o_wall)})",
                f"{fmt_time(med['bare'][0])} ({fmt_time(med['bare'][1])})",
                f"{o_cpu / med['bare'][0]:.2f}× (wall {o_wall / med['bare'][1]:.2f}×)", f"≤ {TARGET_BARE:g}× (CPU)",
                o_cpu / med["bare"][0] <= TARGET_BARE,
                f"{how}; BLAS threads: {threads}; J = {J_ref:.8f}, bare rel. gap {gap_b:+.1e}, states {dx_b:.0e}",
                dict(t_orrc=o_cpu, t_orrc_wall=o_wall, t_bare=med["bare"][0], t_bare_wall=med["bare"][1],
                     ratio=o_cpu / med["bare"][0], J=J_ref, compiled=compiled))]
    s_cpu, s_wall = med["status"]
    rows.append(Row(bench, "orrc.simulate vs bare loop + each solve's status read", f"{fmt_time(o_cpu)} ({fmt_time(o_wall)})",
                    f"{fmt_time(s_cpu)} ({fmt_time(s_wall)})", f"{o_cpu / s_cpu:.2f}× (wall {o_wall / s_wall:.2f}×)",
                    "—", None, "FunctionBuffer.stats() per step: success, status, iterations (orrc records them)",
                    dict(t_status=s_cpu, t_status_wall=s_wall, ratio=o_cpu / s_cpu)))
    for name in peers:
        report, reason = run_peer(name, prob, reps)
        label = {"dompc": "do-mpc", "acados": "acados"}[name]
        if report is None:
            rows.append(Row(bench, f"orrc.simulate vs {label}", f"{fmt_time(o_cpu)} ({fmt_time(o_wall)})",
                            "skipped", "—", "< 1× (CPU)" if name == "acados" else "—", None, reason,
                            dict(skipped=reason)))
            continue
        gap, dx = _check(label, J_ref, X_ref, x0, report["U"], w[:T])
        p_cpu, p_wall = report["cpu"] / T, report["wall"] / T
        target = name == "acados"
        rows.append(Row(bench, f"orrc.simulate vs {label} {report['version']}",
                        f"{fmt_time(o_cpu)} ({fmt_time(o_wall)})", f"{fmt_time(p_cpu)} ({fmt_time(p_wall)})",
                        f"{p_cpu / o_cpu:.2f}× faster (wall {p_wall / o_wall:.2f}×)",
                        "orrc faster (CPU)" if target else "—", (o_cpu < p_cpu) if target else None,
                        f"{label}'s BLAS threads: {report['threads']}; rel. gap {gap:+.1e}, states {dx:.0e}",
                        dict(t_peer=p_cpu, t_peer_wall=p_wall, t_orrc=o_cpu, speedup=p_cpu / o_cpu, gap=gap,
                             peer=label, version=report['version'])))
    # python-control: the same M-step problem as orrc's at those states (its optimum checked outside the timing)
    steps = sorted(set(control_at))
    for t, (U_ct, res) in c_out:
        Wt = traj.w_all[t:t + M]
        plan = rhc.plan(traj.x[t], Wt)
        J_ct, J_o = pendulum.rollout(traj.x[t], U_ct, Wt)[1], pendulum.rollout(traj.x[t], plan.inputs, Wt)[1]
        if not res.success or abs(J_ct - J_o) > pendulum.VALUE_RTOL * abs(J_o):
            raise CheckFailed(f"python-control's step at t={t} ({J_ct:.10g}, {res.message}) is not orrc's ({J_o:.10g})")
    ct_cpu, ct_wall = float(np.median(c_cpu)), float(np.median(c_wall))
    import control
    rows.append(Row(bench, f"orrc.simulate vs python-control {control.__version__} solve_ocp (cold step)",
                    f"{fmt_time(o_cpu)} ({fmt_time(o_wall)})", f"{fmt_time(ct_cpu)} ({fmt_time(ct_wall)})",
                    f"{ct_cpu / o_cpu:.0f}× faster (wall {ct_wall / o_wall:.0f}×)", f"≥ {TARGET_CONTROL:.0f}× (CPU)",
                    ct_cpu / o_cpu >= TARGET_CONTROL,
                    f"BLAS threads: {threads}; steps t = {steps}, same optimum to {pendulum.VALUE_RTOL:g}",
                    dict(t_peer=ct_cpu, t_peer_wall=ct_wall, t_orrc=o_cpu, speedup=ct_cpu / o_cpu,
                         peer="python-control", version=control.__version__)))
    return rows
