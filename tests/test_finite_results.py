"""No public function returns a non-finite number for finite input without an error or a warning.

A sweep over the public API with extreme but finite arguments (huge weights, huge states, an
unstable loop over a long T, constants at the ends of the float range, a controller that
returns V_M = NaN). Each case states its documented outcome, and the test holds it exactly:

* ``"error"``: an ``orrc.OrrcValueError`` (the arguments cannot give a representable result) or a
  ``FloatingPointError`` (``orrc.simulate`` / ``System.step``: the state diverged);
* ``"warn"``: an ``orrc.NonFiniteWarning`` saying what overflowed (a long but legitimate run);
* ``"finite"``: no warning, and every number in the result is finite.

The size limits (``orrc.config``, ``orrc.SizeWarning``) and the LQ path's ignored options are tested
at the end.
"""
import functools
import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

import orrc
from orrc import certify, checks, theory as th


@functools.cache
def di():
    return orrc.examples.double_integrator()


def unstable_zero_input(T):
    """x_{t+1} = 2 x_t + u_t + w_t with u = 0: x_t = 2^t, c_t = x_t² overflows from t = 512 on."""
    sysm = orrc.LinearSystem([[2.0]], [[1.0]])
    return orrc.simulate(sysm, orrc.ZeroInput(1, orrc.QuadraticCost([[1.0]], [[1.0]])), [1.0], np.zeros((T, 1)), T)


class NaNValue(orrc.Controller):
    """A custom controller whose V_M is NaN (a bug in user code)."""

    name = "nan value"
    cost = orrc.QuadraticCost(np.eye(2), [[1.0]])

    def control(self, obs):
        return orrc.Decision(u=np.zeros(1), value=float("nan"))


class NaNInput(NaNValue):
    name = "nan input"

    def control(self, obs):
        return orrc.Decision(u=np.array([np.nan]))


def nan_value_run():
    traj = orrc.simulate(di().system, NaNValue(), di().x0, np.zeros((5, 2)), 5)
    assert not traj.value_valid.any()  # and marked
    return traj


SWEEP = [
    # simulate: derived quantities overflow while the state stays finite -> one NonFiniteWarning
    ("simulate-huge-Q", lambda: orrc.simulate(di().system, orrc.ZeroInput(1, orrc.QuadraticCost(1e300 * np.eye(2), [[1.0]])),
                                              [1e10, 0.0], np.zeros((5, 2)), 5), "warn"),
    ("simulate-huge-x0", lambda: orrc.simulate(di().system, orrc.LQR(di().system, di().cost), [1e200, 0.0],
                                               np.zeros((5, 2)), 5), "warn"),
    ("simulate-unstable-long-T", lambda: unstable_zero_input(600), "warn"),
    ("simulate-unstable-longer-T", lambda: unstable_zero_input(1100), "error"),  # the state itself overflows
    ("simulate-controller-value-nan", nan_value_run, "warn"),
    ("simulate-controller-input-nan", lambda: orrc.simulate(di().system, NaNInput(), di().x0, np.zeros((5, 2)), 5),
     "error"),
    ("simulate-large-but-fine", lambda: orrc.simulate(di().system, orrc.LQR(di().system, di().cost), [1e100, 0.0],
                                                      np.zeros((5, 2)), 5), "finite"),
    # systems and costs at the ends of the float range
    ("LinearSystem-step-overflow", lambda: orrc.LinearSystem([[1e300]], [[1.0]]).step([1e300], [0.0], [0.0]), "error"),
    ("NonlinearSystem-step-overflow", lambda: orrc.examples.van_der_pol().system.step([1e200, 1e200], [0.0],
                                                                                      [0.0, 0.0]), "error"),
    ("QuadraticCost-value-overflow", lambda: di().cost.value([1e200, 0.0], [0.0]), "error"),
    ("QuadraticCost-sigma-overflow", lambda: di().cost.sigma([1e200, 0.0]), "error"),
    ("plan-lq-overflow", lambda: orrc.PreviewRHC(di().system, di().cost, 5).plan([1e200, 0.0], np.zeros((5, 2))),
     "error"),
    # disturbances
    ("sinusoid-huge-amplitude", lambda: orrc.disturbances.sinusoid(10, 2, amplitude=1e308), "finite"),
    ("Box-sample-wide", lambda: orrc.Box(-1e149, 1e149, n=2).sample(50, seed=0), "finite"),
    ("Box-max_norm_sq-wide", lambda: orrc.Box(-1e149, 1e149, n=2).max_norm_sq, "finite"),
    ("Ball-max_norm_sq", lambda: orrc.Ball(1e150, 2).max_norm_sq, "finite"),
    ("energy-overflow", lambda: orrc.disturbances.energy(np.full((3, 2), 1e200)), "error"),
    # theory at extreme constants
    ("horizon_threshold-far-apart", lambda: th.horizon_threshold(1e-160, 1e160), "error"),
    ("Gamma_V-far-apart", lambda: th.Gamma_V(2, 1e-300, 1e10), "error"),
    ("gamma_c-overflow", lambda: th.gamma_c(10 ** 9, 0.999999999, 1e-3, 1.0, 1e300), "error"),
    ("gamma_tilde-underflow", lambda: th.gamma_tilde(1e-320, 1e-300), "error"),
    ("lemma2_coefficients-overflow", lambda: th.lemma2_coefficients(10, 12, 1 - 1e-16, 2.0, 1.0, 1e300), "error"),
    ("theorem1_constant-overflow", lambda: th.theorem1_constant(1e307, np.zeros((30, 1)), 20, 10, 0.99, 1.0, 2.0, 1.0,
                                                                1e9), "error"),
    ("gamma_c-large-but-fine", lambda: th.gamma_c(10 ** 6, 0.999999, 1e-2, 1.0, 1e10), "finite"),
    # certify
    ("lq_constants-overflow", lambda: certify.lq_constants(orrc.LinearSystem([[1e200]], [[1.0]]),
                                                           orrc.QuadraticCost([[1.0]], [[1.0]]), 5), "error"),
    ("alpha_hi_floor-unstabilisable", lambda: certify.alpha_hi_floor(orrc.LinearSystem([[2.0]], [[0.0]]),
                                                                     orrc.QuadraticCost([[1.0]], [[1.0]]), [600]),
     "error"),
    ("Constants-bound-overflow", lambda: certify.lq_constants(di().system, di().cost, 5, grid=30).bound(1e308, 1e308),
     "error"),
    ("worst_case_attenuation-unstable-long", lambda: certify.worst_case_attenuation(
        orrc.LinearSystem([[3.0]], [[1.0]]), orrc.ZeroInput(1, orrc.QuadraticCost([[1.0]], [[1.0]])), 700), "error"),
    # metrics and checks on an overflowed run refuse it
    ("attenuation_regret-overflowed-run", lambda: orrc.attenuation_regret(unstable_zero_input(600), 1.0), "error"),
    ("attenuation_ratio-overflow", lambda: orrc.attenuation_ratio(orrc.simulate(
        di().system, orrc.ZeroInput(1, orrc.QuadraticCost(1e300 * np.eye(2), [[1.0]])), [10.0, 0.0],
        np.full((5, 2), 1e-150), 5)), "error"),  # Σc ≈ 5e302 over Σ‖w‖² = 1e-299
    ("lemma1_margins-nan-values", lambda: checks.lemma1_margins(nan_value_run(), 2, 1.0, 2.0, 1.0), "error"),
]


