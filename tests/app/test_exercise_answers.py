"""Answers as students type them: ``numbers.parse_quantity`` and the exercise's reader of a text (format errors).

Expected values are the numbers the texts spell (``0.15 m`` is 150 mm, ``0,2 kN`` is 200 N, ``62.83 rad/s`` is 10
Hz: ω = 2π f); a format error is one line that names what to change, and never a score.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tpm_viz.app.exercises.answers import FormatError, read_answer, split_values
from tpm_viz.app.exercises.catalogue import by_id
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import parse_quantity
from tpm_viz.core.words import Lang


@pytest.mark.parametrize(
    ("text", "unit", "expected"),
    [
        ("150", "mm", 150.0),
        ("150 mm", "mm", 150.0),
        ("150mm", "mm", 150.0),
        ("15 cm", "mm", 150.0),
        ("0.15 m", "mm", 150.0),
        ("0,15 m", "mm", 150.0),
        ("\u22120.15 m", "mm", -150.0),
        ("1.5e2", "mm", 150.0),
        ("1e3mm", "mm", 1000.0),
        ("1 000 mm", "mm", 1000.0),
        ("0,2 kN", "N", 200.0),
        ("12 N", "N", 12.0),
        ("0.012 kN", "N", 12.0),
        ("30°", "rad", math.pi / 6),
        ("30 deg", "rad", math.pi / 6),
        ("0.5 rad", "deg", 0.5 * 180 / math.pi),
        ("10 Hz", "Hz", 10.0),
        ("62.83185307179586 rad/s", "Hz", 10.0),
        ("2.5 m/s^2", "mm/s^2", 2500.0),
        ("2.5 m/s²", "m/s^2", 2.5),
        ("0.7", "", 0.7),
    ],
)
def test_a_unit_of_the_same_quantity_is_converted(text, unit, expected):
    assert parse_quantity(text, "x", unit) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("text", "unit", "says"),
    [
        ("5 N", "mm", "'N' is a force unit, but x is a length"),
        ("5 xyz", "mm", "unknown unit 'xyz' (use m or mm)"),
        ("5 mm", "", "'mm' does not fit: type the number alone"),
        ("abc", "mm", "'abc' is not a number"),
        ("", "N", "is empty"),
        ("1,000.5 N", "N", "mixes separators"),
        ("1e308 m", "mm", "too large"),
        ("5 kg", "N", "'kg' is a mass unit, but"),
    ],
)
def test_what_does_not_fit_is_one_line(text, unit, says):
    with pytest.raises(InputError) as caught:
        parse_quantity(text, "x", unit)
    message = str(caught.value)
    assert says in message and "\n" not in message


@pytest.mark.parametrize(
    ("text", "parts"),
    [
        ("-35, 20", ["-35", "20"]),
        ("(-35; 20)", ["-35", "20"]),
        ("[-35 20]", ["-35", "20"]),
        ("-35,5; 20,25", ["-35,5", "20,25"]),
        ("-35,5, 20,25", ["-35,5", "20,25"]),
        ("-0.035 m, 0.02 m", ["-0.035 m", "0.02 m"]),
        ("-35 mm 20 mm", ["-35 mm", "20 mm"]),
        ("\u221235\u00a0; 20", ["\u221235", "20"]),
    ],
)
def test_two_values_split_as_written(text, parts):
    assert split_values(text, 2) == parts


@pytest.mark.parametrize("text", ["1", "1; 2; 3", "1,5", "a b c", ";", "1;"])
def test_the_wrong_count_is_a_format_error(text):
    if text == "1,5":  # a pair: 1 and 5 (a comma between two numbers of a pair separates them)
        assert split_values(text, 2) == ["1", "5"]
        return
    with pytest.raises(FormatError, match="type 2 numbers separated by ';'"):
        split_values(text, 2)


def _read(ident: str, text: object, seed: int = 0):
    exercise = by_id(ident).exercise
    return read_answer(exercise, variant_of(exercise, seed), text)


def test_a_pose_outside_the_stroke_or_in_the_other_mode_is_a_format_error():
    with pytest.raises(FormatError, match="other assembly mode"):
        _read("zero-force-pose", "-240; -240")  # lesson 5's P′: det J_x = -0.70
    with pytest.raises(FormatError, match=r"outside the stroke 0 to 300\.0 mm"):
        _read("zero-force-pose", "200; 0")  # d1 = 200 + 390 - 260 = 330 mm
    with pytest.raises(FormatError, match="out of reach"):
        _read("zero-force-pose", "0.3 m; 0")
    assert _read("zero-force-pose", "0,05 m; −20").values == pytest.approx((50.0, -20.0))


def test_gains_and_choices_read_as_typed():
    assert _read("tune-ctc", "62.83185307179586 rad/s; 0,7").values == pytest.approx((10.0, 0.7))
    assert _read("tune-ctc", "(40, 1)").values == (40.0, 1.0)
    for text in ("0; 1", "20001; 1", "20; -1", "20; 101", "20 N; 1", "20; 1 Hz"):
        with pytest.raises(FormatError):
            _read("tune-ctc", text)
    for text, key in (("leg 1", "leg1"), ("  LEG 2 ", "leg2"), ("2", "leg2"), ("leg1", "leg1"), ("다리 1", "leg1")):
        assert _read("nearer-inverse-leg", text).choice == key
    with pytest.raises(FormatError) as caught:
        _read("nearer-inverse-leg", "3")
    assert caught.value.args[0].render(Lang.KO) == "보기의 번호를 입력하세요: 1 (다리 1), 2 (다리 2)"


@given(st.text(max_size=300))
def test_any_text_is_read_or_refused_in_one_line(text):
    for ident in ("force-at-pose", "zero-force-pose", "tune-ctc", "nearer-inverse-leg"):
        try:
            answer = _read(ident, text)
        except FormatError as exc:
            assert "\n" not in str(exc) and str(exc)
        else:
            assert all(math.isfinite(v) for v in answer.values)


def test_a_long_or_non_text_answer_is_a_format_error():
    with pytest.raises(FormatError, match="too long"):
        _read("force-at-pose", "1" * 201)
    with pytest.raises(FormatError, match="must be text"):
        _read("force-at-pose", 12.0)
    with pytest.raises(FormatError, match="empty"):
        _read("force-at-pose", "   ")
