"""``tpm_viz.core.numbers.fixed``: the one formatter of a shown number. Never ``-0.0``; a dash for what is no number."""

from __future__ import annotations

import decimal
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.core.numbers import DASH, fixed

FIXED_POINT = [".0f", ".1f", ".2f", ".3f", ".4f", "+.1f", "+.2f", "+.3f", ",.1f", "+,.2f", ">9.2f", "<7.1f", ".1%"]
ANY_FORMAT = [*FIXED_POINT, ".3e", "+.2e", ".3g", "g", ".4G", ".2E"]


def value_shown(text: str) -> float:
    """The number a formatted text shows (padding, commas, percent)."""
    text = text.strip().replace(",", "")
    return float(text[:-1]) / 100 if text.endswith("%") else float(text)


@pytest.mark.parametrize("fmt", FIXED_POINT)
@pytest.mark.parametrize("x", [-1e-12, -0.0, -1e-300, -5e-324, -4e-5])
def test_tiny_negatives_show_as_zero_without_a_sign(x, fmt):
    text = fixed(x, fmt)
    assert "-" not in text and "\u2212" not in text, text
    assert value_shown(text) == 0.0
    assert text == format(0.0, fmt)  # what zero looks like in that format (a + sign where the format asks one)


@settings(max_examples=examples(500), deadline=None, derandomize=True)
@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e15, max_value=1e15), st.sampled_from(ANY_FORMAT))
def test_never_a_negative_zero_and_otherwise_the_plain_format(x, fmt):
    text = fixed(x, fmt)
    mantissa = re.split("[eE]", text.strip().rstrip("%"))[0]
    if value_shown(text) == 0.0:
        assert not mantissa.lstrip().startswith("-"), text
    else:
        assert text == format(x, fmt)  # nothing else changes


def test_scale_is_applied_first():
    assert fixed(0.1234, ".1f", scale=1e3) == "123.4"
    assert fixed(-1e-15, ".1f", scale=1e3) == "0.0"  # -1e-12 mm
    assert fixed(-0.2, "+.1f", scale=180 / math.pi) == "-11.5"


@pytest.mark.parametrize(
    "x",
    [None, math.nan, math.inf, -math.inf, np.nan, np.float64("inf"), "abc", "", 1 + 2j, object(), True, False, [1.0]],
)
def test_a_dash_for_what_is_no_finite_number(x):
    assert fixed(x) == DASH


def test_a_dash_when_scaling_overflows():
    assert fixed(1e308, ".1f", scale=10.0) == DASH
    assert fixed(1.0, ".1f", scale=math.nan) == DASH


def test_number_types():
    assert fixed(np.float32(-1e-9), ".2f") == "0.00"
    assert fixed(np.int64(-3), ".1f") == "-3.0"
    assert fixed(decimal.Decimal("-0.00001"), ".3f") == "0.000"
    assert fixed(2, "+.1f") == "+2.0"
