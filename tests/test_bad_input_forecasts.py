"""Bad input to the forecasts (orrc.forecasts, simulate's ``forecast``) and the controllers that use
them (LambdaConfident, RobustPreviewRHC): a clear orrc.OrrcValueError naming the argument.

One table in the shared format of tests/bad_input.py.
"""
import numpy as np
import pytest

import orrc
from bad_input import assert_bad_input, case, params
from orrc.controllers.forecast import LambdaConfident, RobustPreviewRHC
from orrc.forecasts import AR, AdversarialError, Bias, Delay, Exact, Forecast, Noisy

EX = orrc.examples.double_integrator()
W = orrc.disturbances.uniform_ball(L=20, n=2, radius=0.1, seed=0)
PEND = orrc.examples.inverted_pendulum()
BOX = orrc.Box(-0.1, 0.1, n=2)


def rhc():
    return orrc.PreviewRHC(EX.system, EX.cost, M=3)


class Misshapen(Forecast):
    name = "misshapen"

    def window(self, t, past, truth):
        return np.zeros((1, 2))


class NotFinite(Forecast):
    name = "not finite"

    def window(self, t, past, truth):
        return np.full(truth.shape, np.nan)


CASES = [
    case("forecasts-not-a-model", lambda: orrc.simulate(EX.system, rhc(), EX.x0, W, T=5, forecast=np.zeros((5, 2))),
         "forecast must be an orrc.forecasts.Forecast", "ndarray"),
    case("forecasts-controller-without-preview",
         lambda: orrc.simulate(EX.system, orrc.LQR(EX.system, EX.cost), EX.x0, W, T=5, forecast=Exact()),
         "forecast=exact", "previews no disturbance"),
    case("forecasts-window-shape", lambda: orrc.simulate(EX.system, rhc(), EX.x0, W, T=5, forecast=Misshapen()),
         "forecast misshapen", "(3, 2) window at t=0", "(1, 2)"),
    case("forecasts-window-not-finite", lambda: orrc.simulate(EX.system, rhc(), EX.x0, W, T=5, forecast=NotFinite()),
         "forecast not finite", "non-finite"),
    case("forecasts-noisy-scale", lambda: Noisy(-1.0), "scale"),
    case("forecasts-noisy-growth", lambda: Noisy(0.1, growth=np.nan), "growth"),
    case("forecasts-noisy-seed", lambda: Noisy(0.1, seed=-3), "seed"),
    case("forecasts-bias-matrix", lambda: Bias(np.ones((2, 2))), "b must be a number or a vector"),
    case("forecasts-bias-length", lambda: orrc.simulate(EX.system, rhc(), EX.x0, W, T=5, forecast=Bias([1, 2, 3])),
         "b must be a number or a vector of length n=2", "3 entries"),
    case("forecasts-delay-negative", lambda: Delay(-1), "d"),
    case("forecasts-ar-order", lambda: AR(order=0), "order"),
    case("forecasts-ar-ridge", lambda: AR(ridge=-1.0), "ridge"),
    case("forecasts-adversarial-radius", lambda: AdversarialError(-0.1), "radius"),
    case("forecasts-adversarial-norm", lambda: AdversarialError(0.1, norm="1"), "norm", "'1'"),
    case("forecasts-errors-without-forecast",
         lambda: orrc.forecasts.forecast_errors(orrc.simulate(EX.system, rhc(), EX.x0, W, T=5)), "traj has no forecasts"),
    case("LambdaConfident-lam-range", lambda: LambdaConfident(EX.system, EX.cost, 3, lam=2.0), "lam"),
    case("LambdaConfident-lam-word", lambda: LambdaConfident(EX.system, EX.cost, 3, lam="auto"), "lam", "'auto'"),
    case("LambdaConfident-lam0", lambda: LambdaConfident(EX.system, EX.cost, 3, lam0=-0.1), "lam0"),
    case("LambdaConfident-M", lambda: LambdaConfident(EX.system, EX.cost, 0), "M"),
    case("LambdaConfident-nonlinear", lambda: LambdaConfident(orrc.examples.inverted_pendulum().system,
                                                              orrc.examples.inverted_pendulum().cost, 3),
         "LambdaConfident needs an orrc.LinearSystem and an orrc.QuadraticCost"),
    case("RobustPreviewRHC-set-type", lambda: RobustPreviewRHC(EX.system, EX.cost, 3, E=(-0.1, 0.1)),
         "E must be an orrc.Box, an orrc.Polytope or an orrc.Ball"),
    case("RobustPreviewRHC-ball-dimension", lambda: RobustPreviewRHC(EX.system, EX.cost, 3, E=orrc.Ball(0.1, n=3)),
         "E must have the state dimension"),
    case("RobustPreviewRHC-set-dimension", lambda: RobustPreviewRHC(EX.system, EX.cost, 3, E=orrc.Box(-1, 1, n=3)),
         "E must have the state dimension n=2", "R^3"),
    case("RobustPreviewRHC-M", lambda: RobustPreviewRHC(EX.system, EX.cost, 0, E=orrc.Box(-1, 1, n=2)), "M"),
    case("RobustPreviewRHC-too-many-vertex-sequences",
         lambda: RobustPreviewRHC(EX.system, EX.cost, 40, E=orrc.Box(-1, 1, n=2)), "vertex sequences", "M=40"),
    case("RobustPreviewRHC-nonlinear-set-dimension",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=orrc.Box(-1, 1, n=3)), "E must have the state dimension n=2",
         "R^3"),
    case("RobustPreviewRHC-nonlinear-polytope",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=orrc.Polytope([[0.1, 0.0], [0.0, 0.1], [-0.1, 0.0]])),
         "E is an orrc.Polytope", "method='exchange'", "orrc.Box or an orrc.Ball"),
    case("RobustPreviewRHC-nonlinear-exact",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=orrc.Box(-1, 1, n=2), method="exact"),
         "method='exact'", "NonlinearSystem", "use method='exchange'"),
    case("RobustPreviewRHC-method", lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX, method="game"),
         "method must be one of", "'game'"),
    case("RobustPreviewRHC-exchange-options",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX, exchange_options={"max_iters": 3}),
         "exchange_options", "max_iters"),
    case("RobustPreviewRHC-exchange-options-with-exact",
         lambda: RobustPreviewRHC(EX.system, EX.cost, 3, E=BOX, exchange_options={"max_iter": 3}),
         "exchange_options", "method='exact'"),
    case("RobustPreviewRHC-seed", lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX, seed=-1), "seed"),
    case("RobustPreviewRHC-tol", lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX, tol=0.0), "tol"),
    case("RobustPreviewRHC-cost-dimension",
         lambda: RobustPreviewRHC(PEND.system, orrc.QuadraticCost(np.eye(3), [[1.0]]), 3, E=BOX), "cost", "n=3"),
    case("RobustPreviewRHC-exchange-too-large",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 10**5, E=BOX), "scenario exchange", "M=100000",
         "too large"),
    case("RobustPreviewRHC-forecast-columns",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX).plan(PEND.x0, np.zeros((3, 3))),
         "w_forecast must be an array (k, n=2)", "(3, 3)"),
    case("RobustPreviewRHC-forecast-not-finite",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX).plan(PEND.x0, np.full((3, 2), np.nan)),
         "w_forecast", "finite"),
    case("RobustPreviewRHC-state-dimension",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX).plan(np.zeros(3), np.zeros((3, 2))), "x"),
    case("RobustPreviewRHC-cost-params-rows",
         lambda: RobustPreviewRHC(PEND.system, PEND.cost, 3, E=BOX).plan(PEND.x0, np.zeros((3, 2)),
                                                                         PEND.cost.default_params[None]),
         "cost_params", "M=3"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error(call, exc, words):
    assert_bad_input(call, exc, words)
