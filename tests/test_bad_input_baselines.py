"""Bad input to the baselines of issue 14 and to the game solvers: a clear OrrcValueError naming the
argument, what was given and what is allowed (one table, one case per row)."""
import numpy as np
import pytest

import orrc
from orrc import certify
from orrc.solvers import game

ex = orrc.examples.scalar_unstable()
S, C = ex.system, ex.cost
UNSTAB = orrc.LinearSystem(np.diag([1.5, 2.0]), [[1.0], [0.0]])        # mode 2 cannot be moved
UNSTAB_COST = orrc.QuadraticCost(np.eye(2), [[1.0]])
PEND = orrc.examples.inverted_pendulum()
I1 = np.eye(1)

CASES = [
    ("hinf-unstabilisable", lambda: orrc.HInfinity(UNSTAB, UNSTAB_COST), "not stabilisable"),
    ("hinf-gamma-below-level", lambda: orrc.HInfinity(S, C, gamma=4.0), "gamma = 4 is not above the optimal level 5"),
    ("hinf-preview-gamma-below", lambda: orrc.HInfinity(S, C, gamma=0.4, preview=3), "optimal level 0.5"),
    ("hinf-gamma-negative", lambda: orrc.HInfinity(S, C, gamma=-1.0), "gamma must be > 0"),
    ("hinf-gamma-nan", lambda: orrc.HInfinity(S, C, gamma=float("nan")), "gamma must be finite"),
    ("hinf-preview-negative", lambda: orrc.HInfinity(S, C, preview=-1), "preview must be an integer >= 0"),
    ("hinf-preview-float", lambda: orrc.HInfinity(S, C, preview=1.5), "preview must be an integer"),
    ("hinf-cost-type", lambda: orrc.HInfinity(S, "cost"), "QuadraticCost"),
    ("hinf-system-type", lambda: orrc.HInfinity("sys", C), "system must be"),
    ("game-gamma-below", lambda: game.finite_horizon_game([[2.0]], [[1.0]], I1, I1, 0.5, 5),
     "gamma = 0.5 is below the smallest admissible level"),
    ("game-M-zero", lambda: game.finite_horizon_game([[2.0]], [[1.0]], I1, I1, 10.0, 0), "M must be an integer >= 1"),
    ("game-A-shape", lambda: game.stationary_game(np.ones((2, 3)), [[1.0]], I1, I1, 10.0), "A must be square"),
    ("game-B-shape", lambda: game.stationary_game([[2.0]], np.ones((2, 1)), I1, I1, 10.0), "B must have shape (1, m)"),
    ("game-Q-nonfinite", lambda: game.stationary_game([[2.0]], [[1.0]], [[np.inf]], I1, 10.0), "Q must be finite"),
    ("game-R-singular", lambda: game.stationary_game([[2.0]], [[1.0]], I1, [[0.0]], 10.0), "R must be positive definite"),
    ("game-E-shape", lambda: game.optimal_game_level([[2.0]], [[1.0]], I1, I1, E=np.ones((3, 1))), "E must have shape (1, q)"),
    ("game-unstabilisable", lambda: game.optimal_game_level(UNSTAB.A, UNSTAB.B, np.eye(2), I1), "not stabilisable"),
    ("game-tol", lambda: game.optimal_game_level([[2.0]], [[1.0]], I1, I1, tol=0.0), "tol must be > 0"),
    ("rhc-preview-too-long", lambda: orrc.PreviewRHC(S, C, 5, preview_w=6), "preview_w must be between 0 and M = 5"),
    ("rhc-preview-negative", lambda: orrc.PreviewRHC(S, C, 5, preview_w=-1), "preview_w must be an integer >= 0"),
    ("rhc-preview-plan-short", lambda: orrc.PreviewRHC(S, C, 5, preview_w=3).plan([0.0], np.zeros((2, 1))),
     "w_preview must have shape (k, n) = (3, 1)"),
    ("gpc-nonlinear", lambda: orrc.GPC(PEND.system, PEND.cost), "GPC needs a LinearSystem"),
    ("gpc-cost-type", lambda: orrc.GPC(S, orrc.Cost(lambda x, u: x[0] ** 2, 1, 1)), "QuadraticCost"),
    ("gpc-H-zero", lambda: orrc.GPC(S, C, H=0), "H must be an integer >= 1"),
    ("gpc-lr-zero", lambda: orrc.GPC(S, C, lr=0.0), "lr must be > 0"),
    ("gpc-K-unstable", lambda: orrc.GPC(S, C, K=[[0.0]]), "K must stabilise"),
    ("gpc-K-shape", lambda: orrc.GPC(S, C, K=[[1.0, 2.0]]), "K must have shape (1, 1)"),
    ("gpc-unstabilisable", lambda: orrc.GPC(UNSTAB, UNSTAB_COST), "no stabilising LQR gain"),
    ("dac-M-shape", lambda: orrc.DisturbanceAction(S, C, np.zeros((2, 2, 1))), "M must have shape (H, m, n) = (H, 1, 1)"),
    ("best-fixed-w-short", lambda: orrc.controllers.gpc.best_fixed_policy(S, C, np.zeros((5, 1)), 10, 3),
     "w must have shape (L, 1) with L >= T = 10"),
    ("ro-T-too-large", lambda: orrc.RegretOptimal(S, C, 40), "T = 40 is too large for the regret-optimal SDP"),
    ("ro-T-limit-stated", lambda: orrc.RegretOptimal(S, C, 33), "limit 64"),
    ("ro-T-small", lambda: orrc.RegretOptimal(S, C, 1), "T must be an integer >= 2"),
    ("ro-nonlinear", lambda: orrc.RegretOptimal(PEND.system, PEND.cost, 5), "RegretOptimal needs a LinearSystem"),
    ("ro-x0-nonzero", lambda: orrc.simulate(S, orrc.RegretOptimal(S, C, 4), [1.0], np.zeros((4, 1)), 4),
     "designed from x_0 = 0"),
    ("ro-run-too-long", lambda: orrc.simulate(S, orrc.RegretOptimal(S, C, 4), [0.0], np.zeros((6, 1)), 6),
     "designed for T = 4 steps"),
    ("regret-gpc-learning", lambda: certify.worst_case_regret(S, orrc.GPC(S, C), 5), "freeze it first"),
    ("regret-T-zero", lambda: certify.worst_case_regret(S, orrc.LQR(S, C), 0), "T must be an integer >= 1"),
    ("regret-nonlinear-rhc", lambda: certify.worst_case_regret(S, orrc.PreviewRHC(S, C, 3, input_bounds=(-1, 1)), 5),
     "PreviewRHC on the exact LQ path"),
    ("regret-beyond-ro-horizon", lambda: certify.worst_case_regret(S, orrc.RegretOptimal(S, C, 4), 6),
     "beyond the horizon T = 4"),
    ("limit-regret-optimal", lambda: certify.worst_case_attenuation_limit(S, orrc.RegretOptimal(S, C, 4)),
     "time-invariant controller"),
]


@pytest.mark.parametrize("call, words", [(c, w) for _, c, w in CASES], ids=[i for i, _, _ in CASES])
def test_bad_input_is_a_clear_error(call, words):
    with pytest.raises(orrc.OrrcValueError) as err:
        call()
    assert words in str(err.value)
