"""The touch handle and *Frame the mechanism* (issue 40, item 3), in headless Chromium.

A phone is known by its page, not its user agent: Chromium's touch emulation at 390×844 keeps a desktop user agent
(``HeadlessChrome``, ``Sec-CH-UA-Mobile: ?0``), and the handle was viser's 6-7 CSS px gizmo there. The page tells the
server that its pointer is coarse (:mod:`tpm_viz.viserkit.seen`); then, measured in the page:

- the handle's size on screen: the canvas with the handle shown minus the canvas with it hidden (a server-side
  switch), the largest region that changed, in CSS px: at least 44 × 44 (WCAG 2.2 AAA), and it holds the middle of
  drei's square projected through the tab's camera (:func:`tests.e2e.test_browser_phone._handle`);
- the drag gain: a 36 px finger move from that middle moves the platform at most 36 mm (1 mm per CSS px);
- three touches that miss the handle orbit the camera (away from the framed pose by more than 50 mm); one tap on
  *Frame the mechanism* brings it back to within 5 mm of the pose it had (about 0.5 % of its distance: the page may
  report a drawing buffer of another size meanwhile, and the framing follows its aspect ratio to the pixel), the
  whole mechanism in the canvas.

On a 1366×768 laptop a mouse orbit and one click do the same, and on a 1024×768 projector in presentation mode (the
panel folded) the box of live numbers has the button. English and Korean; screenshots in a temporary folder.
"""

from __future__ import annotations

import io
import os
import tempfile

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from tests.e2e.test_browser_layout import chromium  # noqa: F401  (fixture)
from tests.e2e.test_browser_phone import CANVAS, _framed, _handle, _settled, _touch_drag
from tests.e2e.test_browser_stage import _open, _presentation_on
from tests.support.protocol import wait_for
from tpm_viz.core.words import Lang, shown
from tpm_viz.ui.app import TpmApp, build_server

pytestmark = [pytest.mark.browser, pytest.mark.slow]

LEAST_PX = 44.0
"""Least size of a touch target [CSS px] (WCAG 2.2 target size, level AAA)."""


@pytest.fixture
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


def _canvas_shot(page, rect) -> np.ndarray:
    """The canvas as RGB [0-255], once two shots in a row agree (the page drew what the server sent)."""
    clip = {"x": rect[0], "y": rect[1], "width": rect[2] - rect[0], "height": rect[3] - rect[1]}
    last: list[np.ndarray] = []

    def steady():
        shot = np.asarray(Image.open(io.BytesIO(page.screenshot(clip=clip))).convert("RGB"), dtype=int)
        same = bool(last) and last[-1].shape == shot.shape and np.array_equal(last[-1], shot)
        last.append(shot)
        return same

    wait_for(steady, timeout=20.0, interval=0.15, what="a steady canvas")
    return last[-1]


def _show_handle(view, on: bool) -> None:
    with view.hub.lock:
        view.scene.gizmo.visible = on
        view.client.flush()


def _handle_box(page, view) -> tuple[float, float, float, float]:
    """The handle's box on screen [CSS px]: left, top, right, bottom of the largest region that the handle changes."""
    rect = _settled(page, view)
    _show_handle(view, False)
    without = _canvas_shot(page, rect)
    _show_handle(view, True)
    wait_for(lambda: not np.array_equal(_canvas_shot(page, rect), without), what="the handle drawn again")
    with_it = _canvas_shot(page, rect)
    changed = np.abs(with_it - without).max(axis=-1) > 40
    labels, n = ndimage.label(changed)
    assert n > 0, "the handle changed nothing on screen"
    sizes = ndimage.sum(changed, labels, range(1, n + 1))
    ys, xs = np.nonzero(labels == 1 + int(np.argmax(sizes)))
    scale = (rect[2] - rect[0]) / with_it.shape[1]  # CSS px per screenshot pixel
    return (
        rect[0] + xs.min() * scale,
        rect[1] + ys.min() * scale,
        rect[0] + (xs.max() + 1) * scale,
        rect[1] + (ys.max() + 1) * scale,
    )


def _camera(view) -> np.ndarray:
    return np.asarray(view.client.camera.position, dtype=float)


def _still(view) -> np.ndarray:
    """The camera once the orbit has come to rest (three readings 0.2 s apart within 0.1 mm: the viewer's controls
    glide on after the pointer is lifted, and a frame set while they glide is carried away with them)."""
    readings: list[np.ndarray] = []

    def rested() -> bool:
        readings.append(_camera(view))
        return len(readings) >= 3 and max(np.linalg.norm(r - readings[-1]) for r in readings[-3:]) < 1e-4

    wait_for(rested, timeout=30, interval=0.2, what="the orbit at rest")
    return readings[-1]


def _frame_button(page, lang: Lang):
    return page.get_by_role("button", name=shown(lang, "Frame the mechanism"), exact=True)


