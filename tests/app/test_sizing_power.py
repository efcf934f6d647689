"""The sizing table's peak power, split into driving and braking (issue 27): the largest ``|τ ḋ|`` is the braking
one when the motion brakes harder than it accelerates; hand formulas for a point mass."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz.app.sizing import format_sizing, size_motion


def test_a_hard_stop_makes_the_braking_power_the_peak():
    m, v, acc, brake = 2.0, 0.8, 4.0, 10.0  # kg, m/s, m/s² (accelerate), m/s² (brake)
    ta, tb = v / acc, v / brake
    t = np.concatenate([np.linspace(0, ta, 9), np.linspace(ta, ta + tb, 9)])
    vel = np.concatenate([acc * t[:9], v - brake * (t[9:] - ta)])
    force = np.concatenate([np.full(9, m * acc), np.full(9, -m * brake)])
    size = size_motion(t, np.stack([force, force], -1), np.stack([vel, vel], -1), dwell=0.0)
    assert size.peak_driving_power == pytest.approx([m * acc * v] * 2, rel=1e-12)  # 6.4 W at the end of the push
    assert size.peak_braking_power == pytest.approx([m * brake * v] * 2, rel=1e-12)  # 16 W at the start of the stop
    assert size.peak_power == pytest.approx(size.peak_braking_power, rel=1e-12)
    rows = {r[0]: r[2] for r in size.rows()}
    assert rows["peak driving power"] == pytest.approx(6.4) and rows["peak braking power"] == pytest.approx(16.0)
    text = format_sizing(size)
    assert "peak driving power" in text and "peak braking power" in text


def test_a_motion_that_never_brakes_has_no_braking_power():
    t = np.linspace(0, 1, 11)
    size = size_motion(t, np.full((11, 2), 3.0), np.stack([t, 2 * t], -1), dwell=0.5)
    assert np.array_equal(size.peak_braking_power, [0.0, 0.0])
    assert size.peak_driving_power == pytest.approx([3.0, 6.0])
