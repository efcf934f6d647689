"""A stage for the room (issue 25), measured in headless Chromium: a 1024×768 projector in presentation mode, a
1366×768 and a 1024×768 laptop in normal mode, a 390×844 touch phone.

Measured in the page (:data:`tests.support.stage.STAGE`): the 3D canvas's share of the window (its bounding box), the
rows of tabs (distinct tops of the panel's tab elements), the first control of every tab (its bottom inside the
window, before any scrolling), the font size of the live numbers in presentation mode, and the mechanism framed in
the canvas, clear of the panel and of the box of live numbers (the pinhole check of ``test_browser_layout``).
The first visit's guide: shown to a new browser, gone after *Got it*, not shown again to the same browser after a
reload, shown again to another browser.
"""

from __future__ import annotations

import os
import tempfile

import pytest

from tests.e2e.test_browser_layout import _in_view, chromium, served  # noqa: F401  (fixtures)
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, STAGE, open_tab
from tpm_viz.core.words import Lang, T, say, shown
from tpm_viz.ui.look import PANEL_WIDTH
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

LIVE_NUMBERS = """
() => [...document.querySelectorAll('[data-live] [data-q]')].filter(e => e.getClientRects().length > 0)
  .map(e => [e.dataset.q, parseFloat(getComputedStyle(e).fontSize)])
"""
"""Font size [CSS px] of each number (and the pose status) shown in the box of live numbers."""
LIVE_SHOWN = """
() => { const w = document.querySelector('[data-floating-window]:has([data-live])');
        return !!w && getComputedStyle(w).visibility === 'visible' && w.getBoundingClientRect().height > 0; }
"""
SINGULARITY_BUTTONS = ("Near an inverse singularity", "Near the direct singularity", "At a stroke end")
FORCE_ROOM = """
() => {  // each force readout's right edge [px] and the right edge of the panel's content box (its scroll bar off)
  const marker = document.querySelector('[data-tpmviz-keys]');
  const region = marker.closest('[data-dock-region]');
  const viewport = region.querySelector('.mantine-ScrollArea-viewport').getBoundingClientRect();
  const bars = [...region.querySelectorAll('.mantine-ScrollArea-scrollbar[data-orientation=vertical]')]
    .map(e => e.getBoundingClientRect()).filter(r => r.width > 0);
  const content = Math.min(viewport.right, ...bars.map(r => r.left));
  const spans = [...region.querySelectorAll('[data-q=tau1], [data-q=tau2]')].filter(e => e.getClientRects().length)
    .map(e => e.parentElement.getBoundingClientRect().right);
  return {content, spans};
}
"""
TIP_CLEAR = """
() => {  // the hint shown, and the panel's inputs and buttons its box intersects
  const tip = [...document.querySelectorAll('.mantine-Tooltip-tooltip')].find(e => e.getClientRects().length
    && parseFloat(getComputedStyle(e).opacity) > 0.5);
  if (!tip) return null;
  const t = tip.getBoundingClientRect();
  const region = document.querySelector('[data-tpmviz-keys]').closest('[data-dock-region]');
  const hit = [...region.querySelectorAll('input:not([type=hidden]), textarea, button, [role=slider], [role=tab]')]
    .filter(e => e.getClientRects().length).filter(e => { const r = e.getBoundingClientRect();
      return r.width > 0 && r.left < t.right && t.left < r.right && r.top < t.bottom && t.top < r.bottom; })
    .map(e => e.getAttribute('aria-label') || e.textContent.trim() || e.tagName);
  return {text: tip.textContent.trim(), box: [t.left, t.top, t.right, t.bottom], hit};
}
"""
GUIDE_BOXES = (
    "() => [...document.querySelectorAll('[data-guide] *')].map(e => { const r = e.getBoundingClientRect(); "
    "return [r.left, r.right]; })"
)
"""Left and right edges [CSS px] of every element of the first visit's guide (its lines and its colour legend)."""
FOLDED = "() => !!document.querySelector('[data-dock-rail-root]')"
"""The panel folded to its rail."""


def _room_for_the_forces(page, where: str) -> None:
    room = page.evaluate(FORCE_ROOM)
    assert len(room["spans"]) == 2, room
    assert all(right <= room["content"] - 4 for right in room["spans"]), f"{where}: {room}"


@pytest.fixture(scope="module")
def shots():
    """Where the screenshots go: ``TPM_VIZ_SCREENSHOTS`` (docs/app.md's come from there), else a temporary folder."""
    folder = os.environ.get("TPM_VIZ_SCREENSHOTS") or tempfile.mkdtemp(prefix="tpm-viz-stage-")
    os.makedirs(folder, exist_ok=True)
    yield folder
    print(f"screenshots: {folder}")


