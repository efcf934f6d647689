"""Honest panels in headless Chromium (issue 25): after a control run the page says whose dynamic load the forces
are, and back on Move, once the platform is moved (Home), the forces the page prints are the static load of the
pose: the paper's closed form at zero velocity and acceleration (:func:`tpm_viz.paper.dynamics.inverse_dynamics`),
read from the page's text, not from the app's state."""

from __future__ import annotations

import os

import numpy as np
import pytest

from tests.support.browser import CHROMIUM, CHROMIUM_ARGS
from tests.support.protocol import wait_for
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.ui.app import TpmApp, build_server

pytestmark = [pytest.mark.browser, pytest.mark.slow]

TEXTS = """() => ({banner: document.querySelector('[data-q=banner]')?.innerText || '',
  tau: ['tau1', 'tau2'].map(q => document.querySelector(`[data-q=${q}]`)?.innerText || '')})"""


@pytest.fixture
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


def _open_tab(page, *names: str) -> None:
    """Click the first of ``names`` that is a tab of the page (grouped tabs: the group, then the tab)."""
    for name in names:
        tab = page.get_by_role("tab", name=name, exact=True)
        if tab.count():
            tab.first.click()


def test_after_a_control_run_home_shows_the_static_load_in_the_page(served):
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            page = browser.new_context(viewport={"width": 1366, "height": 768}).new_page()
            before = set(served.views)
            page.goto(f"http://127.0.0.1:{served.port}/")
            page.wait_for_selector("[data-q=p1]", timeout=30_000)
            view = served.views[next(iter(wait_for(lambda: set(served.views) - before, what="the tab's view")))]
            _open_tab(page, "Lab", "Control")
            page.get_by_role("button", name="Simulate", exact=True).click()
            wait_for(
                lambda: "dynamic load of the control run" in page.evaluate(TEXTS)["banner"],
                timeout=60,
                interval=0.2,
                what="the run's line in the banner",
            )
            _open_tab(page, "Explore", "Move")
            page.get_by_role("button", name="Home (p = 0)").click()
            params = view.session.state.params
            expected = inverse_dynamics(params, (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), f_ext=(0.0, 0.0))

            def static_shown() -> bool:
                texts = page.evaluate(TEXTS)
                try:
                    tau = np.array([float(t.replace("−", "-")) for t in texts["tau"]])
                except ValueError:
                    return False
                return "control run" not in texts["banner"] and bool(np.allclose(tau, expected, atol=0.006))

            wait_for(static_shown, timeout=20, interval=0.2, what="the static load of the home pose in the page")
        finally:
            browser.close()
