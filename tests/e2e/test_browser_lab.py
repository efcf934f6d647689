"""The *Planner* and *Control* tabs in headless Chromium: the live cycle time and the sizing table appear in the
page; *Simulate* fills the run line and the comparison table; no script error; a screenshot of each tab is kept
(``TPM_VIZ_SCREENSHOTS``: a folder to copy them to)."""

from __future__ import annotations

import os
import shutil

import pytest

from tests.support.browser import WORKER_LOG_JS
from tests.support.protocol import wait_for
from tests.support.stage import open_tab

pytestmark = pytest.mark.browser


def _text(page, name: str) -> str:
    return page.locator(f"[data-q={name}]").first.inner_text()


def _keep(path) -> None:
    folder = os.environ.get("TPM_VIZ_SCREENSHOTS")
    if folder:
        shutil.copy(path, folder)


def test_planner_and_control_tabs_show_their_numbers(app, browser, tmp_path):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.add_init_script(WORKER_LOG_JS)
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=20_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")

    open_tab(page, "Planner")
    pv = view.teaching.planner
    wait_for(lambda: pv.result is not None, timeout=20, what="the first plan")
    page.locator("[data-q=cycle-time]").first.wait_for(timeout=10_000)
    wait_for(lambda: _text(page, "cycle-time") == f"{pv.result.cycle_time:.3f}", what="the cycle time in the page")
    assert page.locator("[data-q=sizing]").first.is_visible()
    assert "ABB IRB 360" in _text(page, "industry")
    shot = tmp_path / "planner-tab.png"
    page.screenshot(path=str(shot))
    _keep(shot)

    open_tab(page, "Control")
    page.get_by_role("button", name="Simulate").click()
    cv = view.teaching.control
    wait_for(lambda: cv.run is not None, timeout=20, what="the simulation")
    page.locator("[data-q=run-rms]").first.wait_for(timeout=10_000)
    wait_for(lambda: _text(page, "run-rms") == f"{cv.run.rms_error * 1e6:.2f}", what="the RMS error in the page")
    assert _text(page, "rms-ctc") == f"{cv.run.rms_error * 1e6:.2f}"
    shot = tmp_path / "control-tab.png"
    page.screenshot(path=str(shot))
    _keep(shot)
    assert not errors, errors
