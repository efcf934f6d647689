"""Keyboard and screen reader in headless Chromium (issue 25): the platform and the sliders move with keys by the
documented steps (1 mm, Shift 10 mm: docs/keyboard.md), a lesson is stepped with Tab and Enter only, the live region
speaks once when the pose crosses into a warning (not at each of the frames that follow), and axe-core finds no
moderate, serious or critical violation on any tab at 1366x768, nor on any tab group in Korean.

The steps are checked in the server's state and in the panel's readout (``[data-q=p1]``), the lesson against its
own file's numbers (:func:`tpm_viz.app.demos.demo_params`); axe-core is the copy ``axe-playwright-python`` bundles.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz.app.demos import demo_params
from tpm_viz.core.words import Lang, T, say

pytestmark = pytest.mark.browser

MM = 1e-3
FOCUSED = """() => { const e = document.activeElement;
  return [e.getAttribute("role") || e.tagName.toLowerCase(), e.getAttribute("title") || e.textContent.trim()]; }"""
VISIBLE_TABS = """() => [...document.querySelectorAll('[role="tab"]')].filter(e => e.offsetParent !== null)
  .map(e => e.getAttribute("title"))"""
TOP_TABS = """() => { const tabs = [...document.querySelectorAll('[role="tab"]')];
  return tabs.filter(e => e.parentElement === tabs[0].parentElement).map(e => e.getAttribute("title")); }"""
"""The tabs of the panel's first tab strip (the groups, when the tabs are grouped)."""


