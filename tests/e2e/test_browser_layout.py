"""The projector and the phone (issue 13), in headless Chromium at four screens: 1024×768 (a projector), 1366×768
(a laptop), 1920×1080 (full HD) and 390×844 with touch (a phone), in normal and in presentation mode.

On each screen, measured in the page: the panel and everything in it stays inside the window and inside the panel
(bounding boxes; no text or input wider than its box, no horizontal scrolling of the panel; an equation wider than
the panel scrolls in its own box); the mechanism is in view: the 8 corners of the box around the base plate and the
pins, projected through the tab's camera as the server knows it (position, orientation, field of view and canvas
size reported by the browser; a pinhole written here), land inside the 3D canvas and outside the panel. On the
phone the panel's sheet is at most 45 % of the height, every control is at least 24 px across (a button or tab
44 px), and with the sheet collapsed to its handle the mechanism is framed again in the taller canvas. In presentation
mode (which folds the panel to its rail; one click brings it back) every cell of the compact readout (p, d, τ₁, τ₂) is
at least 20 px, and on the projector with the panel folded the box of live numbers shows, with the mechanism clear of
it. One app and one browser for the module; the screenshots
are kept in a temporary folder named in the output.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pytest

from tests.support.browser import launched_chromium
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.drawing import meshes
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

SCREENS = [(1024, 768), (1366, 768), (1920, 1080), (390, 844)]
LIVE_QS = ["p1", "p2", "d1", "d2", "tau1", "tau2"]
"""The numbers of the compact readout (presentation mode; with the pose status): p, d and the two forces."""
PHONE = (390, 844)
PANEL = '[data-testid="floating-panel"], .mantine-Paper-root[style*="position: fixed"]'
"""The control panel: docked beside the canvas on a wide screen, a sheet along the bottom on a phone."""

OVERFLOW = """
(selector) => {
  const panel = document.querySelector(selector);
  const p = panel.getBoundingClientRect();
  const out = [];
  if (p.left < -1 || p.top < -1 || p.right > innerWidth + 1 || p.bottom > innerHeight + 1)
    out.push(`the panel ${p.left},${p.top},${p.right},${p.bottom} is outside the ${innerWidth}x${innerHeight} window`);
  for (const e of panel.querySelectorAll('*')) {
    if (e.clientWidth === 0) continue;
    const scroller = e.closest('[style*="overflow-x:auto"]');  // an equation: scrolls in its own box
    if (scroller && scroller !== e) continue;
    const s = getComputedStyle(e);
    if (s.visibility === 'hidden') continue;
    const r = e.getBoundingClientRect();
    const what = `${e.tagName} "${(e.tagName === 'INPUT' ? e.value : e.textContent).trim().slice(0, 50)}"`;
    if (r.right > p.right + 1 || r.left < p.left - 1)
      out.push(`${what} sticks out: ${r.left}-${r.right} of ${p.left}-${p.right}`);
    const text = [...e.childNodes].some(n => n.nodeType === 3 && n.textContent.trim());
    const input = e.tagName === 'INPUT' && e.type !== 'hidden';
    const scrolls = (s.overflowX === 'auto' || s.overflowX === 'scroll') && e !== scroller;
    if ((text || input || scrolls) && e.scrollWidth > e.clientWidth + 1)
      out.push(`${what} is wider inside than its box: ${e.scrollWidth} > ${e.clientWidth}`);
  }
  return out;
}
"""
"""Every way the panel or something in it is cut or sticks out (empty: none)."""

TARGETS = """
(selector) => {
  const panel = document.querySelector(selector);
  const out = [];
  const sel = 'button, [role=tab], [role=slider], .mantine-Slider-root, input:not([type=hidden]), [role=checkbox]';
  for (const e of panel.querySelectorAll(sel)) {
    const r = e.getBoundingClientRect();
    if (r.width === 0 || r.height === 0 || getComputedStyle(e).visibility === 'hidden') continue;
    const least = (e.tagName === 'BUTTON' || e.getAttribute('role') === 'tab') ? 44 : 24;
    if (r.width < least - 0.01 || r.height < least - 0.01)
      out.push(`${e.tagName} "${e.textContent.trim().slice(0, 30)}" ${r.width.toFixed(1)}x${r.height.toFixed(1)}`);
  }
  return out;
}
"""
"""Every visible control of the panel smaller than 24 × 24 CSS px, or a button or tab smaller than 44 × 44 (empty:
none)."""

RECTS = """
(selector) => {
  const box = (e) => {
    if (!e) return null;
    const r = e.getBoundingClientRect();
    return [r.left, r.top, r.right, r.bottom];
  };
  const live = document.querySelector('[data-floating-window]:has([data-live])');
  return {canvas: box(document.querySelector('canvas[data-engine]')), panel: box(document.querySelector(selector)),
          live: live && getComputedStyle(live).visibility === 'visible' ? box(live) : null};
}
"""

FONT_SIZES = """
(scope) => [...document.querySelectorAll(`${scope} [data-q]`)]
  .filter(e => e.getClientRects().length > 0)  // shown
  .filter(e => !['banner', 'tau1_ref', 'tau2_ref', 'tau1_diff', 'tau2_diff'].includes(e.dataset.q))
  .map(e => [e.dataset.q, parseFloat(getComputedStyle(e).fontSize)])