def _open(served, chromium, size, context=None, locale="en-US"):  # noqa: F811
    touch = size == (390, 844)
    if context is None:
        context = chromium.new_context(
            viewport={"width": size[0], "height": size[1]}, has_touch=touch, is_mobile=touch, locale=locale
        )
    before = set(served.views)
    page = context.new_page()
    page.goto(f"http://127.0.0.1:{served.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=120_000)
    new = wait_for(lambda: set(served.views) - before, what="the tab's view")
    view = served.views[next(iter(new))]
    wait_for(lambda: view in served.guides.greeted, what="the tab's view connected and greeted")
    return context, page, view


def _every_tab(page, where: str) -> dict[str, float]:
    """Open every tab; check at most two rows of tabs and the tab's first control on screen; its bottom [px]."""
    bottoms = {}
    for name in GROUP_OF:
        if name == "Design":
            page.get_by_role("tab", name=GROUP_OF[name], exact=True).click()
            if page.get_by_role("tab", name="Design", exact=True).count() == 0:
                continue  # the Design view is not in this build
        open_tab(page, name)
        stage = page.evaluate(STAGE)
        assert len(stage["rows"]) <= 2, f"{where}, {name}: tabs on {len(stage['rows'])} rows {stage['names']}"
        first = stage["first"]
        assert first is not None, f"{where}, {name}: nothing under the tabs"
        assert first["bottom"] <= stage["height"], f"{where}, {name}: first control {first} below the window"
        bottoms[name] = first["bottom"]
    open_tab(page, "Move")
    return bottoms


def _buttons_in_view(page, where: str) -> None:
    for label in SINGULARITY_BUTTONS:
        box = page.get_by_role("button", name=label, exact=True).bounding_box()
        assert box is not None and box["y"] + box["height"] <= page.viewport_size["height"], f"{where}: {label} {box}"


def _presentation_on(page, view) -> None:
    open_tab(page, "Class & view")
    page.locator(f'[id="{widget_uuid(view.panel.presentation)}"]').click()
    wait_for(lambda: view.look.presentation, what="presentation mode on the server")


def test_the_projector_in_presentation_mode(served, chromium, shots):  # noqa: F811
    context, page, view = _open(served, chromium, (1024, 768))
    try:
        _presentation_on(page, view)
        # the controls fold to the rail: the canvas is the screen, the live numbers float over its bottom
        wait_for(lambda: page.evaluate(STAGE)["share"] >= 0.6, what="the 3D view on 60 % of the projector")
        wait_for(lambda: page.evaluate(LIVE_SHOWN), what="the box of live numbers")
        _in_view(page, view, "the mechanism framed on the projector, clear of the live numbers")
        share = page.evaluate(STAGE)["share"]
        sizes = dict(page.evaluate(LIVE_NUMBERS))
        assert {"banner", "p1", "p2", "d1", "d2", "tau1", "tau2"} <= set(sizes), sizes
        assert min(sizes.values()) >= 20.0, sizes
        bars = page.locator("[data-live] [style*='grid-template-columns']")
        assert bars.count() == 2 and all(bars.nth(i).is_visible() for i in range(2))  # τ₁ and τ₂ with their bars
        page.screenshot(path=os.path.join(shots, "projector-1024x768-presentation.png"))
        print(f"projector 1024x768, presentation mode, panel folded: canvas share {share:.3f}")

        page.locator('[aria-label^="Expand"]').first.click()  # the lecturer: one click on the rail
        wait_for(lambda: page.evaluate(STAGE)["rows"], what="the panel back")
        stage = page.evaluate(STAGE)
        assert stage["canvas"][2] <= 1024 - 400, stage  # the panel is docked beside the canvas again
        bottoms = _every_tab(page, "projector, presentation mode, panel open")
        _buttons_in_view(page, "projector, presentation mode, panel open")
        print(f"projector, presentation mode, panel open: first control bottoms {bottoms}")

        # ... or one key, P, from anywhere but a text field (the keyboard alone from here on)
        field = page.locator('textarea[aria-label="Platform p1 (mm)"]')
        field.focus()
        page.keyboard.press("End")
        page.keyboard.press("p")  # typed into the field: the panel stays
        page.wait_for_function("document.activeElement.value.endsWith('p')")
        assert not page.evaluate(FOLDED)
        page.keyboard.press("Backspace")
        page.keyboard.press("Escape")
        page.locator("canvas[tabindex]").first.focus()  # the 3D view (Tab reaches it)
        page.keyboard.press("p")
        page.wait_for_function(FOLDED)
        wait_for(lambda: page.evaluate(LIVE_SHOWN), what="the box of live numbers with the panel folded by P")
        page.keyboard.press("p")  # the focus is on the page: P again brings the panel back
        page.wait_for_function(f"!({FOLDED})()")
        wait_for(lambda: page.evaluate(STAGE)["rows"], what="the panel back by P")
    finally:
        context.close()


@pytest.mark.parametrize("size", [(1366, 768), (1024, 768)], ids=["1366x768", "1024x768"])
def test_a_laptop_in_normal_mode_and_the_first_visit(served, chromium, shots, size):  # noqa: F811
    context, page, view = _open(served, chromium, size)
    name = f"{size[0]}x{size[1]}"
    try:
        stage = page.evaluate(STAGE)
        width = stage["canvas"][2] - stage["canvas"][0]
        assert width >= 0.5 * size[0], stage
        guide = page.locator("[data-guide]")
        assert guide.is_visible()  # a new browser: the guide, with the singularity buttons in view beside it
        _buttons_in_view(page, f"{name} with the guide")
        with_guide = _every_tab(page, f"{name} with the guide")
        page.screenshot(path=os.path.join(shots, f"laptop-{name}-guide.png"))
        page.get_by_role("button", name="Got it").click()
        wait_for(lambda: not view.panel.guide.visible, what="the guide dismissed")
        page.wait_for_selector("[data-guide]", state="detached")
        _buttons_in_view(page, f"{name} after the guide")
        after = _every_tab(page, f"{name} after the guide")
        legend = page.get_by_text("workspace: poses inside the stroke", exact=False)
        legend.scroll_into_view_if_needed()
        assert legend.is_visible()  # the colour legend is on the Move tab
        _room_for_the_forces(page, name)
        print(f"{name}: canvas width {width:.0f} px ({width / size[0]:.2f}); first control bottoms {after}")
        print(f"{name} with the guide open: {with_guide}")
        page.screenshot(path=os.path.join(shots, f"laptop-{name}.png"))

        _, page2, view2 = _open(served, chromium, size, context=context)  # the same browser, a new page
        page.close()
        assert not view2.panel.guide.visible and page2.locator("[data-guide]").count() == 0
        other, page3, view3 = _open(served, chromium, size)  # another browser: its own first visit
        try:
            wait_for(lambda: view3.panel.guide.visible, what="the guide for a new browser")
            page3.wait_for_selector("[data-guide]")
        finally:
            other.close()
    finally:
        context.close()


def _tip(page, where: str) -> dict:
    tip = wait_for(lambda: page.evaluate(TIP_CLEAR), what=f"the hint shown ({where})")
    assert tip["hit"] == [], f"{where}: the hint {tip}"
    return tip


def test_hints_beside_the_panel_and_room_for_the_forces_in_korean(served, chromium, shots):  # noqa: F811
    context, page, _ = _open(served, chromium, (1366, 768), locale="ko-KR")
    try:
        _room_for_the_forces(page, "1366x768, Korean")
        field = page.locator(f'textarea[aria-label="{shown(Lang.KO, "Platform p2 (mm)")}"]')
        field.hover()  # a hint of a field with one above it: drawn beside the panel, over the 3D view
        hovered = _tip(page, "hover")
        page.mouse.move(5, 700)
        page.wait_for_function(f"!({TIP_CLEAR})()")
        field.focus()  # keyboard focus shows it too, in the same place
        focused = _tip(page, "keyboard focus")
        assert focused["text"] == hovered["text"] and hovered["box"][2] <= 1366 - PANEL_WIDTH  # over the 3D view
        page.screenshot(path=os.path.join(shots, "hint-1366x768-ko.png"))
        # viser's own names in the tab's language
        collapse = page.locator("[data-dock-region-collapse]").first
        expected = say(Lang.KO, T("Collapse panel area"))
        assert expected != "Collapse panel area"
        wait_for(lambda: collapse.get_attribute("aria-label") == expected, what="viser's names in Korean")
    finally:
        context.close()


def test_a_phone(served, chromium, shots):  # noqa: F811
    context, page, view = _open(served, chromium, (390, 844))
    try:
        _in_view(page, view, "the mechanism framed above the sheet")
        legend = page.evaluate(GUIDE_BOXES)
        assert legend and all(0 <= left and right <= 390 for left, right in legend), legend
        notice = page.locator("#webgl-software-rendering")
        if notice.count():  # a computer without a GPU: one line at the top, not the 3D view's middle
            box = notice.bounding_box()
            assert box is not None and box["height"] <= 30 and box["y"] + box["height"] <= 40, box
        stage = page.evaluate(STAGE)
        assert stage["share"] >= 0.5 and len(stage["rows"]) <= 2, stage
        page.get_by_role("button", name="Got it").click()
        wait_for(lambda: not view.panel.guide.visible, what="the guide dismissed")
        bottoms = _every_tab(page, "phone")
        print(f"phone 390x844: canvas share {stage['share']:.3f}; first control bottoms {bottoms}")
        page.screenshot(path=os.path.join(shots, "phone-390x844.png"))
    finally:
        context.close()
