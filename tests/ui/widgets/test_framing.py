"""Camera framing (:mod:`tpm_viz.ui.widgets.framing`) checked through a pinhole camera written here, independently.

The reference camera follows viser's convention (OpenCV axes: x right, y down, z forward; the image's up is the
world ``up`` projected; a vertical field of view and the canvas aspect), and returns where a point lands on the
canvas in fractions of its width and height from the top-left corner.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tpm_viz.ui.widgets.framing import (
    FULL,
    LIVE_BAND,
    MARGIN,
    VIEW_FROM,
    Region,
    box_corners,
    frame_box,
    frame_points,
    free_region,
)

UP = np.array([0.0, 0.0, 1.0])


def canvas_position(points, position, look_at, fov, aspect, up=UP) -> np.ndarray:
    """(N, 2) canvas fractions (x from the left, y from the top) of world points [m] seen by a pinhole camera."""
    z = np.asarray(look_at, float) - np.asarray(position, float)
    z /= np.linalg.norm(z)
    x = np.cross(z, np.asarray(up, float))  # right = forward x up
    x /= np.linalg.norm(x)
    y = np.cross(z, x)  # down
    rel = np.atleast_2d(points) - position
    depth = rel @ z
    assert np.all(depth > 0), "a point is behind the camera"
    half_h = math.tan(fov / 2.0)
    half_w = aspect * half_h
    u = 0.5 + 0.5 * (rel @ x) / depth / half_w
    v = 0.5 + 0.5 * (rel @ y) / depth / half_h
    return np.stack([u, v], axis=-1)


def inner(region: Region, margin: float) -> tuple[float, float, float, float]:
    w, h = region.right - region.left, region.bottom - region.top
    return region.left + margin * w, region.top + margin * h, region.right - margin * w, region.bottom - margin * h


def test_box_corners_are_the_eight_corners():
    corners = box_corners((0.0, -1.0, 2.0), (1.0, 3.0, 5.0))
    assert corners.shape == (8, 3)
    assert {tuple(c) for c in corners} == {(x, y, z) for x in (0.0, 1.0) for y in (-1.0, 3.0) for z in (2.0, 5.0)}


def test_square_from_above_with_a_right_angle_view():
    """A square of side s seen from straight above with a 90 degree view on a square canvas: the camera sits s/2
    above its centre (tan 45 degrees = 1: half the side at a distance of half the side)."""
    s = 0.8
    square = box_corners((-s / 2, -s / 2, 0.0), (s / 2, s / 2, 0.0))
    framing = frame_points(square, (0.0, 0.0, 1.0), math.pi / 2, 1.0, margin=0.0, up=(0.0, 1.0, 0.0))
    np.testing.assert_allclose(framing.position, [0.0, 0.0, s / 2], atol=1e-12)
    np.testing.assert_allclose(framing.look_at, [0.0, 0.0, 0.0], atol=1e-12)
    assert framing.distance == pytest.approx(s / 2)


def test_square_in_the_left_half_of_a_wide_canvas():
    """Canvas twice as wide as high (90 degrees vertically, so tan of the half-width angle is 2), the square kept in
    its left half: both axes bind at a height of s/2, and the centre lands at a quarter of the width, so the camera
    is s/2 to the right of the square's centre."""
    s = 0.5
    square = box_corners((-s / 2, -s / 2, 0.0), (s / 2, s / 2, 0.0))
    framing = frame_points(
        square, (0.0, 0.0, 1.0), math.pi / 2, 2.0, free=Region(right=0.5), margin=0.0, up=(0.0, 1.0, 0.0)
    )
    np.testing.assert_allclose(framing.position, [s / 2, 0.0, s / 2], atol=1e-12)
    uv = canvas_position(square, framing.position, framing.look_at, math.pi / 2, 2.0, up=(0.0, 1.0, 0.0))
    np.testing.assert_allclose(uv[:, 0].min(), 0.0, atol=1e-12)
    np.testing.assert_allclose(uv[:, 0].max(), 0.5, atol=1e-12)
    np.testing.assert_allclose([uv[:, 1].min(), uv[:, 1].max()], [0.0, 1.0], atol=1e-12)


