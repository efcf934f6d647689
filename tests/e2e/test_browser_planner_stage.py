"""The Planner tab opened after a control run (issue 40, item 5), in headless Chromium: on a 1366×768 laptop in
English and a 390×844 touch phone in Korean, a click on the Planner's tab is enough (the page tells the server which
tab it shows: :mod:`tpm_viz.viserkit.seen`) for the scene to show the Planner's pick path and force bars, the
mechanism at the plan's start with the plan's dynamic load, and not the lab's green ghost and paths or the demo's
ellipses; the Control tab opened again brings the lab's drawing back. Screenshots in a temporary folder.
"""

from __future__ import annotations

import os
import tempfile

import pytest

from tests.e2e.test_browser_layout import chromium  # noqa: F401  (fixture)
from tests.e2e.test_browser_stage import _open
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, open_tab
from tpm_viz.core.words import Lang, shown
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.teaching.stage import CONTROL, PLAN, front
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = [pytest.mark.browser, pytest.mark.slow]


@pytest.fixture
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


def _open_tab(page, lang: Lang, name: str) -> None:
    open_tab(page, shown(lang, name), shown(lang, GROUP_OF[name]))


@pytest.mark.parametrize(
    ("size", "locale", "lang"), [((1366, 768), "en-US", Lang.EN), ((390, 844), "ko-KR", Lang.KO)], ids=["en", "ko"]
)
def test_opening_the_planner_shows_its_path_and_forces(served, chromium, size, locale, lang):  # noqa: F811
    shots = tempfile.mkdtemp(prefix="tpm-viz-planner-stage-")
    context, page, view = _open(served, chromium, size, locale=locale)
    try:
        explorer = view.teaching.explorer
        _open_tab(page, lang, "Explorer")
        page.locator(f'[id="{widget_uuid(explorer.ellipses)}"]').click()  # the ellipses on (a demo's)
        wait_for(lambda: explorer.ellipses_on, what="the ellipses on")
        _open_tab(page, lang, "Control")
        cv = view.teaching.control
        page.locator(f'[id="{widget_uuid(cv.simulate)}"]').click()
        wait_for(lambda: cv.run is not None and not cv.busy, timeout=60, what="the control run")
        wait_for(lambda: cv.nodes.ghost is not None and cv.nodes.ghost.visible, what="the green ghost")
        page.screenshot(path=os.path.join(shots, f"control-{lang.value}.png"))
        pv = view.teaching.planner
        wait_for(lambda: pv.player.motion is not None, timeout=60, what="the default plan")

        _open_tab(page, lang, "Planner")
        wait_for(lambda: front(view) == PLAN, what="the Planner in front")
        wait_for(lambda: view.session.state.trajectory.kind.startswith("plan#"), what="the mechanism on the plan")
        wait_for(lambda: pv._path is not None and pv._path.visible, what="the pick path drawn")
        assert not cv.nodes.ghost.visible and not any(h.visible for h in cv.nodes.paths.values())
        assert not any(h.visible for h in explorer._ellipses.values())
        assert pv._bars is not None and pv._bars.visible
        dashboard = page.locator("[data-q=banner]").first.locator("xpath=..")
        wait_for(lambda: shown(lang, "the planned path") in dashboard.inner_text(), what="the plan's load named")
        page.screenshot(path=os.path.join(shots, f"planner-{lang.value}.png"))

        _open_tab(page, lang, "Control")
        wait_for(lambda: front(view) == CONTROL, what="the Control lab in front again")
        wait_for(lambda: any(h.visible for h in cv.nodes.paths.values()), what="the lab's paths back")
        wait_for(lambda: all(h.visible for h in explorer._ellipses.values()), what="the ellipses back")
        print(f"screenshots: {shots}")
    finally:
        context.close()
