"""Bad input to the NLP path's solver choice and options (SQP, IPOPT) and to the batch interface of V_M
(Controller.values_batch): a clear OrrcValueError naming the argument (one table, one case per row)."""
import functools
import re
import warnings

import numpy as np
import pytest

import orrc
from bad_input import assert_bad_input, case, params
from orrc.controllers import Decision
from orrc.solvers.nlp import ShootingNLP


@functools.cache
def pend():
    return orrc.examples.inverted_pendulum()


@functools.cache
def two_masses_rhc():
    ex = orrc.examples.two_mass_spring()
    return orrc.PreviewRHC(ex.system, ex.cost, 5)


def rhc(**kw):
    return orrc.PreviewRHC(pend().system, pend().cost, 5, input_bounds=pend().input_bounds, **kw)


class NoBatch(orrc.Controller):
    """Defers V_M but has no values_batch."""
    name = "no batch"
    cost = orrc.QuadraticCost([[1.0]], [[1.0]])

    def control(self, obs):
        return Decision(u=np.zeros(1), value_deferred=True)


class WrongBatch(NoBatch):
    name = "wrong batch"

    def values_batch(self, X, W_windows):
        return np.zeros(len(X) + 1)


def run(controller):
    return orrc.simulate(orrc.LinearSystem([[0.5]], [[1.0]]), controller, [1.0], np.zeros((4, 1)), 4)


CASES = [
    case("PreviewRHC-solver-capitals", lambda: rhc(solver="SQP"), "solver must be one of", "'sqp'", "'ipopt'", "'SQP'"),
    case("PreviewRHC-solver-type", lambda: rhc(solver=1), "solver must be one of", "got 1"),
    case("PreviewRHC-sqp-option-unknown", lambda: rhc(solver_options={"sqpmethod.no_such_option": 1}),
         "solver_options", "SQP (sqpmethod)", "no_such_option"),
    case("PreviewRHC-sqp-option-unprefixed", lambda: rhc(solver_options={"tol_du": 1e-9}),
         "solver_options", "IPOPT", "'sqpmethod.max_iter'"),
    case("PreviewRHC-sqp-qpsol-unknown", lambda: rhc(solver_options={"sqpmethod.qpsol": "no_such_qp"}),
         "solver_options", "sqpmethod.qpsol", "no_such_qp"),
    case("PreviewRHC-ipopt-option-unknown", lambda: rhc(solver="ipopt", solver_options={"ipopt.no_such_option": 1}),
         "solver_options", "IPOPT (ipopt)", "ipopt.no_such_option"),
    case("ShootingNLP-solver-unknown", lambda: ShootingNLP(pend().system, pend().cost, 3, solvers=("knitro",)),
         "solvers", "'knitro'"),
    case("ShootingNLP-solve-unbuilt", lambda: rhc(solver="sqp")._nlp.solve(np.zeros(2), np.zeros((5, 2)), np.zeros((5, 5)),
                                                                              solver="ipopt"), "solver", "'ipopt'", "('sqp',)"),
    case("values_batch-X-shape", lambda: two_masses_rhc().values_batch(np.zeros((3, 2)), np.zeros((3, 5, 4))),
         "X must have shape (any, 4)"),
    case("values_batch-windows-shape", lambda: two_masses_rhc().values_batch(np.zeros((3, 4)), np.zeros((3, 4, 4))),
         "W_windows must have shape (3, 5, 4)"),
    case("values_batch-nonfinite", lambda: two_masses_rhc().values_batch(np.full((2, 4), np.nan), np.zeros((2, 5, 4))),
         "X", "finite"),
    case("values_batch-nlp-path", lambda: rhc().values_batch(np.zeros((1, 2)), np.zeros((1, 5, 2))),
         "values_batch", "solver='nlp'"),
    case("simulate-deferred-without-values_batch", lambda: run(NoBatch()), "no batch", "value_deferred=True",
         "values_batch"),
    case("simulate-values_batch-wrong-shape", lambda: run(WrongBatch()), "wrong batch", "values_batch",
         "shape (4,)", "shape (5,)"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error_naming_the_argument(call, exc, words):
    assert_bad_input(call, exc, words)


@pytest.mark.parametrize("solver, options, unused", [
    ("ipopt", {"sqpmethod.max_iter": 3}, "['sqpmethod.max_iter']"),
    ("sqp", {"ipopt.max_iter": 3, "sqpmethod.max_iter": 30}, "['ipopt.max_iter']"),
])
def test_options_for_a_solver_that_is_not_used_are_ignored_with_a_warning(solver, options, unused):
    with pytest.warns(UserWarning, match=re.escape(f"solver_options {unused} are ignored") + f".*uses {solver.upper()}") as rec:
        r = rhc(solver=solver, solver_options=options)
    assert len([w for w in rec if issubclass(w.category, UserWarning)]) == 1
    assert r._nlp.solvers == (solver,)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rhc(solver_options=options)  # the default path uses both solvers: nothing to warn about
