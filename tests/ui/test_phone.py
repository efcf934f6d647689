"""The touch handle's drag gain and detection (ui/phone.py, ui/tabscene.py) and Enter in the presenter-token box
(ui/login.py), without a browser (issue 25).

The gain is checked against a pinhole camera written here: a floor step of ``gain`` times the finger's way, seen
through the camera, must not move more than 1 mm per pixel in any direction (finite differences of the projection).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.support.fixtures import open_tab
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.phone import MM_PER_PX, drag_gain, is_touch

IPHONE = "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) AppleWebKit/605.1.15 Mobile/15E148 Safari/604.1"
DESKTOP = "Mozilla/5.0 (X11; Linux x86_64) AppleWebKit/537.36 (KHTML, like Gecko) Chrome/126.0 Safari/537.36"
TOKEN = "correct-horse-battery"


@pytest.mark.parametrize(
    ("headers", "touch"),
    [
        ({"User-Agent": IPHONE}, True),
        ({"User-Agent": "Mozilla/5.0 (Linux; Android 14; Pixel 8) Mobile Safari/537.36"}, True),
        ({"User-Agent": DESKTOP, "Sec-CH-UA-Mobile": "?1"}, True),
        ({"User-Agent": DESKTOP, "Sec-CH-UA-Mobile": "?0"}, False),
        ({}, False),
    ],
)
def test_a_phone_or_tablet_is_told_by_its_handshake(headers, touch):
    assert is_touch((("10.0.0.7", 50000), headers)) is touch
    assert is_touch(None) is False


def _pixels_per_metre_floor(camera, target, fov, height) -> float:
    """Least pixels a 1 m floor step at ``target`` moves in the picture (over floor directions), by projecting."""
    forward = np.asarray(target, float) - np.asarray(camera, float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    focal = height / 2 / math.tan(fov / 2)

    def pixel(point):
        rel = np.asarray(point, float) - np.asarray(camera, float)
        return focal * np.array([rel @ right, rel @ up]) / (rel @ forward)

    step = 1e-5
    least = math.inf
    for angle in np.linspace(0.0, math.pi, 37):
        d = step * np.array([math.cos(angle), math.sin(angle), 0.0])
        least = min(least, float(np.linalg.norm(pixel(np.asarray(target) + d) - pixel(target))) / step)
    return least


@pytest.mark.parametrize(
    ("camera", "fov", "height"),
    [((0.0, -0.5, 1.0), 1.309, 464.0), ((0.1, -0.9, 0.6), 1.309, 390.0), ((0.0, 0.0, 2.0), 0.8, 928.0)],
)
def test_the_gain_moves_the_platform_at_most_one_millimetre_per_pixel(camera, fov, height):
    target = (0.02, 0.01, 0.04)
    gain = drag_gain(camera, target, fov, height)
    assert 0.0 < gain <= 1.0
    metres_per_px = 1.0 / _pixels_per_metre_floor(camera, target, fov, height)  # the finger's way per pixel
    assert gain * metres_per_px <= MM_PER_PX * 1e-3 * 1.001  # a step this small: the formula is exact to 1e-5
    assert gain * metres_per_px >= 0.4 * MM_PER_PX * 1e-3  # not needlessly slow: within the slant's bound


def test_a_touch_tabs_drag_is_geared_and_ends_back_under_the_platform(connect):
    client, view = connect()
    owner = str(view.client.client_id)
    wait_for(lambda: view.panel.class_info.content, what="the tab's connection done (it tells touch from mouse)")
    with view.hub.lock:
        view.scene.set_touch(True)
        view.scene._gain = lambda at: 0.25  # the camera's gain, fixed here: the gearing itself is under test
    assert view.scene.gizmo.fixed
    client.drag(view.scene.gizmo, owner, [(0.0, 0.0, 0.09), (0.04, 0.02, 0.09)])
    wait_for(lambda: np.allclose(view.session.state.pose.p, (0.01, 0.005), atol=1e-12), what="a quarter of the way")
    wait_for(lambda: np.allclose(view.scene.gizmo.position[:2], (0.01, 0.005)), what="the handle back")


@pytest.fixture
def presenter_app():
    application = TpmApp(build_server("127.0.0.1", 0), presenter_token=TOKEN)
    yield application
    application.stop()


def test_enter_in_the_token_box_logs_in_with_the_whole_token(presenter_app):
    opened: list[ProtocolClient] = []
    try:
        client, view = open_tab(presenter_app, opened)
        client.set_value(view.login.token, "not the token\n")  # Enter: a line break, sent with the whole text
        wait_for(lambda: "wrong presenter token" in view.panel.message.content, what="a wrong token refused")
        assert view.login.token.value == ""
        client.set_value(view.login.token, TOKEN + "\n")  # typed with Enter in one burst
        wait_for(lambda: "You are the presenter" in view.login.status.content, what="the login by Enter")
        assert view.login.token.value == ""
    finally:
        for c in opened:
            c.close()
