"""Typed actuator positions d1, d2 (issue 13): what a text means in a mm field, the stroke as the accepted range,
and both actuators driven at once.

Expected values are the numbers the texts spell (``1.5e2`` mm is 150 mm, ``0.15 m`` is 150 mm) and the geometry of
the paper written here: slider ``i`` at ``A_i = (d_i - a) e_i`` (eq. 1), ``B_i = P - b e_i``, ``|B_i - A_i| = l_a``
(eq. 2), i.e. P on the circle of radius ``l_a`` about ``(d1 - a + b, 0)`` and on the one about ``(0, d2 - a + b)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.app import transitions
from tpm_viz.app.state import AppState
from tpm_viz.core.errors import InputError
from tpm_viz.ui.widgets.typed import Quantity, TypedField, TypedGroup

P = Params.paper()
D1 = Quantity("d1", "mm", 1.0, 0.0, 300.0)


@pytest.mark.parametrize(
    ("text", "mm"),
    [
        ("1.5e2", 150.0),
        ("150,5", 150.5),
        ("0.15 m", 150.0),
        ("0.15m", 150.0),
        ("15 cm", 150.0),
        ("1,5e1 cm", 150.0),
        ("150 mm", 150.0),
        ("150mm", 150.0),
        ("3e2", 300.0),
        ("0", 0.0),
        ("−0", 0.0),
    ],
)
def test_a_mm_field_reads_what_people_type(text, mm):
    assert D1.read(text) == pytest.approx(mm, rel=1e-15)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("350", "d1: 350 mm is out of range; type a value from 0 to 300 mm"),
        ("0.5 m", "d1: 500 mm is out of range; type a value from 0 to 300 mm"),
        ("-1", "d1: -1 mm is out of range; type a value from 0 to 300 mm"),
        ("1e308 m", "d1 [mm]: '1e308 m' is too large"),
        ("abc", "'abc' is not a number"),
        ("m", "'m' is not a number"),
        ("1.5e2 km", "d1: 1.5e+08 mm is out of range; type a value from 0 to 300 mm"),  # read, then out of range
        ("5 N", "d1 [mm]: 'N' is a force unit, but d1 is a length in m"),
        ("", "is empty"),
    ],
)
def test_a_mm_field_refuses_with_the_fix(text, words):
    with pytest.raises(InputError) as info:
        D1.read(text)
    assert words in str(info.value)
    assert "nan" not in str(info.value).lower() and "inf" not in str(info.value).lower()


def test_other_units_only_for_millimetres():
    with pytest.raises(InputError):
        Quantity("T", "s", 1.0, 0.0).read("0.5 m")  # a duration in metres is not a duration
    assert Quantity("m_a", "kg").read("0.95 kg") == 0.95


def test_the_stroke_is_the_range_and_follows_a_new_stroke():
    group = TypedGroup({k: TypedField(Quantity(k, "mm", 1.0, 0.0, 300.0), 130.0) for k in ("d1", "d2")}, quiet=1.5)
    group.typed("d1", "310", 0.0)
    with pytest.raises(InputError, match="from 0 to 300 mm"):
        group.read()
    group.limit(0.0, 320.0)  # a longer stroke applied
    group.typed("d1", "310", 1.0)
    assert group.read() == {"d1": 310.0, "d2": 130.0}  # d2 was not typed: its value in use


def _on_both_circles(params: Params, p, d) -> None:
    """P is at ``l_a`` from both slider joints A_i (eqs. 1-2), computed here."""
    a, b, la = params.a, params.b, params.l_a
    a1, a2 = np.array([d[0] - a, 0.0]), np.array([0.0, d[1] - a])
    b1, b2 = np.asarray(p) - [b, 0.0], np.asarray(p) - [0.0, b]
    assert math.dist(b1, a1) == pytest.approx(la, abs=1e-12)
    assert math.dist(b2, a2) == pytest.approx(la, abs=1e-12)


def test_both_actuators_typed_at_once():
    state = AppState.initial()
    new = transitions.drive_both(state, (150.0, 210.5))
    assert list(new.pose.d) == pytest.approx([0.15, 0.2105], abs=1e-15)
    assert str(new.note) == ""
    _on_both_circles(P, new.pose.p, (0.15, 0.2105))
    assert new.pose.mode(P) == state.pose.mode(P) == 1  # the assembly mode of the home pose kept


def test_a_stroke_end_read_back_from_mm_is_the_end_without_a_note():
    state = transitions.drive_both(AppState.initial(), (300.0, 130.0))
    assert state.pose.d[0] == P.stroke and str(state.note) == ""
    d_mm = state.pose.d * 1e3  # the value in use of a field nobody typed in, as the panel holds it
    again = transitions.drive_both(state, (float(np.nextafter(d_mm[0], 1e9)), 140.0))
    assert again.pose.d[0] == P.stroke and again.pose.d[1] == pytest.approx(0.14, abs=1e-15)
    assert str(again.note) == ""


def test_beyond_the_stroke_stops_at_the_end_stop_and_says_so():
    state = transitions.drive_both(AppState.initial(), (400.0, 130.0))  # the panel refuses first; the library clamps
    assert state.pose.d[0] == pytest.approx(P.stroke, abs=1e-9)
    assert "end-stop" in str(state.note)
