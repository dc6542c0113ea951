"""Bad input to orrc.progress (and the status line of a long call, orrc._progress.working): a clear
orrc.OrrcValueError naming the argument."""
import pytest

import orrc
from orrc._progress import working

from bad_input import assert_bad_input, case, params

CASES = [
    case("progress-not-iterable", lambda: orrc.progress(5), "iterable", "int"),
    case("progress-desc", lambda: orrc.progress(range(3), desc=3), "desc", "string", "int"),
    case("progress-total-negative", lambda: orrc.progress(range(3), total=-1), "total", "-1"),
    case("progress-total-type", lambda: orrc.progress(range(3), total="3"), "total", "integer"),
    case("progress-delay-negative", lambda: orrc.progress(range(3), delay=-1.0), "delay", "-1"),
    case("progress-delay-nan", lambda: orrc.progress(range(3), delay=float("nan")), "delay", "nan"),
    case("working-message", lambda: working("").__enter__(), "message", "non-empty string"),
    case("working-delay", lambda: working("solving", delay=-1).__enter__(), "delay", "-1"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_is_refused_with_a_clear_message(call, exc, words):
    assert_bad_input(call, exc, words)
