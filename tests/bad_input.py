"""The shared format of the bad-input tests (``tests/test_bad_input*.py``).

A module of bad-input cases holds ONE table, a list of :func:`case` rows, and one test::

    from bad_input import assert_bad_input, case, params

    CASES = [
        case("lemma4-M-zero", lambda: orrc.theory.unknown.Gamma_V_theta(0, ...), "M"),
        case("sdp-too-large", lambda: ..., "n=", "limit"),
        case("odd-one", lambda: ..., "x", exc=TypeError),   # only with a reason
    ]

    @pytest.mark.parametrize("call, exc, words", params(CASES))
    def test_bad_input_gets_a_clear_error(call, exc, words):
        assert_bad_input(call, exc, words)

Each case: an id, a zero-argument callable, the words the message must contain (at least the
argument's name; matched case-sensitively, as written in the message), and the exception type
(``orrc.OrrcValueError`` unless there is a reason).
"""
from __future__ import annotations

import pytest

import orrc


def case(case_id: str, call, *words: str, exc=orrc.OrrcValueError):
    """One row of a bad-input table."""
    if not words:
        raise ValueError(f"case {case_id!r}: give at least the argument's name as a word of the message")
    return pytest.param(call, exc, words, id=case_id)


def params(cases) -> list:
    """The table, checked: unique ids (pytest would silently suffix duplicates)."""
    ids = [c.id for c in cases]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ValueError(f"duplicate case ids: {dup}")
    return list(cases)


def assert_bad_input(call, exc, words) -> str:
    """``call()`` raises exactly ``exc`` (or a subclass) and its message holds every word; returns it."""
    with pytest.raises(exc) as info:
        call()
    message = str(info.value)
    missing = [w for w in words if w not in message]
    assert not missing, f"the message lacks {missing}: {message!r}"
    return message
