"""Bad input to the Lemma 6 search (orrc.certify.lemma6): a clear orrc.OrrcValueError.

One table in the shared format of tests/bad_input.py: each case an id, a zero-argument callable
and the words its message must contain (at least the argument's name).
"""
import numpy as np
import pytest

import orrc
from orrc import certify
from bad_input import assert_bad_input, case, params

EX = orrc.examples.scalar_unstable(A=1.2)
SYS, COST = EX.system, EX.cost
W1 = orrc.Box(-0.3, 0.3)
SYS3 = orrc.LinearSystem(np.eye(3), np.ones((3, 1)))
COST3 = orrc.QuadraticCost(np.eye(3), np.eye(1))
SYS2 = orrc.LinearSystem(np.eye(2), np.ones((2, 1)))
COST2 = orrc.QuadraticCost(np.eye(2), np.eye(1))
COST_SINGULAR = orrc.QuadraticCost(np.zeros((1, 1)), np.eye(1))


def _case(**kw):
    args = {"system": SYS, "cost": COST, "M": 3, "W": W1}
    args.update(kw)
    return lambda: certify.lemma6_case(**args)


def _search(**kw):
    return lambda: certify.lemma6_search(**kw)


CASES = [
    case("lemma6_case-three-states", _case(system=SYS3, cost=COST3, W=orrc.Box(-1, 1, 3)), "n = 1 or 2", "n=3"),
    case("lemma6_case-nonlinear", _case(system=orrc.examples.inverted_pendulum().system), "LinearSystem"),
    case("lemma6_case-ball", _case(W=orrc.Ball(0.3, 1)), "W must be an orrc.Box", "Ball"),
    case("lemma6_case-box-dimension", _case(W=orrc.Box(-1, 1, 2)), "W", "dimension n=1"),
    case("lemma6_case-box-zero", _case(W=orrc.Box(0.0, 0.0)), "W", "max‖w‖² > 0"),
    case("lemma6_case-alpha-zero", _case(cost=COST_SINGULAR), "alpha_lo", "> 0"),
    case("lemma6_case-M-one", _case(M=1), "M", "1"),
    case("lemma6_case-M-too-long", _case(M=13), "M", "13"),
    case("lemma6_case-M-float", _case(M=2.5), "M", "2.5"),
    case("lemma6_case-n_x", _case(n_x=2), "n_x", "2"),
    case("lemma6_case-n_angles", _case(n_angles=0), "n_angles"),
    case("lemma6_case-n_pairs", _case(n_pairs=1), "n_pairs"),
    case("lemma6_case-x_span", _case(x_span=1.0), "x_span"),
    case("lemma6_case-x_span-nan", _case(x_span=float("nan")), "x_span"),
    case("lemma6_case-refine", _case(refine="yes"), "refine", "'yes'"),
    case("lemma6_case-too-large", _case(system=SYS2, cost=COST2, W=orrc.Box(-1, 1, 2), M=12, n_x=1000, n_angles=1000),
         "lemma6_case", "M=12", "too large"),
    case("lemma6_search-n-three", _search(n=3), "n", "3"),
    case("lemma6_search-problems-zero", _search(n_problems=0), "n_problems", "0"),
    case("lemma6_search-M-empty", _search(M=[]), "M", "[]"),
    case("lemma6_search-M-one", _search(M=[1, 3]), "M", "1"),
    case("lemma6_search-M-string", _search(M="6"), "M", "'6'"),
    case("lemma6_search-backend", _search(n_problems=1, n_x=3, M=2, backend="gpu"), "backend", "gpu"),
    case("lemma6_search-too-large", _search(n=2, n_problems=10_000, M=12, n_x=1000), "lemma6_search", "n_problems=10000",
         "too large"),
    case("lemma6_recheck-not-a-case", lambda: certify.lemma6_recheck({"x": 0}), "case", "Lemma6Case", "{'x': 0}"),
    case("lemma6_problem-n-zero", lambda: certify.lemma6_problem(0, 3, 0), "n", "0"),
    case("lemma6_problem-seed", lambda: certify.lemma6_problem(1, 3, "s"), "seed"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error(call, exc, words):
    assert_bad_input(call, exc, words)
