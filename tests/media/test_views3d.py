"""The software renderer of a tab's 3D view (tpm_viz.media.views3d): its pinhole projection against the textbook formula
written out here, where the mechanism lands in a rendered frame (the tool marker's pixels, found by their colour),
that a moved camera or a later time moves it by what the formula says, byte-identical frames, and one-line refusals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.core.errors import InputError
from tpm_viz.drawing.meshes import PLATFORM_Z
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.media.videos import encode_clip
from tpm_viz.media.views3d import Camera, View3dRenderer, focal_length, project
from tpm_viz.paper.kinematics import inverse_kinematics
from tpm_viz.paper.trajectories import paper_trajectory

MARKER_TOP = PLATFORM_Z[1] + 0.008  # m, the top of the tool marker (a disc 8 mm high on the platform)
MAGENTA = (255, 0, 255)  # the marker's colour in these tests: no other part is near it
COLOURS = {**PALETTE, "marker": MAGENTA, "path": (234, 179, 8), "trace": (15, 23, 42)}
FOV = math.radians(50.0)


@dataclass(frozen=True)
class _Run:
    params: Params
    t: np.ndarray
    p: np.ndarray
    d: np.ndarray
    tau: np.ndarray


@pytest.fixture(scope="module")
def run() -> _Run:
    """The paper's circle, 41 samples; made-up forces (the renderer only draws them)."""
    params, traj = Params.paper(), paper_trajectory("circle", samples=41)
    tau = np.column_stack([40.0 * np.sin(2 * np.pi * traj.t / 0.5), -25.0 * np.cos(2 * np.pi * traj.t / 0.5)])
    return _Run(params, traj.t, traj.p, inverse_kinematics(params, traj.p), tau)


def _top(x: float, y: float, height: float = 0.6, aspect: float = 16 / 9) -> Camera:
    """A camera ``height`` [m] over (x, y), looking straight down, +y up on the screen (a top view)."""
    return Camera.looking_at((x, y, height), (x, y, 0.0), (0.0, 1.0, 0.0), FOV, aspect)


def _pinhole(point, camera_xy, height, size) -> tuple[float, float]:
    """The top view's pixel of a world point by hand: image x = world x, image down = world -y, depth = height - z,
    focal length from the vertical field of view."""
    f = size[1] / 2 / math.tan(FOV / 2)
    depth = height - point[2]
    return size[0] / 2 + f * (point[0] - camera_xy[0]) / depth, size[1] / 2 - f * (point[1] - camera_xy[1]) / depth


def _marker(frame: np.ndarray) -> tuple[float, float]:
    """Centre ``(u, v)`` [px, pixel centres at i + 0.5] of the tool marker's top face: the brightest of the magenta
    pixels (its sides are shaded darker; a disc parallel to the image projects its centre to its centre)."""
    rgb = frame.astype(int)
    magenta = (rgb[..., 0] > 100) & (rgb[..., 1] < 40) & (np.abs(rgb[..., 0] - rgb[..., 2]) < 8)
    assert magenta.any(), "the marker is not in the frame"
    mask = magenta & (rgb[..., 0] >= rgb[..., 0][magenta].max() - 1)
    rows, cols = np.nonzero(mask)
    assert rows.size > 20, "the marker is not in the frame"
    return float(cols.mean() + 0.5), float(rows.mean() + 0.5)


def test_projection_is_the_pinhole_formula():
    size, camera = (800, 450), _top(0.05, -0.02, 0.7)
    rng = np.random.default_rng(7)
    points = rng.uniform((-0.3, -0.3, 0.0), (0.3, 0.3, 0.1), size=(50, 3))
    uv, depth = project(camera, size, points)
    expected = np.array([_pinhole(p, (0.05, -0.02), 0.7, size) for p in points])
    np.testing.assert_allclose(uv, expected, atol=1e-9)
    np.testing.assert_allclose(depth, 0.7 - points[:, 2], atol=1e-12)
    # looking straight down with +y up is a half turn about x: R = diag(1, -1, -1), w = 0
    assert np.allclose(np.abs(camera.wxyz), (0.0, 1.0, 0.0, 0.0))


def test_a_frame_narrower_than_the_tab_keeps_what_the_tab_shows():
    camera = _top(0.0, 0.0, 1.0, aspect=16 / 9)
    edge = (math.tan(FOV / 2) * 16 / 9, 0.0, 0.0)  # on the right edge of the tab's canvas, 1 m below the camera
    for size in ((1280, 720), (640, 480), (400, 360)):
        uv, _ = project(camera, size, [edge])
        assert uv[0, 0] == pytest.approx(size[0], abs=1e-9), size
        if size[0] / size[1] < 16 / 9:  # narrower: the focal length is set by the width
            assert focal_length(camera, size) < size[1] / 2 / math.tan(FOV / 2)


