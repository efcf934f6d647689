"""A phone (issue 25), in headless Chromium at 390×844 touch, in both orientations, with a phone's user agent.

Measured in the page and through the tab's camera as the server knows it (a pinhole written here): the whole
mechanism (the base plate's corners, which hold the rails, sliders and links) lands inside the 3D canvas for the
paper's parameters and for l_a = 240 mm (which cut rail 1 and A₁ at the left edge before); the drag handle is a
target a finger can hold: touch drags that start 20 px left, right, above and below its middle (a square at least
44 px across) all move the platform, and a 30 px finger move moves it by at most 30 mm (1 mm per CSS px); viser's
software-WebGL notice is a one-line strip clear of the whole mechanism and the handle; the first visit's guide and its
colour legend (in Korean, the longer words) fit the phone's width. The handle's middle is where viser's gizmo draws
its square (drei's ``PivotControls``: at 1.7/7 of its size from the platform diagonally, 0.225 of its size across); a
touch that missed it would orbit the camera and move nothing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import viser.transforms as tf

from tests.support.browser import launched_chromium
from tests.support.protocol import wait_for
from tpm_viz.app import transitions
from tpm_viz.drawing import meshes
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.phone import TOUCH_GIZMO_PX
from tpm_viz.ui.scene import GIZMO_Z

pytestmark = [pytest.mark.browser, pytest.mark.slow]

IPHONE = (
    "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) AppleWebKit/605.1.15 (KHTML, like Gecko) "
    "Version/17.0 Mobile/15E148 Safari/604.1"
)
CANVAS = """() => { const r = document.querySelector('canvas[data-engine]').getBoundingClientRect();
  return [r.left, r.top, r.right, r.bottom]; }"""
GUIDE_EDGES = """() => [...document.querySelectorAll('[data-guide] *')]
  .map(e => { const r = e.getBoundingClientRect(); return [r.left, r.right]; })"""
NOTICE = """() => { const e = document.getElementById('webgl-software-rendering'); if (!e) return null;
  const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; }"""


@pytest.fixture(scope="module")
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


@pytest.fixture(scope="module")
def chromium():
    with launched_chromium() as browser:
        yield browser


def _project(view, points, rect) -> np.ndarray:
    """Page coordinates [CSS px] of world points [m] through the tab's camera (OpenCV axes, vertical fov)."""
    cam = view.client.camera
    rot = tf.SO3(np.asarray(cam.wxyz)).as_matrix()
    xc = (np.asarray(points, dtype=float) - np.asarray(cam.position)) @ rot
    assert np.all(xc[:, 2] > 0), "a point is behind the camera"
    focal = 0.5 / math.tan(cam.fov / 2)
    aspect = cam.image_width / cam.image_height
    u, v = 0.5 + focal * xc[:, 0] / xc[:, 2] / aspect, 0.5 + focal * xc[:, 1] / xc[:, 2]
    return np.stack([rect[0] + u * (rect[2] - rect[0]), rect[1] + v * (rect[3] - rect[1])], axis=1)


def _settled(page, view) -> list[float]:
    """The canvas rectangle once the server's camera is framed for it (its aspect ratio is the page's)."""

    def ready():
        rect = page.evaluate(CANVAS)
        cam = view.client.camera
        page_aspect = (rect[2] - rect[0]) / (rect[3] - rect[1])
        return rect if abs(cam.image_width / cam.image_height / page_aspect - 1.0) < 0.02 else None

    return wait_for(ready, timeout=20.0, interval=0.2, what="the camera framed for the canvas")


def _framed(page, view) -> None:
    def fine():
        rect = _settled(page, view)
        lo, hi = meshes.base_extent(view.session.state.params)
        corners = [(x, y, z) for x in (lo, hi) for y in (lo, hi) for z in (-0.012, meshes.PIN_Z[1])]
        px = _project(view, corners, rect)
        return bool(np.all((px >= [rect[0], rect[1]]) & (px <= [rect[2], rect[3]])))

    wait_for(fine, timeout=20.0, interval=0.2, what="the whole mechanism in the canvas")


