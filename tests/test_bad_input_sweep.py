"""Bad input to orrc.sweep and its Table: a clear orrc.OrrcValueError naming the argument.

One table in the shared format of tests/bad_input.py: each case an id, a zero-argument callable
and the words its message must contain (at least the argument's name).
"""
import numpy as np
import pytest

import orrc
from bad_input import assert_bad_input, case, params

EX = orrc.examples.van_der_pol()


def f(M, seed=0):
    return {"cost": float(M)}


def captures_casadi():
    """A function (sent by value, like one defined in a notebook) that captured a nonlinear PreviewRHC, whose
    CasADi symbols do not pickle."""
    rhc = orrc.PreviewRHC(EX.system, EX.cost, 3)
    return lambda M: rhc.M + M

def _with_env(name, value, call):
    import os

    old = os.environ.get(name)
    os.environ[name] = value
    try:
        return call()
    finally:
        os.environ.pop(name) if old is None else os.environ.__setitem__(name, old)


TABLE = orrc.sweep(f, {"M": [1, 2]}, seeds=[0], backend="serial")

CASES = [
    case("sweep-fn-not-callable", lambda: orrc.sweep("f", {"M": [1]}), "fn must be callable", "'f'"),
    case("sweep-fn-wrong-keywords", lambda: orrc.sweep(f, {"N": [1]}, backend="serial"), "fn", "N", "cannot be called"),
    case("sweep-fn-takes-no-seed", lambda: orrc.sweep(lambda M: M, {"M": [1]}, seeds=2), "fn", "seed"),
    case("sweep-fn-does-not-pickle", lambda: orrc.sweep(captures_casadi(), {"M": [1, 2]}, backend="processes"), "fn cannot be sent",
         "inside fn", "backend='serial'"),
    case("sweep-fn-result-clashes", lambda: orrc.sweep(lambda M: {"M": 2 * M}, {"M": [1]}, backend="serial"),
         "fn returned the keys ['M']"),
    case("sweep-grid-type", lambda: orrc.sweep(f, 3), "grid must be a dict of lists", "3"),
    case("sweep-grid-scalar-values", lambda: orrc.sweep(f, {"M": 3}), "grid['M'] must be a list", "3"),
    case("sweep-grid-string-values", lambda: orrc.sweep(f, {"M": "123"}), "grid['M'] must be a list", "'123'"),
    case("sweep-grid-2d-array", lambda: orrc.sweep(f, {"M": np.ones((2, 2))}), "grid['M']", "1-D"),
    case("sweep-grid-empty-values", lambda: orrc.sweep(f, {"M": []}), "grid['M'] must hold at least one value"),
    case("sweep-grid-empty-list", lambda: orrc.sweep(f, []), "grid must hold at least one point"),
    case("sweep-grid-point-type", lambda: orrc.sweep(f, [{"M": 1}, 2]), "grid[1] must be a dict", "2"),
    case("sweep-grid-points-differ", lambda: orrc.sweep(f, [{"M": 1}, {"N": 2}]), "grid[1]", "['N']", "['M']"),
    case("sweep-grid-key-not-identifier", lambda: orrc.sweep(f, {"a b": [1]}), "grid", "identifiers", "'a b'"),
    case("sweep-grid-key-not-string", lambda: orrc.sweep(f, {3: [1]}), "grid", "identifiers", "3"),
    case("sweep-grid-seed-parameter", lambda: orrc.sweep(f, {"seed": [1]}, seeds=2), "grid", "'seed'"),
    case("sweep-grid-too-large", lambda: orrc.sweep(f, {"M": range(10 ** 4), "N": range(10 ** 4)}),
         "grid of 100000000 points", "10000 M × 10000 N", "too large", "limit"),
    case("sweep-seeds-too-many-runs", lambda: orrc.sweep(f, {"M": [1, 2]}, seeds=10 ** 6), "1000000 seeds",
         "2000000 runs", "too large", "limit"),
    case("sweep-ops_per_call-too-large", lambda: orrc.sweep(f, {"M": [1]}, ops_per_call=1e15), "ops_per_call=1e+15",
         "too large"),
    case("sweep-ops_per_call-nan", lambda: orrc.sweep(f, {"M": [1]}, ops_per_call=float("nan")), "ops_per_call",
         "finite"),
    case("sweep-seeds-zero", lambda: orrc.sweep(f, {"M": [1]}, seeds=0), "seeds must be an integer >= 1", "0"),
    case("sweep-seeds-float", lambda: orrc.sweep(f, {"M": [1]}, seeds=2.5), "seeds must be None", "2.5"),
    case("sweep-seeds-negative-entry", lambda: orrc.sweep(f, {"M": [1]}, seeds=[1, -2]), "seeds[1]", ">= 0", "-2"),
    case("sweep-seeds-empty-list", lambda: orrc.sweep(f, {"M": [1]}, seeds=[]), "seeds must be None", "[]"),
    case("sweep-seed-negative", lambda: orrc.sweep(f, {"M": [1]}, seeds=2, seed=-1), "seed must be an integer >= 0"),
    case("sweep-common_seeds-type", lambda: orrc.sweep(f, {"M": [1]}, seeds=2, common_seeds="yes"), "common_seeds",
         "'yes'"),
    case("sweep-backend-unknown", lambda: orrc.sweep(f, {"M": [1]}, backend="threads"), "backend must be one of",
         "'threads'"),
    case("sweep-backend-environment", lambda: _with_env("ORRC_SWEEP_BACKEND", "threads",
                                                       lambda: orrc.sweep(f, {"M": [1]})), "ORRC_SWEEP_BACKEND", "'threads'"),
    case("sweep-backend-dask-without-client", lambda: orrc.sweep(f, {"M": [1]}, backend="dask"), "backend='dask'",
         "client="),
    case("sweep-client-type", lambda: orrc.sweep(f, {"M": [1]}, client="tcp://127.0.0.1:8786"), "client must be",
         "Client", "tcp://"),
    case("sweep-workers-zero", lambda: orrc.sweep(f, {"M": [1]}, workers=0), "workers must be an integer >= 1", "0"),
    case("sweep-chunksize-float", lambda: orrc.sweep(f, {"M": [1]}, chunksize=1.5), "chunksize must be an integer"),
    case("sweep-progress-type", lambda: orrc.sweep(f, {"M": [1]}, progress="on"), "progress must be", "'on'"),
    case("sweep-on_error-unknown", lambda: orrc.sweep(f, {"M": [1]}, on_error="ignore"), "on_error must be one of",
         "'ignore'"),
    case("Table-column-unknown", lambda: TABLE.column("gamma"), "name must be a column", "'gamma'", "cost"),
    case("Table-where-unknown", lambda: TABLE.where(gamma=1), "where: unknown columns ['gamma']"),
    case("Table-to_records-no-scalar", lambda: orrc.Table([{"x": np.zeros(2)}]).to_records(), "to_records",
         "no column"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error_naming_the_argument(call, exc, words):
    assert_bad_input(call, exc, words)