def _all_finite(out) -> bool:
    if isinstance(out, orrc.Trajectory):
        parts = [out.x, out.u, out.costs, out.sigma] + ([] if out.values is None else [out.values])
        return all(np.all(np.isfinite(p)) for p in parts)
    return bool(np.all(np.isfinite(out)))


@pytest.mark.parametrize("call, outcome", [pytest.param(c, o, id=i) for i, c, o in SWEEP])
def test_finite_input_never_gives_a_silent_non_finite_result(call, outcome):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        try:
            out = call()
        except (orrc.OrrcValueError, FloatingPointError) as exc:
            assert outcome == "error", f"unexpected error: {exc}"
            return
    nonfinite = [r for r in rec if issubclass(r.category, orrc.NonFiniteWarning)]
    assert outcome != "error", f"expected an error; got {out!r}"
    if outcome == "warn":
        assert len(nonfinite) == 1 and any(k in str(nonfinite[0].message) for k in ("overflowed", "non-finite V_M"))
    else:
        assert not rec, [str(r.message) for r in rec]
        assert _all_finite(out)


def test_the_nonfinite_warning_names_the_quantities_and_the_first_step():
    with pytest.warns(orrc.NonFiniteWarning, match=r"stage costs c_t at 88 steps from t=512.*overflowed"):
        traj = unstable_zero_input(600)
    assert np.isfinite(traj.x).all() and np.isinf(traj.costs[512:]).all() and np.isfinite(traj.costs[:512]).all()


# -- size limits -------------------------------------------------------------------------------------
def test_size_limits_refuse_with_the_estimate_and_the_limit_and_can_be_raised():
    box = orrc.Box(-1.0, 1.0, n=12)
    with orrc.config.limits(max_bytes=1e5) as lim:
        assert lim.max_bytes == 1e5 and lim.warn_bytes == 1e5  # a warning threshold never exceeds its limit
        with pytest.raises(orrc.OrrcValueError, match=r"n=12.*about 1.12 MiB of memory \(the limit is 97.7 KiB\)"):
            box.vertices()
    assert orrc.config.get_limits() == orrc.config.Limits()  # restored after the block
    V = box.vertices()
    assert V.shape == (4096, 12) and {tuple(v) for v in V} == {tuple(v) for v in
                                                               __import__("itertools").product([-1.0, 1.0], repeat=12)}


def test_a_large_but_allowed_computation_warns():
    with orrc.config.limits(warn_ops=1e5):
        with pytest.warns(orrc.SizeWarning, match=r"Ms.*=300.*a large computation"):
            certify.alpha_hi_floor(di().system, di().cost, [300])


def test_set_limits_returns_the_previous_limits_for_restoring():
    previous = orrc.config.set_limits(max_ops=math.inf)
    try:
        assert orrc.config.get_limits().max_ops == math.inf
    finally:
        orrc.config.set_limits(**vars(previous))
    assert orrc.config.get_limits() == previous


@pytest.mark.parametrize("value, ok", [("5e3", True), ("lots", False)])
def test_limits_come_from_the_environment(value, ok):
    code = ("import orrc\n"
            "try:\n    orrc.Box(-1.0, 1.0, n=8).vertices(); print('ran')\n"
            "except orrc.OrrcValueError as e:\n    print(e)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={"ORRC_MAX_BYTES": value, "PATH": ""}).stdout
    if ok:
        assert "the limit is 4.88 KiB" in out
    else:
        assert "ORRC_MAX_BYTES must be a positive number" in out and "'lots'" in out


def test_solver_options_on_the_lq_path_are_not_silently_ignored():
    with pytest.warns(UserWarning, match=r"solver_options \['ipopt.max_iter'\] are ignored.*solver='nlp'"):
        rhc = orrc.PreviewRHC(di().system, di().cost, 5, solver_options={"ipopt.max_iter": 3})
    assert rhc.solver == "lq"
