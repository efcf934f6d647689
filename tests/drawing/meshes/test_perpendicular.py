"""Parts of the paper's perpendicular mechanism (tpm_viz.drawing.meshes.perpendicular): rails along e_i over the
stroke, end-stops where the slider touches them, pivots carried by the slider and covered by the platform."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.drawing import meshes as m
from tpm_viz.drawing.meshes import perpendicular as mp

P = Params.paper()


@pytest.mark.parametrize("i", [0, 1])
def test_rail_spans_the_stroke_and_stops_touch_the_slider_at_its_ends(i):
    rail = mp.rail(P, i).bounds
    stops = mp.end_stops(P, i).bounds
    assert rail[0, i] < -P.a - m.SLIDER_LENGTH / 2 and rail[1, i] > -P.a + P.stroke + m.SLIDER_LENGTH / 2
    assert stops[0, i] == pytest.approx(-P.a - m.SLIDER_LENGTH / 2 - 0.012)
    assert stops[1, i] == pytest.approx(-P.a + P.stroke + m.SLIDER_LENGTH / 2 + 0.012)


def test_slider_carries_both_pivots_and_the_platform_covers_its_pins():
    for i in range(2):
        lo, hi = mp.slider(P, i).bounds
        for pin in mp.slider_pin_offsets(P, i):
            assert np.all(lo[:2] < pin[:2]) and np.all(pin[:2] < hi[:2])
    lo, hi = mp.platform(P).bounds
    for pin in mp.platform_pin_offsets(P):
        assert np.all(lo[:2] < pin[:2]) and np.all(pin[:2] < hi[:2])


def test_the_package_names_are_the_perpendicular_parts():
    """``meshes.rail`` and the rest are the live (perpendicular) mechanism's, as every drawing of it expects."""
    for name in ("base_extent", "base_plate", "rail", "end_stops", "slider", "platform", "platform_pin_offsets"):
        assert getattr(m, name) is getattr(mp, name)