"""
"""Font size [CSS px] of each readout cell shown (kinematics and the two forces) under ``scope``."""


@pytest.fixture(scope="module")
def served():
    server = build_server("127.0.0.1", 0)
    application = TpmApp(server)
    yield application
    application.stop()


@pytest.fixture(scope="module")
def chromium():
    with launched_chromium() as browser:
        yield browser


@pytest.fixture(scope="module")
def shots():
    folder = tempfile.mkdtemp(prefix="tpm-viz-layout-")
    yield folder
    print(f"screenshots: {folder}")


def _open(served, chromium, size, locale="en-US"):
    """A new page of ``size`` (touch for the phone) and the app's view of it."""
    touch = size == PHONE
    context = chromium.new_context(
        viewport={"width": size[0], "height": size[1]}, has_touch=touch, is_mobile=touch, locale=locale
    )
    before = set(served.views)
    page = context.new_page()
    page.goto(f"http://127.0.0.1:{served.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=30_000)
    new = wait_for(lambda: set(served.views) - before, what="the tab's view")
    view = served.views[next(iter(new))]
    return context, page, view


def _canvas_fractions(view, points) -> np.ndarray:
    """Where world points [m] land in the tab's canvas (fractions of its width and height from the top-left), by a
    pinhole camera with viser's pose (OpenCV axes: x right, y down, z forward) and vertical field of view."""
    import viser.transforms as tf

    cam = view.client.camera
    rot = tf.SO3(np.asarray(cam.wxyz)).as_matrix()
    xc = (np.asarray(points, dtype=float) - np.asarray(cam.position)) @ rot  # rows: rot.T @ (p - c)
    assert np.all(xc[:, 2] > 0), "a corner of the mechanism is behind the camera"
    focal = 0.5 / np.tan(cam.fov / 2)  # in canvas heights
    aspect = cam.image_width / cam.image_height
    return np.stack([0.5 + focal * xc[:, 0] / xc[:, 2] / aspect, 0.5 + focal * xc[:, 1] / xc[:, 2]], axis=1)


def _corners(params) -> np.ndarray:
    lo, hi = meshes.base_extent(params)
    return np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (-0.012, meshes.PIN_Z[1])])


def _mechanism_problems(page, view) -> list[str]:
    """Why the mechanism is not fully in view in the canvas, clear of the panel and of the live box (empty: it is)."""
    rects = page.evaluate(RECTS, PANEL)
    canvas = rects["canvas"]
    width, height = canvas[2] - canvas[0], canvas[3] - canvas[1]
    reported = view.client.camera.image_width / view.client.camera.image_height
    if abs(width / height / reported - 1.0) > 0.02:
        return [f"the server's canvas aspect {reported:.3f} is not the page's {width / height:.3f} yet"]
    uv = _canvas_fractions(view, _corners(view.session.state.params))
    xs, ys = canvas[0] + uv[:, 0] * width, canvas[1] + uv[:, 1] * height
    problems = []
    for x, y in zip(xs, ys, strict=True):
        if not (canvas[0] <= x <= canvas[2] and canvas[1] <= y <= canvas[3]):
            problems.append(f"corner at ({x:.0f}, {y:.0f}) outside the canvas {canvas}")
        for name in ("panel", "live"):
            r = rects[name]
            if r is not None and r[0] < x < r[2] and r[1] < y < r[3]:
                problems.append(f"corner at ({x:.0f}, {y:.0f}) under the {name} {r}")
    return problems


def _in_view(page, view, what: str) -> None:
    problems: list[str] = []

    def fine() -> bool:
        problems[:] = _mechanism_problems(page, view)
        return not problems

    try:
        wait_for(fine, timeout=15.0, interval=0.2, what=what)
    except AssertionError as exc:
        raise AssertionError(f"{exc}: {problems}") from None


def _tab(page, name: str) -> None:
    open_tab(page, name)  # its group first (tests/support/stage.py)


def _fits(page, where: str) -> None:
    for tab in ("Move", "Equations", "Class & view"):
        _tab(page, tab)
        problems = page.evaluate(OVERFLOW, PANEL)
        assert problems == [], f"{where}, {tab} tab: {problems}"


def _presentation(page, view) -> None:
    _tab(page, "Class & view")
    page.locator(f'[id="{widget_uuid(view.panel.presentation)}"]').click()
    wait_for(lambda: view.look.presentation, what="presentation mode on the server")
    _unfold(page)
    _tab(page, "Move")


