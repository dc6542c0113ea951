"""Bad input to the baselines of the comparison chapter and to the game solvers: a clear OrrcValueError naming the
argument, what was given and what is allowed (one table, one case per row)."""
import numpy as np
import pytest

import orrc
from orrc import certify
from orrc.solvers import game
from bad_input import assert_bad_input, case, params

ex = orrc.examples.scalar_unstable()
S, C = ex.system, ex.cost
UNSTAB = orrc.LinearSystem(np.diag([1.5, 2.0]), [[1.0], [0.0]])        # mode 2 cannot be moved
UNSTAB_COST = orrc.QuadraticCost(np.eye(2), [[1.0]])
PEND = orrc.examples.inverted_pendulum()
I1 = np.eye(1)

CASES = [
    case("HInfinity-unstabilisable", lambda: orrc.HInfinity(UNSTAB, UNSTAB_COST), "not stabilisable"),
    case("HInfinity-gamma-below-level", lambda: orrc.HInfinity(S, C, gamma=4.0), "gamma = 4 is not above the optimal level 5"),
    case("HInfinity-preview-gamma-below", lambda: orrc.HInfinity(S, C, gamma=0.4, preview=3), "optimal level 0.5"),
    case("HInfinity-gamma-negative", lambda: orrc.HInfinity(S, C, gamma=-1.0), "gamma must be > 0"),
    case("HInfinity-gamma-nan", lambda: orrc.HInfinity(S, C, gamma=float("nan")), "gamma must be finite"),
    case("HInfinity-preview-negative", lambda: orrc.HInfinity(S, C, preview=-1), "preview must be an integer >= 0"),
    case("HInfinity-preview-float", lambda: orrc.HInfinity(S, C, preview=1.5), "preview must be an integer"),
    case("HInfinity-cost-type", lambda: orrc.HInfinity(S, "cost"), "QuadraticCost"),
    case("HInfinity-system-type", lambda: orrc.HInfinity("sys", C), "system must be"),
    case("game-gamma-below", lambda: game.finite_horizon_game([[2.0]], [[1.0]], I1, I1, 0.5, 5),
     "gamma = 0.5 is below the smallest admissible level"),
    case("game-M-zero", lambda: game.finite_horizon_game([[2.0]], [[1.0]], I1, I1, 10.0, 0), "M must be an integer >= 1"),
    case("game-A-shape", lambda: game.stationary_game(np.ones((2, 3)), [[1.0]], I1, I1, 10.0), "A must be square"),
    case("game-B-shape", lambda: game.stationary_game([[2.0]], np.ones((2, 1)), I1, I1, 10.0), "B must have shape (1, m)"),
    case("game-Q-nonfinite", lambda: game.stationary_game([[2.0]], [[1.0]], [[np.inf]], I1, 10.0), "Q must be finite"),
    case("game-R-singular", lambda: game.stationary_game([[2.0]], [[1.0]], I1, [[0.0]], 10.0), "R must be positive definite"),
    case("game-E-shape", lambda: game.optimal_game_level([[2.0]], [[1.0]], I1, I1, E=np.ones((3, 1))), "E must have shape (1, q)"),
    case("game-unstabilisable", lambda: game.optimal_game_level(UNSTAB.A, UNSTAB.B, np.eye(2), I1), "not stabilisable"),
    case("game-tol", lambda: game.optimal_game_level([[2.0]], [[1.0]], I1, I1, tol=0.0), "tol must be > 0"),
    case("game-with-error-type", lambda: game.optimal_game_level([[2.0]], [[1.0]], I1, I1, with_error="yes"),
         "with_error must be True or False; got 'yes'"),
    case("game-gamma-at-level", lambda: game.stationary_game([[2.0]], [[1.0]], I1, I1, 5.0),
         "gamma = 5 is not above the optimal level 5 (within"),
    case("PreviewRHC-preview-too-long", lambda: orrc.PreviewRHC(S, C, 5, preview_w=6), "preview_w must be between 0 and M = 5"),
    case("PreviewRHC-preview-negative", lambda: orrc.PreviewRHC(S, C, 5, preview_w=-1), "preview_w must be an integer >= 0"),
    case("PreviewRHC-preview-plan-short", lambda: orrc.PreviewRHC(S, C, 5, preview_w=3).plan([0.0], np.zeros((2, 1))),
     "w_preview must have shape (k, n) = (3, 1)"),
    case("GPC-nonlinear", lambda: orrc.GPC(PEND.system, PEND.cost), "GPC needs a LinearSystem"),
    case("GPC-cost-type", lambda: orrc.GPC(S, orrc.Cost(lambda x, u: x[0] ** 2, 1, 1)), "QuadraticCost"),
    case("GPC-H-zero", lambda: orrc.GPC(S, C, H=0), "H must be an integer >= 1"),
    case("GPC-lr-zero", lambda: orrc.GPC(S, C, lr=0.0), "lr must be > 0"),
    case("GPC-K-unstable", lambda: orrc.GPC(S, C, K=[[0.0]]), "K must stabilise"),
    case("GPC-K-shape", lambda: orrc.GPC(S, C, K=[[1.0, 2.0]]), "K must have shape (1, 1)"),
    case("GPC-unstabilisable", lambda: orrc.GPC(UNSTAB, UNSTAB_COST), "no stabilising LQR gain"),
    case("DisturbanceAction-M-shape", lambda: orrc.DisturbanceAction(S, C, np.zeros((2, 2, 1))), "M must have shape (H, m, n) = (H, 1, 1)"),
    case("best_fixed_policy-w-short", lambda: orrc.controllers.gpc.best_fixed_policy(S, C, np.zeros((5, 1)), 10, 3),
     "w must have shape (L, 1) with L >= T = 10"),
    case("RegretOptimal-T-too-large", lambda: orrc.RegretOptimal(S, C, 40, method="sdp"),
         "T = 40 is too large for the regret-optimal SDP"),
    case("RegretOptimal-T-limit-stated", lambda: orrc.RegretOptimal(S, C, 33, method="sdp"), "limit 64"),
    case("RegretOptimal-T-beyond-the-structured-limits", lambda: orrc.RegretOptimal(S, C, 10 ** 6),
         "RegretOptimal over T=1000000 steps"),
    case("RegretOptimal-method-unknown", lambda: orrc.RegretOptimal(S, C, 4, method="lmi"),
         "method must be one of 'structured', 'sdp'"),
    case("RegretOptimal-T-small", lambda: orrc.RegretOptimal(S, C, 1), "T must be an integer >= 2"),
    case("RegretOptimal-nonlinear", lambda: orrc.RegretOptimal(PEND.system, PEND.cost, 5), "RegretOptimal needs a LinearSystem"),
    case("RegretOptimal-x0-nonzero", lambda: orrc.simulate(S, orrc.RegretOptimal(S, C, 4), [1.0], np.zeros((4, 1)), 4),
     "designed from x_0 = 0"),
    case("RegretOptimal-run-too-long", lambda: orrc.simulate(S, orrc.RegretOptimal(S, C, 4), [0.0], np.zeros((6, 1)), 6),
     "designed for T = 4 steps"),
    case("worst_case_regret-gpc-learning", lambda: certify.worst_case_regret(S, orrc.GPC(S, C), 5), "freeze it first"),
    case("worst_case_regret-T-zero", lambda: certify.worst_case_regret(S, orrc.LQR(S, C), 0), "T must be an integer >= 1"),
    case("worst_case_regret-nonlinear-rhc", lambda: certify.worst_case_regret(S, orrc.PreviewRHC(S, C, 3, input_bounds=(-1, 1)), 5),
     "PreviewRHC on the exact LQ path"),
    case("worst_case_regret-beyond-ro-horizon", lambda: certify.worst_case_regret(S, orrc.RegretOptimal(S, C, 4), 6),
     "beyond the horizon T = 4"),
    case("worst_case_attenuation_limit-regret-optimal", lambda: certify.worst_case_attenuation_limit(S, orrc.RegretOptimal(S, C, 4)),
     "time-invariant controller"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error(call, exc, words):
    assert_bad_input(call, exc, words)
