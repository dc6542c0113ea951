"""The named examples (``orrc.examples``): the scalar system x+ = A x + B u + w takes its
coefficients as ``A`` and ``B`` (one meaning per symbol: in the book ``a`` is the decay rate
and ``b`` Lemma 2's constant); the old keywords ``a`` and ``b`` still work, with a warning."""
import warnings

import numpy as np
import pytest

import orrc
from orrc import examples as exs


def test_the_scalar_system_has_coefficients_A_and_B():
    ex = exs.scalar_unstable(A=1.5, B=0.5)
    assert np.array_equal(ex.system.A, [[1.5]]) and np.array_equal(ex.system.B, [[0.5]]), \
        "A and B are the entries of the linear system x+ = A x + B u + w"
    default = exs.scalar_unstable()
    assert default.system.A[0, 0] == 2.0 and default.system.B[0, 0] == 1.0, \
        "the default system is x+ = 2 x + u + w"
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # the new keywords warn about nothing
        exs.scalar_unstable(A=1.2)


@pytest.mark.parametrize("old, new", [("a", "A"), ("b", "B")])
def test_the_old_keywords_still_work_with_a_deprecation_warning(old, new):
    with pytest.warns(DeprecationWarning, match=f"keyword {new}"):
        ex = exs.scalar_unstable(**{old: 3.0})
    assert ex.system.A[0, 0] == (3.0 if old == "a" else 2.0), "a= sets the coefficient A"
    assert ex.system.B[0, 0] == (3.0 if old == "b" else 1.0), "b= sets the coefficient B"


@pytest.mark.parametrize("old, new", [("a", "A"), ("b", "B")])
def test_an_old_and_a_new_keyword_together_are_refused(old, new):
    with pytest.raises(orrc.OrrcValueError, match=f"{new}=0.5.*{old}=3.0"):
        exs.scalar_unstable(**{new: 0.5, old: 3.0})


def test_the_old_keywords_are_checked_like_the_new_ones():
    with pytest.warns(DeprecationWarning), pytest.raises(orrc.OrrcValueError, match="B must be non-zero"):
        exs.scalar_unstable(b=0.0)