def _random_case(rng: np.random.Generator):
    centre = rng.uniform(-2.0, 2.0, 3)
    points = centre + rng.uniform(-1.0, 1.0, (int(rng.integers(2, 40)), 3)) * rng.uniform(0.05, 1.5, 3)
    elevation = rng.uniform(0.15, 1.45)  # rad above the horizon, short of straight down
    azimuth = rng.uniform(-math.pi, math.pi)
    view_from = (math.cos(elevation) * math.cos(azimuth), math.cos(elevation) * math.sin(azimuth), math.sin(elevation))
    fov = rng.uniform(0.3, 1.8)
    aspect = float(np.exp(rng.uniform(math.log(0.4), math.log(2.6))))
    left, top = rng.uniform(0.0, 0.4, 2)
    free = Region(left, top, rng.uniform(left + 0.3, 1.0), rng.uniform(top + 0.3, 1.0))
    margin = rng.uniform(0.0, 0.2)
    return points, view_from, fov, aspect, free, margin


def test_random_scenes_land_in_the_free_region_and_touch_it_on_one_axis():
    rng = np.random.default_rng(20260413)
    for _ in range(300):
        points, view_from, fov, aspect, free, margin = _random_case(rng)
        framing = frame_points(points, view_from, fov, aspect, free=free, margin=margin)
        assert framing.fov == fov and framing.aspect == aspect
        uv = canvas_position(points, framing.position, framing.look_at, fov, aspect)
        x0, y0, x1, y1 = inner(free, margin)
        tol = 1e-9
        assert uv[:, 0].min() >= x0 - tol and uv[:, 0].max() <= x1 + tol
        assert uv[:, 1].min() >= y0 - tol and uv[:, 1].max() <= y1 + tol
        touches_x = abs(uv[:, 0].min() - x0) < 1e-7 and abs(uv[:, 0].max() - x1) < 1e-7
        touches_y = abs(uv[:, 1].min() - y0) < 1e-7 and abs(uv[:, 1].max() - y1) < 1e-7
        direction = (framing.look_at - framing.position) / framing.distance
        nearest = float(np.min((points - framing.position) @ direction))
        assert nearest >= 0.01 - 1e-12
        at_near = nearest == pytest.approx(0.01, abs=1e-12)
        assert touches_x or touches_y or at_near, "a closer camera would still show every point: not the closest"
        # the look-at point is on the optical axis (the canvas centre), at the depth of the points' box centre
        np.testing.assert_allclose(direction, -np.asarray(view_from) / np.linalg.norm(view_from), atol=1e-12)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2
        assert framing.distance == pytest.approx(float(direction @ (centre - framing.position)), rel=1e-9)


def test_a_point_hiding_the_others_keeps_the_camera_at_the_near_distance():
    """A thin column seen from above: the top point hides the others; the camera stops ``near`` in front of it."""
    column = np.array([[0.0, 0.0, z] for z in np.linspace(0.0, 1.0, 11)])
    framing = frame_points(column, (0.0, 0.0, 1.0), 1.0, 1.0, up=(0.0, 1.0, 0.0), near=0.05)
    np.testing.assert_allclose(framing.position, [0.0, 0.0, 1.05], atol=1e-12)
    uv = canvas_position(column, framing.position, framing.look_at, 1.0, 1.0, up=(0.0, 1.0, 0.0))
    np.testing.assert_allclose(uv, 0.5, atol=1e-12)


@pytest.mark.slow
def test_a_camera_moved_closer_loses_a_point_whatever_its_sideways_shift():
    """The closest camera: 2 % closer along the view, no sideways shift (searched on a fine grid) keeps every
    point in the free region."""
    rng = np.random.default_rng(7)
    checked = 0
    while checked < 8:
        points, view_from, fov, aspect, free, margin = _random_case(rng)
        framing = frame_points(points, view_from, fov, aspect, free=free, margin=margin)
        forward = (framing.look_at - framing.position) / framing.distance
        if float(np.min((points - framing.position) @ forward)) < 0.011:
            continue  # held back by the near distance, not by the free region
        checked += 1
        right = np.cross(forward, UP)
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        closer = framing.position + 0.02 * framing.distance * forward
        x0, y0, x1, y1 = inner(free, margin)
        span = framing.distance
        for da in np.linspace(-0.3, 0.3, 41) * span:
            for db in np.linspace(-0.3, 0.3, 41) * span:
                pos = closer + da * right + db * up
                rel = (points - pos) @ forward
                if np.any(rel <= 0):
                    continue
                uv = canvas_position(points, pos, pos + forward, fov, aspect)
                inside = (uv[:, 0] >= x0) & (uv[:, 0] <= x1) & (uv[:, 1] >= y0) & (uv[:, 1] <= y1)
                assert not inside.all()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"points": np.full((3, 3), np.nan)},
        {"points": np.zeros((0, 3))},
        {"near": 0.0},
        {"fov": 0.0},
        {"fov": math.pi},
        {"fov": float("nan")},
        {"aspect": 0.0},
        {"aspect": float("inf")},
        {"margin": 0.5},
        {"margin": -0.1},
        {"view_from": (0.0, 0.0, 0.0)},
        {"view_from": (0.0, 0.0, 2.0)},  # along up: no right direction
    ],
)
def test_bad_input_is_refused(kwargs):
    args = {
        "points": box_corners((-1, -1, 0), (1, 1, 0.1)),
        "view_from": (0.0, -0.5, 1.0),
        "fov": 1.0,
        "aspect": 1.5,
        "margin": 0.05,
        **kwargs,
    }
    with pytest.raises(ValueError):
        frame_points(
            args["points"],
            args["view_from"],
            args["fov"],
            args["aspect"],
            margin=args["margin"],
            near=args.get("near", 0.01),
        )


