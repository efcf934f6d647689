"""The axes of the player's charts (:mod:`tpm_viz.ui.widgets.chart_axes`): ticks for every run length and value range.

Each property is checked from the outside: the labels are read back by a parser written here (true minus, thousands
commas, ``×10ⁿ``), the spacing and the 1-2-5 steps are recomputed from the tick values, and the claims of the
docstrings (smallest step, fewest ticks, room between labels) are checked against the neighbouring steps.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.ui.widgets.chart_axes import Ticks, text_width, tick_labels, time_ticks, value_ticks

SETTINGS = settings(max_examples=examples(300), deadline=None, derandomize=True)
_SUP = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-")
GAP = 12.0  # px, time_ticks' default room between two labels


def read(label: str) -> tuple[float, float]:
    """The number a label shows and half a unit of its last digit (how far the tick may be from it)."""
    assert "-" not in label, f"{label!r}: a hyphen where a minus sign (U+2212) belongs"
    text = label.replace("\u2212", "-").replace(",", "")
    mantissa, _, power = text.partition("×10")
    exponent = int(power.translate(_SUP)) if power else 0
    decimals = len(mantissa.partition(".")[2])
    return float(mantissa) * 10.0**exponent, 0.5 * 10.0 ** (exponent - decimals)


def steps_125(lo: float, hi: float):
    """Every step 1, 2, 5 × 10^k in ``[lo, hi]``, ascending."""
    k = math.floor(math.log10(lo)) - 1
    while True:
        for m in (1, 2, 5):
            step = m * 10.0**k
            if step > hi * (1 + 1e-9):
                return
            if step >= lo * (1 - 1e-9):
                yield step
        k += 1


def count_inside(step: float, t0: float, t1: float) -> int:
    return math.floor(t1 / step + 1e-9) - math.ceil(t0 / step - 1e-9) + 1


def check_axis(ticks: Ticks) -> float:
    """The properties every axis has; returns its step."""
    values = np.array(ticks.values)
    assert len(values) >= 2 and len(ticks.labels) == len(values)
    assert np.all(np.isfinite(values)) and math.isfinite(ticks.lo) and math.isfinite(ticks.hi)
    assert ticks.lo <= values[0] and values[-1] <= ticks.hi and np.all(np.diff(values) > 0)
    steps = np.diff(values)
    step = float(np.median(steps))
    np.testing.assert_allclose(steps, step, rtol=1e-6)  # evenly spaced
    mantissa = step / 10.0 ** math.floor(math.log10(step) + 1e-9)
    assert min(abs(mantissa - m) for m in (1, 2, 5)) < 1e-6, f"step {step} is not 1, 2 or 5 × 10^k"
    assert len(set(ticks.labels)) == len(ticks.labels), ticks.labels
    for value, label in zip(values, ticks.labels, strict=True):
        shown, half = read(label)
        assert abs(shown - value) <= half + 1e-9 * abs(value), (label, value)
        if shown == 0.0:
            assert "\u2212" not in label, f"negative zero label {label!r}"
        assert not any(c in label for c in "en"), label  # no 'nan', 'inf' or 1e-05 notation
    return step


# -- time axes ----------------------------------------------------------------------------------------------------
DURATION = st.floats(1e-3, 100.0) | st.sampled_from([1e-3, 0.0137, 0.2, 0.5, 1.0, 1.1, 7.0, 99.99, 100.0])


@SETTINGS
@given(DURATION, st.sampled_from([6, 8, 3]))
def test_time_axis_of_a_run_from_zero(duration, most):
    ticks = time_ticks(0.0, duration, most=most)
    step = check_axis(ticks)
    most = max(most, 6)
    assert (ticks.lo, ticks.hi) == (0.0, duration)  # the axis spans exactly the run
    assert ticks.values[0] == 0.0 and ticks.labels[0].strip("0.") == ""
    assert 3 <= len(ticks.values) <= most
    # The smallest 1-2-5 step with at most `most` ticks: the step below it gives more.
    smaller = [s for s in steps_125(step / 3, step) if s < step * (1 - 1e-9)][-1]
    assert count_inside(smaller, 0.0, duration) > most


@SETTINGS
@given(st.floats(-100.0, 100.0), st.floats(1e-3, 100.0))
def test_time_axis_with_any_start(t0, span):
    t1 = t0 + span
    ticks = time_ticks(t0, t1)
    check_axis(ticks)
    assert (ticks.lo, ticks.hi) == (t0, t1) and 2 <= len(ticks.values) <= 6


@SETTINGS
@given(DURATION, st.floats(80.0, 400.0))
def test_time_labels_keep_apart_on_a_narrow_chart(duration, room):
    ticks = time_ticks(0.0, duration, room=room)
    step = check_axis(ticks)
    widest = max(text_width(label) for label in ticks.labels)
    apart = room * step / duration  # px between two ticks on a plot `room` px wide
    if apart < widest + GAP:  # only when no larger step leaves 3 ticks
        larger = next(s for s in steps_125(step * 1.5, step * 3) if s > step * (1 + 1e-9))
        assert count_inside(larger, 0.0, duration) < 3
    assert len(ticks.values) >= 3
    wide = time_ticks(0.0, duration)
    assert len(ticks.values) <= len(wide.values)  # room only ever removes ticks


def test_time_axis_examples():
    """The durations of the paper (0.2 s, 0.5 s) and the issue's extremes, on a phone-wide plot (116 px)."""
    assert time_ticks(0.0, 0.5).labels == ("0.0", "0.1", "0.2", "0.3", "0.4", "0.5")
    assert time_ticks(0.0, 0.5, room=116).labels == ("0.0", "0.2", "0.4")
    assert time_ticks(0.0, 0.2, room=116).labels == ("0.0", "0.1", "0.2")
    assert time_ticks(0.0, 1e-3, room=116).labels == ("0.0000", "0.0005", "0.0010")
    assert time_ticks(0.0, 100.0, room=116).labels == ("0", "50", "100")


