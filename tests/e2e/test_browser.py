"""End to end in headless Chromium (Debian's /usr/bin/chromium via Playwright).

One page session, in order: the page loads with no page errors and no request leaving 127.0.0.1; the 3D canvas
is not blank; a gizmo drag with the real mouse, a typed platform position and an actuator slider click move the
platform and change the displayed numbers; a parameter change updates them; a bad value is refused with a
message and the app keeps working. All GUI inputs share a 50 ms throttle in viser's client: we pause between
inputs.
"""

from __future__ import annotations

import io
import time

import numpy as np
import pytest

from tests.support.browser import WORKER_LOG_JS, text_input
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

PAUSE = 0.08  # s, longer than the client's 50 ms input throttle


def _project(view, point) -> tuple[float, float]:
    """Pixel position of a world point [m] in this tab's camera (OpenCV convention, vertical fov)."""
    import viser.transforms as tf

    cam = view.client.camera
    rot = tf.SO3(np.asarray(cam.wxyz)).as_matrix()
    xc = rot.T @ (np.asarray(point, dtype=float) - np.asarray(cam.position))
    focal = (cam.image_height / 2) / np.tan(cam.fov / 2)
    return cam.image_width / 2 + focal * xc[0] / xc[2], cam.image_height / 2 + focal * xc[1] / xc[2]


def _text(page, name: str) -> str:
    return page.locator(f"[data-q={name}]").first.inner_text()


def _wait_text(page, name: str, expected: str, timeout: float = 10.0) -> None:
    wait_for(lambda: _text(page, name) == expected, timeout=timeout, what=f"{name} = {expected!r}")


def _fill(page, handle, value: str, enter: bool = True) -> None:
    """Type into a typed number field (a text input) and press Enter (or leave it with Tab)."""
    field = text_input(page, handle)
    field.fill(value)
    field.press("Enter" if enter else "Tab")
    time.sleep(PAUSE)


def _canvas_is_not_blank(page) -> bool:
    from PIL import Image

    png = page.locator("canvas").first.screenshot()
    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    colours = len(np.unique(pixels.reshape(-1, 3).astype(np.uint8), axis=0))
    return pixels.std() > 10.0 and colours > 200


def test_app_end_to_end(app, browser):
    pytest.importorskip("PIL")
    page = browser.new_page()
    errors: list[str] = []
    requests: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.on("request", lambda req: requests.append(req.url))
    page.on("websocket", lambda ws: requests.append(ws.url))
    page.add_init_script(WORKER_LOG_JS)

    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_function("() => (window.__viserLog || []).some(m => m.type === 'ReplayDoneMessage')", timeout=20_000)
    page.wait_for_selector("[data-q=p1]", timeout=20_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    assert _text(page, "p1") == "0.0" and _text(page, "d1") == "130.0"

    # The 3D view renders the mechanism.
    wait_for(lambda: _canvas_is_not_blank(page), timeout=20.0, what="a non-blank canvas")

    # Drag the gizmo along +x with the real mouse (grab the x arrow half-way along it).
    wait_for(lambda: view.client.camera.image_width > 0, what="the camera size")
    gizmo = np.asarray(view.scene.gizmo.position)
    x0, y0 = _project(view, gizmo + np.array([0.5 * 0.16, 0.0, 0.0]))
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 9):
        page.mouse.move(x0 + 6 * k, y0, steps=2)
        time.sleep(0.06)
    page.mouse.up()
    wait_for(lambda: float(_text(page, "p1")) > 5.0, what="p1 to grow after the drag")
    assert _text(page, "p2") == "0.0"
    assert float(_text(page, "d1")) > 130.0

    # Type a platform position (Move tab, first tab).
    _fill(page, view.panel.p.inputs["p1"], "40", enter=False)  # the next field, then Enter: both at once
    _fill(page, view.panel.p.inputs["p2"], "-3e1")
    _wait_text(page, "p1", "40.0")
    _wait_text(page, "p2", "-30.0")
    tau_before = _text(page, "theta1")

    # Click the d1 slider track near its right end: forward kinematics moves the platform.
    track = page.locator(f'[id="{widget_uuid(view.panel.d[0])}"]')
    box = track.bounding_box()
    track.click(position={"x": 0.9 * box["width"], "y": box["height"] / 2})
    wait_for(lambda: float(_text(page, "d1")) > 250.0, what="d1 near 270 mm")
    assert _text(page, "theta1") != tau_before

    # A parameter change (Parameters tab): l_a = 280 mm, then Apply. Numbers change everywhere.
    open_tab(page, "Parameters")
    _fill(page, view.panel.params.inputs["l_a"], "280", enter=False)
    page.get_by_role("button", name="Apply parameters").click()
    wait_for(lambda: view.session.state.params.l_a == pytest.approx(0.28), what="l_a applied")
    d1_expected = f"{view.session.state.pose.d[0] * 1e3:.1f}"
    _wait_text(page, "d1", d1_expected)

    # A bad value is refused with a message under the Apply button; the last good mechanism stays (and is shown
    # under the field, which keeps the text); the app keeps working.
    time.sleep(PAUSE)
    _fill(page, view.panel.params.inputs["b"], "-5", enter=False)
    page.get_by_role("button", name="Apply parameters").click()
    page.get_by_text("Refused: parameter b must be positive").first.wait_for(timeout=10_000)
    page.get_by_text("b: in use 92 mm").first.wait_for(timeout=10_000)
    assert view.session.state.params.b == pytest.approx(0.092)
    assert text_input(page, view.panel.params.inputs["b"]).input_value() == "-5"
    open_tab(page, "Move")
    time.sleep(PAUSE)
    page.get_by_role("button", name="Home (p = 0)").click()
    _wait_text(page, "p1", "0.0")
    _wait_text(page, "d1", "110.0")  # a - b - l_a with l_a = 280 mm (eq. 4 at p = 0)

    body = page.locator("body").inner_text().lower()
    assert "nan" not in body.split() and "inf" not in body.split()
    assert errors == []
    outside = [u for u in requests if not u.startswith(("http://127.0.0.1:", "ws://127.0.0.1:", "blob:", "data:"))]
    assert outside == []
    page.close()
