"""One home for accepted ranges (yadebreak.model.intervals): the scripts' options and attach()'s
options check with the same Interval."""
import math

import pytest

from yadebreak.model.intervals import Interval


@pytest.mark.parametrize("interval, inside, outside, text", [
    (Interval(0, 1, lo_open=True), [1e-12, 0.5, 1.0], [0.0, 1.0 + 1e-12, math.nan], "in (0, 1]"),
    (Interval(0, 0.5, hi_open=True), [0.0, 0.25], [0.5, -1e-12], "in [0, 0.5)"),
    (Interval(0, lo_open=True), [1e-300, 1e300], [0.0, math.inf, -1.0], "> 0"),
    (Interval(hi=2), [-1e9, 2.0], [2.5, -math.inf], "<= 2"),
    (Interval(), [-1.0, 0.0, 3.0], [math.inf, math.nan], "any number"),
])
def test_interval_contains_finite_numbers_within_its_ends_and_says_so(interval, inside,
                                                                       outside, text):
    assert all(v in interval for v in inside)
    assert not any(v in interval for v in outside)
    assert str(interval) == text


def test_script_options_and_attach_options_check_alike():
    from yadebreak.options.table import _number
    from yadebreak.options.flags import number
    param = number("x", 0.5, "-", "a share", lo=0, hi=1, lo_open=True)
    check = _number(0, 1, lo_open=True)
    for v in (0.0, 1e-9, 0.5, 1.0, 1.5, math.nan, math.inf):
        assert (v in param.interval) == check(v)
    assert not check(True) and check(None) is False and _number(none=True)(None)