@pytest.mark.parametrize(
    "t0, t1", [(0.0, 0.0), (0.5, 0.5), (1.0, 0.0), (math.nan, 1.0), (0.0, math.inf), (-1e308, 1e308)]
)
def test_degenerate_time_ranges_still_make_an_axis(t0, t1):
    ticks = time_ticks(t0, t1)
    check_axis(ticks)
    assert ticks.lo < ticks.hi


# -- value axes ---------------------------------------------------------------------------------------------------
LEVEL = st.sampled_from([1e-12, 1e-6, 1e-3, 1.0, 130.0, 5e4, 1e8, 1e12])
SERIES = st.one_of(
    st.lists(st.floats(-1e9, 1e9), min_size=1, max_size=20),  # anything
    st.tuples(st.floats(-1e6, 1e6), st.integers(1, 10)).map(lambda c: [c[0]] * c[1]),  # constant
    st.tuples(LEVEL, st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=10)).map(
        lambda s: [s[0] * v for v in s[1]]  # small, large, negative, around zero
    ),
    st.tuples(LEVEL, st.floats(-1e3, 1e3), st.lists(st.floats(0.0, 1.0), min_size=2, max_size=10)).map(
        lambda s: [s[1] + s[0] * v for v in s[2]]  # a small change on a level
    ),
    st.sampled_from([[-1e-12], [-1e-12, 0.0], [0.0], [-0.0, -1e-15], [-1e-300], [1e-9, -1e-9], [-3.0, -2.0]]),
)


@SETTINGS
@given(SERIES)
def test_value_axis_holds_the_data(data):
    ticks = value_ticks(data)
    step = check_axis(ticks)
    assert 3 <= len(ticks.values) <= 5
    assert ticks.lo <= min(data) and max(data) <= ticks.hi  # the range covers the data
    # ... from tick to tick: the end ticks are the range's ends, or a rounding error (1e-9 step) inside them
    assert 0.0 <= ticks.values[0] - ticks.lo <= 1e-8 * step and 0.0 <= ticks.hi - ticks.values[-1] <= 1e-8 * step


@pytest.mark.parametrize("data", [[-1e-12], [-1e-12, 3e-13], [0.0, -0.0], [], [math.nan, math.inf]])
def test_a_negligible_or_empty_series_is_shown_around_zero(data):
    ticks = value_ticks(data)
    assert (ticks.lo, ticks.hi) == (-1.0, 1.0)
    assert ticks.labels == ("\u22121.0", "\u22120.5", "0.0", "0.5", "1.0")


def test_a_flat_series_is_shown_within_ten_percent_of_its_level():
    ticks = value_ticks([130.0] * 5 + [130.0 + 1e-12])
    assert ticks.lo <= 130.0 * 0.9 and ticks.hi >= 130.0 * 1.1 and ticks.hi - ticks.lo <= 0.5 * 130.0
    assert "130" in ticks.labels


def test_value_labels_examples():
    """Thousands commas, one exponent per axis from 10⁶ up, ×10ⁿ for tiny steps below 1, a true minus."""
    assert value_ticks([-4100.0, 2000.0]).labels == ("\u22126,000", "\u22124,000", "\u22122,000", "0", "2,000")
    assert value_ticks([-5e7, 1e8]).labels == ("\u22120.5×10⁸", "0", "0.5×10⁸", "1.0×10⁸")
    assert value_ticks([1e-6, 5e-6]).labels == ("1×10⁻⁶", "2×10⁻⁶", "3×10⁻⁶", "4×10⁻⁶", "5×10⁻⁶")
    assert value_ticks([1.0, 1.000002]).labels == ("1.000000", "1.000001", "1.000002")


def test_tick_labels_never_read_minus_zero():
    assert tick_labels([-1e-17, 0.0, -0.0], -2) == ("0.00", "0.00", "0.00")
    assert tick_labels([-1e-20, 2e-6], -6)[0] == "0"


# -- text widths ----------------------------------------------------------------------------------------------------
TEXT = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=30)


@SETTINGS
@given(TEXT, st.characters(codec="utf-8", exclude_categories=["Cs"]), st.floats(6.0, 40.0))
def test_text_width_grows_with_every_character(text, extra, px):
    assert text_width(text + extra, px) > text_width(text, px) >= 0.0
    assert text_width(text, px, bold=True) >= text_width(text, px)
    assert text_width(text, 2 * px) == pytest.approx(2 * text_width(text, px))


@pytest.mark.parametrize(
    "text, bold, measured",
    [  # canvas measureText in headless Chromium (Debian, DejaVu Sans), 12 px, uPlot's axis fonts
        ("0.0", False, 19.08),
        ("\u221250,000", False, 52.04),
        ("force (N)", True, 59.82),
        ("d\u0308 (mm/s²)", True, 65.53),
        ("time t (s)", True, 62.70),
    ],
)
def test_text_width_is_no_less_than_chromium_measures(text, bold, measured):
    assert measured <= text_width(text, 12.0, bold=bold) <= 1.5 * measured