def test_top_view_puts_the_platform_where_the_formula_says(run):
    size, k = (640, 360), 10
    centre = (float(run.p[k, 0]) + 0.03, float(run.p[k, 1]) - 0.02)  # P is off the frame's centre
    frame = View3dRenderer(run, "top", size, _top(*centre), COLOURS).frame(k)
    expected = _pinhole((run.p[k, 0], run.p[k, 1], MARKER_TOP), centre, 0.6, size)
    assert _marker(frame) == pytest.approx(expected, abs=0.5)


def test_moving_the_camera_moves_the_mechanism(run):
    size, k = (800, 450), 0
    frames = {dx: View3dRenderer(run, "top", size, _top(0.02 + dx, 0.0), COLOURS).frame(k) for dx in (0.0, 0.06)}
    (u0, v0), (u1, v1) = _marker(frames[0.0]), _marker(frames[0.06])
    f = size[1] / 2 / math.tan(FOV / 2)
    assert u1 - u0 == pytest.approx(-f * 0.06 / (0.6 - MARKER_TOP), abs=0.5)  # the camera right: the scene left
    assert v1 == pytest.approx(v0, abs=0.5)
    assert np.abs(frames[0.0].astype(int) - frames[0.06]).sum() > 0


def test_a_later_time_moves_the_platform_and_the_frames_repeat_to_the_byte(run):
    size, camera = (640, 360), _top(0.0, 0.0, 0.7)
    first = View3dRenderer(run, "circle", size, camera, COLOURS)
    again = View3dRenderer(run, "circle", size, camera, COLOURS)
    k = len(run.t) // 4  # a quarter of the circle: P moved from (0.1, 0) to (0, 0.1)
    assert not np.array_equal(first.frame(0), first.frame(k))
    for j in (0, k):
        expected = _pinhole((run.p[j, 0], run.p[j, 1], MARKER_TOP), (0.0, 0.0), 0.7, size)
        assert _marker(first.frame(j)) == pytest.approx(expected, abs=0.5)
    for j in (0, 7, len(run.t) - 1):
        assert first.frame(j).tobytes() == again.frame(j).tobytes()
    gif = [encode_clip("gif", r.frame, 6, 10) for r in (first, again)]
    assert gif[0] == gif[1]


def test_a_slanted_camera_draws_the_forces_as_bars(run):
    size = (1920, 1080)
    camera = Camera.looking_at((0.1, -0.55, 0.6), (0.05, 0.05, 0.0), (0.0, 0.0, 1.0), math.radians(75), 1.6)
    renderer = View3dRenderer(run, "slanted", size, camera, COLOURS)
    geometry, k = renderer.geometry(), 5
    frame = renderer.frame(k)
    assert frame.shape == (1080, 1920, 3)
    lo, hi = round(geometry.zero_x - renderer.scale * geometry.px_per_newton), round(geometry.zero_x)
    for i, colour in enumerate(((31, 119, 180), (214, 39, 40))):
        row = frame[geometry.rows[i], lo : 2 * hi - lo].astype(int)
        cols = np.flatnonzero(np.abs(row - colour).sum(axis=1) < 30) + lo
        ends = (cols.min() - geometry.zero_x, cols.max() + 1 - geometry.zero_x)
        drawn = max(ends, key=abs) / geometry.px_per_newton
        assert drawn == pytest.approx(run.tau[k, i], abs=1.0 / geometry.px_per_newton), i
    _marker(frame)  # the platform is in view


@pytest.mark.parametrize(
    "bad",
    [
        dict(position=(0.0, 0.0, math.nan)),
        dict(fov=0.0),
        dict(aspect=math.nan),
        dict(wxyz=(0.0, 0.0, 0.0, 0.0)),
    ],
)
def test_an_unknown_camera_is_refused_in_one_line(bad):
    good = dict(position=(0.0, 0.0, 1.0), wxyz=(0.0, 1.0, 0.0, 0.0), fov=1.0, aspect=1.5)
    with pytest.raises(InputError) as caught:
        Camera(**{**good, **bad})
    assert "\n" not in str(caught.value) and "camera is not known yet" in str(caught.value)


def test_a_force_that_is_not_a_number_is_a_dash_and_draws_nothing(run):
    tau = run.tau.copy()
    tau[3] = (np.nan, np.inf)
    broken = _Run(run.params, run.t, run.p, run.d, tau)
    renderer = View3dRenderer(broken, "nan", (640, 360), _top(0.0, 0.0), COLOURS)
    _, one, two = renderer.texts(3)
    assert "nan" not in (one + two).lower() and "inf" not in (one + two).lower()
    assert one.startswith("τ1 = ") and not any(c.isdigit() for c in one[5:])
    assert renderer.texts(4)[1] == f"τ1 = {tau[4, 0]:+.2f} N"
    assert (
        renderer.frame(3).shape == (360, 640, 3)
        and renderer.scale == View3dRenderer(run, "finite", (640, 360), _top(0.0, 0.0), COLOURS).scale
    )