def _open(browser, app, width: int = 1366, height: int = 768):
    page = browser.new_page()
    page.set_viewport_size({"width": width, "height": height})
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", state="attached", timeout=60_000)
    page.wait_for_selector("[data-tpmviz-keys]", state="attached", timeout=60_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    return page, view, errors


def _near(value, target) -> bool:
    return bool(np.allclose(np.asarray(value, dtype=float), np.asarray(target, dtype=float), atol=1e-9, rtol=0))


def _tab_to(page, role: str, name: str, limit: int = 80) -> None:
    """Press Tab until the focused element is ``role`` named ``name`` (at most ``limit`` presses)."""
    for _ in range(limit):
        page.keyboard.press("Tab")
        if page.evaluate(FOCUSED) == [role, name]:
            return
    raise AssertionError(f"{role} {name!r} not reached with Tab")


def test_arrow_keys_move_the_platform_and_q_w_the_sliders(app, browser):
    page, view, errors = _open(browser, app)
    p0 = np.array(view.session.state.pose.p)
    assert _near(p0, (0.0, 0.0))  # home
    page.locator("canvas[tabindex]").first.focus()  # the 3D view takes focus (Tab reaches it too)
    for _ in range(5):
        page.keyboard.press("ArrowRight")
    page.keyboard.press("Shift+ArrowUp")
    wait_for(lambda: _near(view.session.state.pose.p, (5 * MM, 10 * MM)), what="p = (5, 10) mm")
    wait_for(  # both at once: a frame between the two keys' commits shows p1 = 5.0 with p2 = 0.0
        lambda: [page.locator(f"[data-q={q}]").first.inner_text() for q in ("p1", "p2")] == ["5.0", "10.0"],
        what="the readouts p1 = 5.0, p2 = 10.0",
    )

    # In a text field the arrows move the caret, not the platform; Q then moves slider 1 by 1 mm.
    d0 = np.array(view.session.state.pose.d)
    page.locator("textarea, input[type=text]").first.focus()
    page.keyboard.press("ArrowLeft")
    page.locator("canvas[tabindex]").first.focus()
    page.keyboard.press("q")
    wait_for(lambda: _near(view.session.state.pose.d[0], d0[0] + 1 * MM), what="d1 + 1 mm")
    page.keyboard.press("Shift+s")  # slider 2 back by 10 mm
    wait_for(lambda: _near(view.session.state.pose.d[1], d0[1] - 10 * MM), what="d2 - 10 mm")
    assert _near(view.session.state.pose.d[0], d0[0] + 1 * MM)
    assert errors == []


def test_the_live_region_speaks_once_when_the_pose_crosses_into_a_warning(app, browser):
    page, view, errors = _open(browser, app)
    page.locator("canvas[tabindex]").first.focus()
    for key in ("Shift+ArrowLeft", "Shift+ArrowDown") * 16:  # to p = (-160, -160) mm: still a regular pose
        page.keyboard.press(key)
        page.wait_for_timeout(30)
    wait_for(lambda: _near(view.session.state.pose.p, (-160 * MM, -160 * MM)), what="p = (-160, -160) mm")
    wait_for(lambda: not view.session.readout.alerts, what="a regular pose")
    page.wait_for_function("document.getElementById('tpmviz-live').textContent.startsWith('Regular pose')")
    page.evaluate("""() => {
      window.__spoken = []; window.__banners = [];
      const live = document.getElementById("tpmviz-live");
      new MutationObserver(() => window.__spoken.push(live.textContent))
        .observe(live, { childList: true, characterData: true, subtree: true });
      new MutationObserver(() => {
        const b = document.querySelector('[data-q="banner"] b');
        const t = b ? b.textContent : "";
        if (window.__banners[window.__banners.length - 1] !== t) window.__banners.push(t);
      }).observe(document.body, { childList: true, characterData: true, subtree: true });
    }""")
    for step in range(1, 11):  # 1 mm down the diagonal at a time, to (-170, -170) mm: cos(θ1+θ2) < 0.2 from -165
        page.keyboard.press("ArrowLeft")
        page.keyboard.press("ArrowDown")
        target = (-(160 + step) * MM, -(160 + step) * MM)
        wait_for(lambda target=target: _near(view.session.state.pose.p, target), what=f"p = {target}")
        value = f"{view.session.readout.det_jx:.3f}"
        if step >= 5:
            page.wait_for_function("(v) => (window.__banners.at(-1) || '').includes(v)", arg=value)
    warnings = [b for b in page.evaluate("window.__banners") if "direct singularity" in b]
    assert len(warnings) >= 5  # the banner's number changed at every step in the warning...
    spoken = page.evaluate("window.__spoken")
    assert len(spoken) == 1, spoken  # ...the live region spoke once, when the pose crossed into it
    assert "direct singularity" in spoken[0] and "eq. 12" in spoken[0]
    assert page.get_attribute("#tpmviz-live", "aria-live") == "polite"
    assert errors == []


def test_a_lesson_is_stepped_with_tab_and_enter_only(app, browser):
    page, view, errors = _open(browser, app)
    page.wait_for_function(f"({VISIBLE_TABS})().includes('Teach')")
    _tab_to(page, "tab", "Teach")
    page.keyboard.press("Enter")
    page.wait_for_function(f"({VISIBLE_TABS})().includes('Demos')")
    _tab_to(page, "tab", "Demos")
    page.keyboard.press("Enter")
    _tab_to(page, "button", "Next")
    page.keyboard.press("Enter")
    demos = view.teaching.demos
    wait_for(lambda: demos.index == 1, what="the second lesson")
    lesson = demos.lessons[1]
    wait_for(lambda: view.session.state.params == demo_params(lesson), what="the lesson's parameters")
    page.wait_for_function(  # the Demonstration drop-down shows it
        "(title) => [...document.querySelectorAll('input')].some(i => i.value === title)", arg=lesson.title
    )
    page.keyboard.press("Enter")  # the focus stayed on Next: the third lesson
    wait_for(lambda: demos.index == 2, what="the third lesson")
    assert errors == []


def _axe(axe, page) -> list[str]:
    """axe-core's moderate, serious and critical violations on the page as it is."""
    return [
        f"{v['id']} ({v['impact']}): {v['nodes'][0]['html'][:160]}"
        for v in axe.run(page).response["violations"]
        if v["impact"] in ("moderate", "serious", "critical")
    ]


def test_axe_core_finds_no_moderate_serious_or_critical_violation_on_any_tab(app, browser):
    axe = pytest.importorskip("axe_playwright_python.sync_playwright").Axe()
    page, view, errors = _open(browser, app)
    page.wait_for_function(f"({VISIBLE_TABS})().length > 0")
    groups = page.evaluate(TOP_TABS)
    found: dict[str, list[str]] = {}
    seen = []
    for group in groups:
        page.locator(f'[role="tab"][title="{group}"]').first.click()
        page.wait_for_function(
            f"document.querySelector('[role=\"tab\"][title=\"{group}\"]').getAttribute('aria-selected') === 'true'"
        )
        inner = [t for t in page.evaluate(VISIBLE_TABS) if t not in groups] or [None]
        for tab in inner:
            if tab is not None:
                page.locator(f'[role="tab"][title="{tab}"]').first.click()
            page.wait_for_timeout(300)  # the tab's widgets laid out
            seen.append(f"{group}/{tab}")
            bad = _axe(axe, page)
            if bad:
                found[f"{group}/{tab}"] = bad
    assert len(seen) >= 10, seen  # every tab of every group was checked
    # in Korean (the Language selector): every group, with viser's own names in Korean too
    page.get_by_role("combobox", name="Language").click()
    page.get_by_role("option", name=Lang.KO.label).click()
    wait_for(lambda: view.lang is Lang.KO, what="the tab in Korean")
    korean = [say(Lang.KO, T(group)) for group in groups]
    page.wait_for_function(
        "(names) => names.every(n => document.querySelector(`[role=tab][title='${n}']`))", arg=korean
    )
    for group in korean:
        page.locator(f'[role="tab"][title="{group}"]').first.click()
        page.wait_for_function(
            f"document.querySelector('[role=\"tab\"][title=\"{group}\"]').getAttribute('aria-selected') === 'true'"
        )
        page.wait_for_timeout(300)  # the tab's widgets laid out
        bad = _axe(axe, page)
        if bad:
            found[f"ko {group}"] = bad
    assert found == {}
    assert errors == []