@pytest.mark.parametrize("locale,lang", [("en-US", Lang.EN), ("ko-KR", Lang.KO)], ids=["en", "ko"])
def test_a_touch_phone_without_a_phones_user_agent_gets_the_touch_handle(served, chromium, locale, lang):  # noqa: F811
    shots = tempfile.mkdtemp(prefix="tpm-viz-touch-handle-")
    context, page, view = _open(served, chromium, (390, 844), locale=locale)
    try:
        assert "Mobi" not in page.evaluate("navigator.userAgent")  # the user agent does not say phone
        wait_for(lambda: view.scene.touch, what="the page telling the server its pointer is coarse")
        page.get_by_role("button", name=shown(lang, "Got it"), exact=True).tap()
        _framed(page, view)
        box = _handle_box(page, view)
        width, height = box[2] - box[0], box[3] - box[1]
        page.screenshot(path=os.path.join(shots, f"phone-handle-{lang.value}.png"))
        print(f"{lang.value}: the handle is {width:.0f} x {height:.0f} CSS px on screen")
        assert width >= LEAST_PX and height >= LEAST_PX, box
        rect = _settled(page, view)
        middle = _handle(view, rect)
        assert box[0] <= middle[0] <= box[2] and box[1] <= middle[1] <= box[3], (middle, box)

        cdp = context.new_cdp_session(page)
        start = np.array(view.session.state.pose.p)
        direction = -36.0 if middle[0] > (rect[0] + rect[2]) / 2 else 36.0  # towards the canvas's middle
        _touch_drag(cdp, page, float(middle[0]), float(middle[1]), direction)
        wait_for(lambda: view.session.state.pose.p[0] != start[0], what="the platform moved")
        wait_for(lambda: np.allclose(view.scene.gizmo.position[:2], view.session.state.pose.p), what="handle back")
        moved = np.linalg.norm(np.array(view.session.state.pose.p) - start)
        print(f"{lang.value}: a 36 px finger move moved the platform {moved * 1e3:.1f} mm")
        assert 0.0 < moved <= 36 * 1.0e-3 * 1.02, f"{moved * 1e3:.1f} mm for a 36 px drag"

        framed = _still(view)  # the framing done (presentation mode frames again for its canvas)
        for k in range(3):  # three touches that miss the handle: the camera orbits
            _touch_drag(cdp, page, rect[0] + 30.0, rect[3] - 30.0 - 10 * k, 60.0)
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) > 0.05, what="the camera orbited")
        _still(view)
        page.screenshot(path=os.path.join(shots, f"phone-orbited-{lang.value}.png"))
        _frame_button(page, lang).tap()  # one tap
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) < 5e-3, what="the framed camera back")
        _framed(page, view)
        page.screenshot(path=os.path.join(shots, f"phone-framed-{lang.value}.png"))
        print(f"screenshots: {shots}")
    finally:
        context.close()


def test_frame_the_mechanism_on_a_laptop_and_on_a_projector(served, chromium):  # noqa: F811
    shots = tempfile.mkdtemp(prefix="tpm-viz-frame-")
    context, page, view = _open(served, chromium, (1366, 768))
    try:
        assert not view.scene.touch  # a mouse: viser's gizmo with its arrows
        _framed(page, view)
        framed = _still(view)  # the framing done (presentation mode frames again for its canvas)
        rect = page.evaluate(CANVAS)
        page.mouse.move(rect[0] + 60, rect[3] - 60)
        page.mouse.down()
        page.mouse.move(rect[0] + 200, rect[3] - 120, steps=8)
        page.mouse.up()
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) > 0.05, what="the camera orbited")
        _still(view)
        _frame_button(page, Lang.EN).click()
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) < 5e-3, what="the framed camera back")
        page.screenshot(path=os.path.join(shots, "laptop-1366x768-framed.png"))
    finally:
        context.close()

    context, page, view = _open(served, chromium, (1024, 768))
    try:
        _presentation_on(page, view)
        page.wait_for_selector("[data-dock-rail-root]")
        _framed(page, view)
        framed = _still(view)  # the framing done (presentation mode frames again for its canvas)
        rect = page.evaluate(CANVAS)
        page.mouse.move(rect[2] - 120, rect[1] + 120)  # clear of the WebGL notice, the mechanism and the live box
        page.mouse.down()
        page.mouse.move(rect[2] - 280, rect[1] + 180, steps=8)
        page.mouse.up()
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) > 0.05, what="the camera orbited")
        _still(view)
        button = page.locator("[data-floating-window]").get_by_role("button", name="Frame the mechanism", exact=True)
        button.click()  # in the box of live numbers: the panel stays folded
        wait_for(lambda: np.linalg.norm(_camera(view) - framed) < 5e-3, what="the framed camera back")
        assert page.locator("[data-dock-rail-root]").count() == 1
        page.screenshot(path=os.path.join(shots, "projector-1024x768-framed.png"))
        print(f"screenshots: {shots}")
    finally:
        context.close()
