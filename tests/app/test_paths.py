"""Geometric paths for the planner: the paper's line and circle, pick-and-place, waypoints, and the region check."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tpm_viz as tv
from tests.support.hypo import examples
from tpm_viz.app import paths
from tpm_viz.core.errors import InputError
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus
from tpm_viz.paper.trajectories import circle_state, line_state

P = tv.Params.paper()


def assert_arc_length_and_derivatives(path: paths.GeometricPath, n: int = 2001) -> None:
    """``|p'| = 1``; ``p'`` and ``p''`` match central differences away from the junctions; ``p`` is continuous."""
    s = np.linspace(0.0, path.length, n)
    assert np.allclose(np.hypot(*path.evaluate(s, 1).T), 1.0, atol=1e-12)
    h = 1e-6
    inner = s[(s > h) & (s < path.length - h)]
    inner = inner[np.min(np.abs(inner[:, None] - np.append(path.junctions, [0.0])[None, :]), axis=1) > 2 * h]
    fd1 = (path.evaluate(inner + h) - path.evaluate(inner - h)) / (2 * h)
    fd2 = (path.evaluate(inner + h, 1) - path.evaluate(inner - h, 1)) / (2 * h)
    assert np.allclose(fd1, path.evaluate(inner, 1), atol=1e-7)
    assert np.allclose(fd2, path.evaluate(inner, 2), atol=1e-3 * (1 + np.abs(path.evaluate(inner, 2)).max()))
    for j in path.junctions:  # position and tangent continuous (G1) where segments meet
        for order in (0, 1):
            assert np.allclose(path.evaluate(j, order, "left"), path.evaluate(j, order, "right"), atol=1e-12)
    assert np.all(np.hypot(*np.diff(path.evaluate(s), axis=0).T) <= (s[1] - s[0]) * (1 + 1e-9))


def test_the_line_is_the_papers_fig4_line():
    path = paths.line_path()
    assert path.length == pytest.approx(math.hypot(0.2, 0.1), abs=1e-15)
    cubic, _, _ = line_state(np.linspace(0.0, 0.2, 11))  # the paper's points, by the cubic law
    s = np.hypot(*(cubic - cubic[0]).T)
    assert np.allclose(path.evaluate(s), cubic, atol=1e-15)
    assert np.allclose(path.evaluate(s, 2), 0.0)
    assert_arc_length_and_derivatives(path)


def test_the_circle_is_the_papers_fig5_circle():
    path = paths.circle_path()
    assert path.length == pytest.approx(2 * math.pi * 0.1, abs=1e-15)
    t = np.linspace(0.0, 0.5, 21)
    cubic, _, _ = circle_state(t)
    phi = np.unwrap(np.arctan2(cubic[:, 1], cubic[:, 0]))
    assert np.allclose(path.evaluate(0.1 * phi), cubic, atol=1e-14)
    assert np.allclose(np.hypot(*path.evaluate(np.linspace(0, path.length, 50), 2).T), 1 / 0.1)  # curvature 1/r
    assert_arc_length_and_derivatives(path)


def test_pick_and_place_dimensions_by_hand():
    h, w, r = 0.025, 0.150, 0.010
    path = paths.pick_and_place((0.01, -0.02), paths.PickSize(h, w, r))
    # two quarter circles replace 2 r of straight each: 2h + w - 2 (2r - πr/2)
    assert path.length == pytest.approx(2 * h + w - (4 - math.pi) * r, abs=1e-15)
    pts = path.evaluate(np.linspace(0.0, path.length, 4001))
    assert pts[:, 0].min() == pytest.approx(0.01, abs=1e-15)
    assert pts[:, 0].max() == pytest.approx(0.16, abs=1e-15)
    assert pts[:, 1].max() == pytest.approx(-0.02 + h, abs=1e-15)
    assert np.allclose(path.evaluate(path.length), (0.16, -0.02), atol=1e-15)
    assert sorted(np.round(path.radius, 12)) == [0, 0, 0, r, r]
    assert_arc_length_and_derivatives(path)


def test_the_default_pick_fits_the_papers_workspace_at_full_size():
    path = paths.path_for(P, "pick")
    pts = path.evaluate(np.linspace(0.0, path.length, 2001))
    assert np.ptp(pts[:, 0]) == pytest.approx(0.150, abs=1e-12)
    assert np.ptp(pts[:, 1]) == pytest.approx(0.025, abs=1e-12)
    assert np.all(tv.classify(P, pts, MOVE_LIMITS) == PoseStatus.REGULAR)


def test_the_default_pick_shrinks_to_fit_a_short_stroke():
    small = P.replace(stroke=0.12)
    path = paths.path_for(small, "pick")
    pts = path.evaluate(np.linspace(0.0, path.length, 2001))
    assert np.ptp(pts[:, 0]) < 0.150
    assert np.ptp(pts[:, 0]) / np.ptp(pts[:, 1]) == pytest.approx(6.0, rel=1e-9)  # same proportions
    assert np.all(tv.classify(small, pts, MOVE_LIMITS) == PoseStatus.REGULAR)


def test_reversed_runs_the_same_curve_backwards():
    path = paths.path_for(P, "pick")
    back = path.reversed()
    s = np.linspace(0.0, path.length, 997)
    assert np.allclose(back.evaluate(s), path.evaluate(path.length - s), atol=1e-15)
    assert np.allclose(back.evaluate(s, 1), -path.evaluate(path.length - s, 1), atol=1e-12)
    inner = s[np.min(np.abs(s[:, None] - back.junctions[None, :]), axis=1) > 1e-9]
    assert np.allclose(back.evaluate(inner, 2), path.evaluate(path.length - inner, 2), atol=1e-9)


def _first_bad_mm(message: str) -> np.ndarray:
    x, y = re.search(r"at \((-?[\d.]+), (-?[\d.]+)\) mm", message).groups()
    return np.array([float(x), float(y)]) / 1e3


def test_a_path_leaving_the_stroke_is_refused_at_its_first_offending_point():
    path = paths.waypoint_path([(0.0, 0.0), (0.25, 0.0)])  # the stroke ends near p1 = +170 mm on this line
    with pytest.raises(InputError, match="out of stroke") as err:
        paths.check_path(P, path)
    msg = str(err.value)
    assert "\n" not in msg
    bad = _first_bad_mm(msg)
    d_end = tv.inverse_kinematics(P, [bad[0], 0.0])[0]
    assert d_end == pytest.approx(P.stroke, abs=0.6e-3)  # where d_1 reaches Δd, to the check step and rounding
    s = np.linspace(0.0, bad[0] - 1e-3, 200)
    assert np.all(tv.classify(P, path.evaluate(s), MOVE_LIMITS) == PoseStatus.REGULAR)  # nothing bad before it


def test_an_unreachable_waypoint_is_refused():
    with pytest.raises(InputError, match=r"unreachable|out of stroke"):
        paths.path_for(P, "waypoints", [(0.0, 0.0), (0.0, 0.3)])


@pytest.mark.parametrize(
    "points, match",
    [
        ([(0.0, 0.0)], "at least two points"),
        ([(0.0, 0.0), (0.0, 0.0)], "coincide"),
        ([(0.0, 0.0), (0.05, 0.0), (0.0, 0.0)], "reverses direction"),
        ([(0.0, 0.0), (float("nan"), 0.0)], "not finite"),
    ],
)
def test_bad_waypoints_are_refused_with_one_line(points, match):
    with pytest.raises(InputError, match=match) as err:
        paths.waypoint_path(points)
    assert "\n" not in str(err.value)


def test_bad_kinds_and_sizes_are_refused():
    with pytest.raises(InputError, match="path kind"):
        paths.path_for(P, "spiral")
    with pytest.raises(InputError, match="corner radius"):
        paths.pick_and_place((0, 0), paths.PickSize(0.02, 0.15, 0.03))
    with pytest.raises(InputError, match="waypoint path needs"):
        paths.path_for(P, "waypoints")


@settings(max_examples=examples(40), deadline=None)
@given(
    pts=st.lists(st.tuples(st.floats(-0.1, 0.1), st.floats(-0.1, 0.1)), min_size=2, max_size=7),
    radius=st.floats(0.001, 0.05),
)
def test_waypoint_polylines_are_arc_length_paths_near_their_points(pts, radius):
    pts = np.array(pts)
    seg = np.hypot(*np.diff(pts, axis=0).T)
    try:
        path = paths.waypoint_path(pts, radius)
    except InputError as exc:  # only coincident points or a full reversal may be refused
        assert seg.min() < 1e-9 or "reverses" in str(exc)
        return
    assert np.allclose(path.evaluate(0.0), pts[0], atol=1e-12)
    assert np.allclose(path.evaluate(path.length), pts[-1], atol=1e-12)
    assert path.length <= seg.sum() * (1 + 1e-12)  # rounding corners only shortens the polyline
    dense = path.evaluate(np.linspace(0.0, path.length, 4001))
    for k in range(1, len(pts) - 1):
        u, v = (pts[k] - pts[k - 1]) / seg[k - 1], (pts[k + 1] - pts[k]) / seg[k]
        turn = math.acos(max(-1.0, min(1.0, float(u @ v))))
        if turn > math.pi - 1e-3:
            continue
        bound = radius * (1 / math.cos(turn / 2) - 1)  # the arc's distance from the corner it cuts
        gap = np.min(np.hypot(*(dense - pts[k]).T))
        assert gap <= bound + 1e-9 + path.length / 4000
    s = np.linspace(0.0, path.length, 301)
    assert np.allclose(np.hypot(*path.evaluate(s, 1).T), 1.0, atol=1e-9)
