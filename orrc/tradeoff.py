"""Theorem 2's exploration trade-off, measured: how long should Algorithm 2 excite the system?

Theorem 2 bounds R^p_T(γ) by O(N) + O(1) + O((T - N + 1) g(N)): every exciting step costs, and
every control step pays for the estimation error g(N). For g(N) = Θ(1/√N) the bound is smallest
at N = Θ(T^{2/3}). :func:`exploration_tradeoff` measures both parts on closed loops of
:class:`~orrc.EstimateThenControl` run by :func:`orrc.simulate`, for a grid of N and several
seeds, and :class:`Tradeoff` finds the best N for each T.

What is measured, for each seed and each N (one closed loop of N + ``window`` steps):

* E(N) = Σ_{t<N} c_t, the cost of the estimation phase;
* ℓ(N) = the mean per-step cost of the control phase (after a burn-in of ``burn_in`` steps) minus
  that of Algorithm 1 on the true system on the *same* disturbances (one run per seed): the loss
  per step caused by the estimation error (common random numbers make the difference precise);
* the estimation error ‖θ̂ - θ‖ (g(N)).

With θ̂ fixed and i.i.d. disturbances the control phase is a stationary process, so its excess
cost over T - N steps is (T - N) ℓ(N) plus the burn-in transient: the trade-off curve is
Δ(N, T) = E(N) - N c₀ + transient(N) + (T - N) ℓ(N), the cost of not knowing θ over T steps
(c₀: the known-system cost per step). Its minimiser over N is the best N for T.

Averaged over seeds, ℓ(N) is still noisy (it is proportional to a random |θ̂ - θ|), and the raw
minimiser of a flat curve jumps between grid points. :meth:`Tradeoff.best_N` therefore minimises the
*fitted* curve: E(N) - N c₀ + transient fitted by a line in N, ℓ(N) by κ N^(-p) with the exponent
p fitted (log-log least squares) from the data, never assumed. The minimiser is searched only
inside the measured range of N (no extrapolation). The raw minimisers are reported too
(``fitted=False``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._validate import OrrcValueError, as_array, as_bool, as_float, as_int, check_size
from ._problem import check_problem
from .estimation.edmd import EDMD
from .parametric import ParametricSystem

__all__ = ["Tradeoff", "exploration_tradeoff"]

#: operations of one simulated closed-loop step of Algorithm 2 (about 0.1 ms: a small QP, or the LQ law)
_STEP_OPS = 1e5


@dataclass
class Tradeoff:
    """The measured exploration trade-off of Theorem 2 (see the module docstring).

    Attributes
    ----------
    Ns : (k,) the estimation-phase lengths N.
    explore_cost : (S, k) E(N) = Σ_{t<N} c_t per seed.
    known_cost : (S, k) Σ_{t<N} c_t of Algorithm 1 on the true system (same disturbances).
    transient : (S, k) Σ over the burn-in of (c_t - c_t^known).
    loss : (S, k) ℓ(N): control-phase cost per step minus the known system's, after the burn-in.
    errors : (S, k) ‖θ̂ - θ‖ (g(N)).
    c0 : mean per-step cost of the known system.
    fit : the fitted curve: ``slope_e`` and ``offset_e`` of E(N) - N c₀ + transient, ``kappa`` and
        ``p`` of ℓ(N) = κ N^(-p), and ``g_p``, ``g_kappa`` of g(N) = κ_g N^(-p_g).

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> di = orrc.examples.double_integrator()
    >>> result = tradeoff.exploration_tradeoff(di.system,
    ...                                        orrc.ParametricSystem.linear(2, 1), di.cost,
    ...                                        M=5, Ns=[3, 6, 12], seeds=2, window=30,
    ...                                        backend="serial")
    >>> result.Ns, result.explore_cost.shape, result.loss.shape
    (array([ 3.,  6., 12.]), (2, 3), (2, 3))
    """

    Ns: np.ndarray
    explore_cost: np.ndarray
    known_cost: np.ndarray
    transient: np.ndarray
    loss: np.ndarray
    errors: np.ndarray
    c0: float
    window: int
    burn_in: int
    fit: dict = field(default_factory=dict)

    @property
    def seeds(self) -> int:
        return self.explore_cost.shape[0]

    def mean(self, name: str) -> np.ndarray:
        """The seed average of one measured array (``explore_cost``, ``loss``, ``errors``, ...)."""
        return getattr(self, name).mean(axis=0)

    def up_front(self) -> np.ndarray:
        """E(N) - (the known system's cost over the same N steps) + transient: the O(N) part (seed mean)."""
        return self.mean("explore_cost") - self.mean("known_cost") + self.mean("transient")

    def excess(self, T) -> np.ndarray:
        """Δ(N, T) for every N of the grid (seed mean): the measured cost of not knowing θ over T steps."""
        T = as_float("T", T, minimum=1.0)
        return self.up_front() + (T - self.Ns) * self.mean("loss")

    def fitted_excess(self, N, T) -> np.ndarray:
        """The fitted trade-off curve at N (array): slope_e N + offset_e + (T - N) κ N^(-p)."""
        f = self.fit
        N = np.asarray(N, dtype=float)
        return f["slope_e"] * N + f["offset_e"] + (T - N) * f["kappa"] * N ** (-f["p"])

    def best_N(self, Ts, fitted: bool = True) -> np.ndarray:
        """The best estimation-phase length for each T: the minimiser over N of the fitted curve
        (``fitted=True``, searched on a fine grid inside [min N, max N]), or of the raw seed-mean
        curve over the grid of N (``fitted=False``)."""
        Ts = np.atleast_1d(as_array("Ts", Ts))
        if np.any(Ts < 1):
            raise OrrcValueError(f"Ts must be >= 1; got minimum {Ts.min()}")
        if not as_bool("fitted", fitted):
            return np.array([self.Ns[int(np.argmin(self.excess(T)))] for T in Ts], dtype=float)
        grid = np.geomspace(self.Ns[0], self.Ns[-1], 2000)
        return np.array([grid[int(np.argmin(self.fitted_excess(grid, T)))] for T in Ts])

    def interior(self, Ts) -> np.ndarray:
        """True where the fitted best N lies strictly inside the measured range of N (not at its ends)."""
        b = self.best_N(Ts)
        return (b > self.Ns[0] * 1.0001) & (b < self.Ns[-1] / 1.0001)

    def slope(self, Ts, fitted: bool = True) -> float:
        """The log-log slope of the best N against T (least squares over ``Ts``): 2/3 for g(N) ∝ 1/√N and
        a loss linear in the error."""
        Ts = np.atleast_1d(as_array("Ts", Ts))
        if Ts.size < 2:
            raise OrrcValueError("Ts must hold at least two horizons T to fit a slope")
        return float(np.polyfit(np.log(Ts), np.log(self.best_N(Ts, fitted)), 1)[0])


def exploration_tradeoff(system, model, cost, M: int, Ns, seeds: int = 10, window: int = 300,
                         burn_in: int | None = None, excitation_amplitude: float = 1.0, w_radius: float = 0.5,
                         use_w: bool = False, theta_true=None, x0=None, input_bounds=None, seed: int = 0,
                         backend: str | None = None, client=None) -> Tradeoff:
    """Measure Theorem 2's trade-off for Algorithm 2 on ``system`` (see the module docstring).

    Parameters
    ----------
    system : the true system (simulated).
    model : the controller's model (a ParametricSystem, e.g. ``ParametricSystem.linear(n, m)``).
    cost, M : the stage cost and the horizon of the control phase.
    Ns : the estimation-phase lengths to measure (increasing integers >= 1).
    seeds : number of independent runs to average (run s uses the seeds ``seed + s``).
    window : control steps measured after each estimation phase; ``burn_in`` (default 2M) of them are the
        transient, the rest give the per-step loss.
    excitation_amplitude : PRBS amplitude of the estimation phase (``orrc.estimation.prbs``, nested in N).
    w_radius : the disturbances are i.i.d. uniform in the box [-w_radius, w_radius]^n (they are noise to an
        estimator with ``use_w=False``, the default: g(N) = Θ(1/√N)).
    theta_true : the true θ, to report ‖θ̂ - θ‖ (the controller does not use it).
    x0 : initial state (default 0).

    backend, client : where the seeds run, one task per seed (:func:`orrc.sweep`'s backends: "auto" by default,
        "serial", "processes" on the local cores, or a Dask ``client``); the results are the same whatever the backend.

    Every closed loop is an :func:`orrc.simulate` run of :class:`~orrc.EstimateThenControl`; the known
    system's runs are :class:`~orrc.PreviewRHC` on ``system``. Cost: seeds·Σ_N (N + window) + seeds·(max N +
    window) simulated steps.

    Returns
    -------
    Tradeoff
        per seed and N (arrays (seeds, len(Ns))): the exploration cost, the control-phase loss per
        step, the estimation error, and the fitted curves.

    Raises
    ------
    orrc.OrrcValueError
        When Ns are not increasing integers >= 1, the model does not match the system, or the runs
        exceed the size limits.

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> di = orrc.examples.double_integrator()
    >>> result = tradeoff.exploration_tradeoff(di.system,
    ...                                        orrc.ParametricSystem.linear(2, 1), di.cost,
    ...                                        M=5, Ns=[3, 6, 12], seeds=2, window=30,
    ...                                        backend="serial")
    >>> # exploring longer costs more
    >>> bool((result.explore_cost[:, -1] > result.explore_cost[:, 0]).all())
    True
    """
    import functools

    from .sweep import sweep

    Ns = np.asarray(Ns)
    if Ns.ndim != 1 or Ns.size < 3 or not np.issubdtype(Ns.dtype, np.integer) or np.any(Ns < 1) \
            or np.any(np.diff(Ns) <= 0):
        raise OrrcValueError(f"Ns must be at least three increasing integers >= 1; got {Ns!r}")
    seeds = as_int("seeds", seeds, minimum=1)
    seed = as_int("seed", seed, minimum=0)
    M = as_int("M", M, minimum=1)
    window = as_int("window", window, minimum=2)
    burn_in = 2 * M if burn_in is None else as_int("burn_in", burn_in, minimum=0)
    if burn_in >= window:
        raise OrrcValueError(f"burn_in must be < window = {window}; got {burn_in}")
    amp = as_float("excitation_amplitude", excitation_amplitude, minimum=0.0, strict_min=True)
    w_radius = as_float("w_radius", w_radius, minimum=0.0, strict_min=True)
    _check_models(system, model, cost)
    use_w = as_bool("use_w", use_w)
    if theta_true is not None and not isinstance(model, EDMD):
        theta_true = model.check_theta(theta_true, "theta_true")
    x0 = np.zeros(system.n) if x0 is None else as_array("x0", x0, (system.n,))
    steps = seeds * (int(Ns.sum()) + Ns.size * window + int(Ns[-1]) + window)
    check_size(f"exploration_tradeoff with seeds={seeds}, window={window}, N up to {int(Ns[-1])}: {steps} simulated steps",
               ops=steps * _STEP_OPS, hint="use fewer seeds, a shorter window or smaller N")
    one = functools.partial(_one_seed, system=system, model=model, cost=cost, M=M, Ns=Ns, window=window,
                            burn_in=burn_in, amp=amp, w_radius=w_radius, use_w=use_w, theta_true=theta_true, x0=x0,
                            input_bounds=input_bounds, seed=seed)
    rows = sweep(one, {"s": list(range(seeds))}, backend=backend, client=client, ops_per_call=steps * _STEP_OPS / seeds)
    E, Ek, tr, loss, err = (np.array([row[name] for row in rows])
                            for name in ("explore", "known", "transient", "loss", "error"))
    c0s = [row["c0"] for row in rows]
    out = Tradeoff(Ns=Ns.astype(float), explore_cost=E, known_cost=Ek, transient=tr, loss=loss, errors=err,
                   c0=float(np.mean(c0s)), window=window, burn_in=burn_in)
    out.fit = _fit(out)
    return out


def _check_models(system, model, cost) -> None:
    """The problem checked here, before the sweep (in its workers an error would arrive wrapped in a
    SweepError): the true system, the controller's model of it and the cost, of matching dimensions."""
    check_problem(system, cost)
    if not isinstance(model, (ParametricSystem, EDMD)):
        raise OrrcValueError(f"model must be an orrc.ParametricSystem (θ unknown) or an orrc.estimation.EDMD; got "
                             f"{type(model).__name__}")
    if model.n != system.n or (isinstance(model, ParametricSystem) and model.m != system.m):
        raise OrrcValueError(f"model must have the dimensions of system (n={system.n}, m={system.m}); got "
                             f"n={model.n}" + (f", m={model.m}" if isinstance(model, ParametricSystem) else ""))


def _one_seed(s, system, model, cost, M, Ns, window, burn_in, amp, w_radius, use_w, theta_true, x0, input_bounds,
              seed) -> dict:
    """The measurements of :func:`exploration_tradeoff` for seed ``seed + s``: one disturbance and one PRBS for every N
    (nested in N), the known system's run on them, and one run of Algorithm 2 per N."""
    from . import disturbances
    from .controllers import EstimateThenControl, PreviewRHC
    from .estimation import prbs
    from .simulate import simulate

    n, m, k = system.n, system.m, Ns.size
    E, Ek, tr, loss, err = (np.zeros(k) for _ in range(5))
    known = PreviewRHC(system, cost, M, input_bounds=input_bounds)
    L = int(Ns[-1]) + window
    w = disturbances.uniform_box(L + M, n, -w_radius, w_radius, seed=np.random.default_rng([seed + s, 1]))
    exc = prbs(int(Ns[-1]), m, amplitude=amp, seed=np.random.default_rng([seed + s, 2]))
    ref = simulate(system, known, x0, w, L).costs
    for i, N in enumerate(Ns):
        N = int(N)
        etc = EstimateThenControl(model, cost, M, N, excitation=exc[:N], use_w=use_w, theta_true=theta_true,
                                  input_bounds=input_bounds)
        c = simulate(system, etc, x0, w, N + window).costs
        E[i], Ek[i] = c[:N].sum(), ref[:N].sum()
        tr[i] = (c[N:N + burn_in] - ref[N:N + burn_in]).sum()
        loss[i] = (c[N + burn_in:N + window] - ref[N + burn_in:N + window]).mean()
        info = etc.record()
        err[i] = np.nan if info["theta_error"] is None else info["theta_error"]
    return {"explore": E, "known": Ek, "transient": tr, "loss": loss, "error": err, "c0": float(ref.mean())}


def _fit(t: Tradeoff) -> dict:
    """Least-squares fits of the two parts of the trade-off and of g(N) (see :class:`Tradeoff`)."""
    N = t.Ns
    slope_e, offset_e = np.polyfit(N, t.up_front(), 1)
    ell = t.mean("loss")
    ok = ell > 0
    if ok.sum() < 2:
        raise OrrcValueError("the measured control-phase loss is not positive at two N or more: the estimation error "
                             "does not cost anything measurable here (g(N) = 0, or too few seeds)")
    p_neg, logk = np.polyfit(np.log(N[ok]), np.log(ell[ok]), 1)
    fit = {"slope_e": float(slope_e), "offset_e": float(offset_e), "kappa": float(math.exp(logk)),
           "p": float(-p_neg), "loss_points": int(ok.sum())}
    g = t.mean("errors")
    if np.all(np.isfinite(g)) and np.all(g > 0):
        gp, gk = np.polyfit(np.log(N), np.log(g), 1)
        fit.update(g_p=float(-gp), g_kappa=float(math.exp(gk)))
    return fit