@pytest.mark.parametrize("bounds", [(0.5, 0.0, 0.5, 1.0), (0.0, 0.0, 1.0, 1.2), (float("nan"), 0, 1, 1)])
def test_a_region_must_be_a_part_of_the_canvas(bounds):
    with pytest.raises(ValueError):
        Region(*bounds)


# -- the tab's canvas ------------------------------------------------------------------------------------------
CANVASES = {
    "projector, panel docked (1024 x 768, 384 px column)": (1024 - 384) / 768,
    "projector, presentation (1024 x 768, 430 px column)": (1024 - 430) / 768,
    "projector, panel collapsed to its rail": (1024 - 34) / 768,
    "laptop (1366 x 768)": (1366 - 384) / 768,
    "full HD (1920 x 1080)": (1920 - 384) / 1080,
    "phone (390 x 844, canvas above a 45 % sheet)": 390 / (0.55 * 844),
}


@pytest.mark.parametrize("aspect", list(CANVASES.values()), ids=list(CANVASES))
@pytest.mark.parametrize("presentation", [False, True])
def test_the_base_plate_fills_the_free_part_of_each_canvas(aspect, presentation):
    """The 8 corners of a plate 0.5 m wide and 0.1 m high, seen with viser's default 50 degree field of view, land
    inside the free part of the canvas less the margin, touching it on one axis; in presentation mode they stay out
    of the bottom band kept for the box of banner and forces."""
    lo, hi = (-0.2, -0.2, -0.012), (0.3, 0.3, 0.082)
    fov = math.radians(50.0)
    framing = frame_box(lo, hi, fov, aspect, presentation)
    uv = canvas_position(box_corners(lo, hi), framing.position, framing.look_at, fov, aspect)
    top_of_band = 1.0 - LIVE_BAND if presentation else 1.0
    x0, y0, x1, y1 = inner(Region(bottom=top_of_band), MARGIN)
    assert uv[:, 0].min() >= x0 - 1e-9 and uv[:, 0].max() <= x1 + 1e-9
    assert uv[:, 1].min() >= y0 - 1e-9 and uv[:, 1].max() <= y1 + 1e-9
    touches_x = math.isclose(uv[:, 0].min(), x0, abs_tol=1e-7) and math.isclose(uv[:, 0].max(), x1, abs_tol=1e-7)
    touches_y = math.isclose(uv[:, 1].min(), y0, abs_tol=1e-7) and math.isclose(uv[:, 1].max(), y1, abs_tol=1e-7)
    assert touches_x or touches_y
    # seen from the front and above, as the default camera: the view direction is -VIEW_FROM
    direction = (framing.look_at - framing.position) / framing.distance
    np.testing.assert_allclose(direction, -np.asarray(VIEW_FROM) / np.linalg.norm(VIEW_FROM), atol=1e-12)


def test_a_portrait_canvas_puts_the_camera_further_away_than_a_landscape_one():
    """The same plate on a canvas half as wide (same height, same vertical field of view) needs a camera further
    away: the width binds (a phone held upright)."""
    lo, hi = (-0.2, -0.2, 0.0), (0.3, 0.3, 0.08)
    wide = frame_box(lo, hi, 0.9, 1.6)
    narrow = frame_box(lo, hi, 0.9, 0.8)
    assert narrow.distance > 1.5 * wide.distance


def test_the_free_region():
    assert free_region() == FULL
    band = free_region(presentation=True)
    assert (band.left, band.top, band.right) == (0.0, 0.0, 1.0)
    assert band.bottom == pytest.approx(1.0 - LIVE_BAND)
    assert 0.15 <= LIVE_BAND <= 0.35
