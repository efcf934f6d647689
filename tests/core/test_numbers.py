"""tpm_viz.core.numbers.parse_number: numbers as people type them, exact round trips, one-line bounded errors."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import MAX_TEXT, parse_number, plausibility_note

finite = st.floats(allow_nan=False, allow_infinity=False)
BOUNDED = settings(max_examples=examples(300), deadline=None)


def same(a: float, b: float) -> bool:
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


@BOUNDED
@given(finite)
def test_repr_round_trips_exactly(x):
    assert same(parse_number(repr(x), "x"), x)


@BOUNDED
@given(finite)
def test_decimal_comma_round_trips_exactly(x):
    assert same(parse_number(repr(x).replace(".", ","), "x"), x)


@BOUNDED
@given(finite, st.sampled_from([".17e", ".17E", ".16e"]))
def test_scientific_notation_round_trips_exactly(x, spec):
    text = format(x, spec)
    assert same(parse_number(text, "x"), x)
    assert same(parse_number(text.replace(".", ","), "x"), x)


@BOUNDED
@given(finite.filter(lambda x: x < 0))
def test_unicode_minus_and_spaces(x):
    assert same(parse_number("  \u2212" + repr(x)[1:] + "\t", "x"), x)


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1e9", 1e9),
        ("5e-1", 0.5),
        ("0,25", 0.25),
        (" +2,5E-3 ", 2.5e-3),
        ("1 000", 1000.0),
        ("12\u00a0345,5", 12345.5),
        ("1\u202f000\u202f000", 1e6),
        ("1,000", 1.0),  # a comma is always a decimal comma (documented)
        (".5", 0.5),
        ("\u22120,5", -0.5),
        (3, 3.0),
    ],
)
def test_what_people_type(text, value):
    assert parse_number(text, "x") == value


def test_own_unit_after_the_number():
    assert parse_number("5 mm", "stroke", "mm") == 5.0
    with pytest.raises(InputError, match=r"stroke \[m\]"):
        parse_number("5 mm", "stroke", "m")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "is empty"),
        ("   ", "is empty"),
        ("abc", "is not a number"),
        ("1,234.5", "mixes separators"),
        ("1.234,5", "mixes separators"),
        ("1,000,000", "mixes separators"),
        ("1 00", "is not a number"),
        ("nan", "not finite"),
        ("-inf", "not finite"),
        ("1e999", "too large"),
        ("9" * 400, "too large"),
        (True, "must be a number"),
        (float("nan"), "finite"),
        (None, "must be a number"),
    ],
)
def test_refusals_are_one_line(text, message):
    with pytest.raises(InputError, match=message) as exc:
        parse_number(text, "duration", "s")
    assert "\n" not in str(exc.value) and "duration" in str(exc.value)


def test_huge_inputs_give_short_messages():
    for text in ("1" * 100_000, "x" * 100_000, "1" * (MAX_TEXT + 1)):
        with pytest.raises(InputError) as exc:
            parse_number(text, "n" * 1000)
        assert len(str(exc.value)) < 250


def test_plausibility_note():
    assert plausibility_note(50.0, "tau1", "N", typical=100.0) is None
    note = plausibility_note(3e6, "tau1", "N", typical=100.0)
    assert note and "tau1" in note and "units" in note and "\n" not in note
    assert plausibility_note(float("inf"), "tau1", "N", typical=100.0) is None