def _handle(view, rect) -> np.ndarray:
    """Page coordinates of the middle of the handle's square, for the platform where it is now."""
    with view.hub.lock:
        p = np.array(view.session.state.pose.p)
    origin = np.array([p[0], p[1], GIZMO_Z])
    cam = view.client.camera
    size = TOUCH_GIZMO_PX * 2 * np.linalg.norm(origin - np.asarray(cam.position)) * math.tan(cam.fov / 2)
    size /= rect[3] - rect[1]  # metres of TOUCH_GIZMO_PX CSS px at the platform's distance
    return _project(view, [origin + (1.7 / 7) * size * np.array([1.0, 1.0, 0.0])], rect)[0]


def _touch_drag(cdp, page, x: float, y: float, dx: float) -> None:
    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": [{"x": x, "y": y}]})
    for k in range(1, 11):
        page.wait_for_timeout(30)  # a finger's pace (the events' order, not a result, depends on it)
        cdp.send("Input.dispatchTouchEvent", {"type": "touchMove", "touchPoints": [{"x": x + dx * k / 10, "y": y}]})
    cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})


@pytest.mark.parametrize("size", [(390, 844), (844, 390)], ids=["portrait", "landscape"])
def test_a_phone_holds_the_handle_moves_finely_and_sees_the_whole_mechanism(served, chromium, size):
    portrait = size[0] < size[1]
    context = chromium.new_context(
        viewport={"width": size[0], "height": size[1]},
        has_touch=True,
        is_mobile=True,
        user_agent=IPHONE,
        locale="ko-KR" if portrait else "en-US",  # the longer words of the guide's legend
    )
    try:
        before = set(served.views)
        page = context.new_page()
        page.goto(f"http://127.0.0.1:{served.port}/")
        page.wait_for_selector("[data-q=p1]", timeout=30_000)
        view = served.views[next(iter(wait_for(lambda: set(served.views) - before, what="the tab's view")))]
        assert view.scene.touch and view.scene.gizmo.fixed
        with view.hub.lock:  # the paper's mechanism at home (the module's other test changed the shared one)
            view.hub.commit(view.session, transitions.home(transitions.paper_params(view.session.state)))
        _framed(page, view)
        rect = _settled(page, view)
        lo, hi = meshes.base_extent(view.session.state.params)
        corners = [(x, y, z) for x in (lo, hi) for y in (lo, hi) for z in (-0.012, meshes.PIN_Z[1])]
        px = _project(view, corners, rect)
        notice = page.evaluate(NOTICE)
        if notice is not None:  # a computer without a GPU: a one-line strip clear of the whole mechanism
            assert notice[3] - notice[1] <= 30, notice
            assert notice[3] <= px[:, 1].min() or notice[2] <= px[:, 0].min(), (notice, px.min(axis=0))
        if portrait:  # the first visit's guide and its colour legend fit the phone's width
            page.wait_for_selector("[data-guide]")
            edges = page.evaluate(GUIDE_EDGES)
            assert edges and all(0 <= left and right <= size[0] for left, right in edges), edges
        cdp = context.new_cdp_session(page)
        for dx, dy in ((0, 0), (-20, 0), (20, 0), (0, -20), (0, 20)):  # a target at least 40 px + 2 x 2 px
            rect = _settled(page, view)
            centre = _handle(view, rect)
            notice = page.evaluate(NOTICE)
            if notice is not None:
                assert not (notice[0] <= centre[0] <= notice[2] and notice[1] <= centre[1] <= notice[3])
            with view.hub.lock:
                start = np.array(view.session.state.pose.p)
            direction = -30.0 if centre[0] > (rect[0] + rect[2]) / 2 else 30.0  # towards the canvas's middle
            _touch_drag(cdp, page, centre[0] + dx, centre[1] + dy, direction)
            wait_for(lambda s=start: view.session.state.pose.p[0] != s[0], what=f"the platform moved ({dx}, {dy})")
            wait_for(
                lambda: np.allclose(view.scene.gizmo.position[:2], view.session.state.pose.p), what="the handle back"
            )
            with view.hub.lock:
                moved = np.linalg.norm(np.array(view.session.state.pose.p) - start)
            assert 0.0 < moved <= 30 * 1.0e-3 * 1.02, f"{moved * 1e3:.1f} mm for a 30 px drag"

        with view.hub.lock:  # l_a = 240 mm: the mechanism framed again, whole
            view.hub.commit(view.session, transitions.apply_params(view.session.state, {"l_a": "240"}))
        wait_for(lambda: view.session.state.params.l_a == pytest.approx(0.24), what="l_a = 240 mm")
        _framed(page, view)
    finally:
        context.close()