def _unfold(page) -> None:
    """Presentation mode folds the panel to its rail (on a wide screen; the phone's sheet stays): one click on the
    rail brings it back."""
    if page.viewport_size == {"width": PHONE[0], "height": PHONE[1]}:
        return
    rail = page.locator('[aria-label^="Expand"]')
    wait_for(lambda: rail.count() > 0, what="the panel folded to its rail")
    rail.first.click()
    wait_for(lambda: page.evaluate(RECTS, PANEL)["canvas"][2] < page.viewport_size["width"] - 300, what="the panel")


@pytest.mark.parametrize("size", SCREENS, ids=[f"{w}x{h}" for w, h in SCREENS])
def test_each_screen_in_normal_and_presentation_mode(served, chromium, shots, size):
    context, page, view = _open(served, chromium, size)
    name = f"{size[0]}x{size[1]}"
    try:
        _in_view(page, view, f"the mechanism in view at {name}")
        rects = page.evaluate(RECTS, PANEL)
        if size == PHONE:  # the sheet: full width, at most 45 % of the height, under the canvas
            panel = rects["panel"]
            assert panel[3] - panel[1] <= 0.45 * size[1] + 1 and panel[2] - panel[0] >= size[0] - 1
            assert rects["canvas"][3] <= panel[1] + 1
            _tab(page, "Move")
            assert page.evaluate(TARGETS, PANEL) == []
            handle = page.locator(PANEL).locator('div[style*="cursor: pointer"]').first
            handle.click()  # the sheet collapsed to its handle: the canvas takes the rest, the camera follows
            wait_for(lambda: page.evaluate(RECTS, PANEL)["panel"][1] > 0.9 * size[1], what="the sheet collapsed")
            _in_view(page, view, "the mechanism in view above the collapsed sheet")
            assert page.evaluate(RECTS, PANEL)["canvas"][3] > 0.9 * size[1]
            handle.click()
            wait_for(lambda: page.evaluate(RECTS, PANEL)["panel"][1] < 0.6 * size[1], what="the sheet open again")
        else:  # the panel beside the canvas, covering none of it
            assert rects["canvas"][2] <= rects["panel"][0] + 1
        page.screenshot(path=os.path.join(shots, f"{name}-normal.png"))
        _fits(page, name)

        _presentation(page, view)
        _in_view(page, view, f"the mechanism in view at {name} in presentation mode")
        sizes = page.evaluate(FONT_SIZES, PANEL.split(", ")[size == PHONE])  # the compact readout of the stage
        assert [q for q, _ in sizes] == LIVE_QS and min(px for _, px in sizes) >= 20.0, sizes
        page.screenshot(path=os.path.join(shots, f"{name}-presentation.png"))
        _fits(page, f"{name} in presentation mode")
        if size == PHONE:
            assert page.evaluate(TARGETS, PANEL) == []
        if size == (1024, 768):  # collapse the panel: the box of banner and forces shows, the mechanism is reframed
            page.locator("[data-dock-region-collapse]").first.click()
            wait_for(lambda: page.evaluate(RECTS, PANEL)["live"] is not None, what="the box of banner and forces")
            _in_view(page, view, "the mechanism in view, clear of the box of banner and forces")
            sizes = page.evaluate(FONT_SIZES, "[data-live]")
            assert [q for q, _ in sizes] == LIVE_QS and min(px for _, px in sizes) >= 20.0, sizes
            assert page.locator("[data-live] [data-q=banner]").is_visible()
            page.screenshot(path=os.path.join(shots, f"{name}-presentation-collapsed.png"))
    finally:
        context.close()


def test_a_korean_projector_in_presentation_mode(served, chromium, shots):
    """Korean words are longer and break differently: the panel still fits, in presentation mode too."""
    context, page, view = _open(served, chromium, (1024, 768), locale="ko-KR")
    try:
        wait_for(lambda: view.lang.value == "ko", what="a Korean tab")
        _in_view(page, view, "the mechanism in view")
        groups = ["살펴보기", "가르치기", "실험", "설정"]  # Explore, Teach, Lab, Setup
        open_tab(page, "수업·보기", group=groups[3])  # Class & view
        page.locator(f'[id="{widget_uuid(view.panel.presentation)}"]').click()
        wait_for(lambda: view.look.presentation, what="presentation mode on the server")
        _unfold(page)
        for group in groups:
            page.get_by_role("tab", name=group, exact=True).click()
            inner = page.locator(PANEL).get_by_role("tab")
            names = [inner.nth(i).inner_text().strip() for i in range(inner.count())]
            for name in names[len(groups) :]:  # the open group's tabs, after the row of groups
                open_tab(page, name, group=group)
                assert page.evaluate(OVERFLOW, PANEL) == [], f"Korean, presentation mode, the {name} tab"
        open_tab(page, "이동", group=groups[0])  # Move
        _in_view(page, view, "the mechanism in view in presentation mode")
        page.screenshot(path=os.path.join(shots, "1024x768-korean-presentation.png"))
    finally:
        context.close()
