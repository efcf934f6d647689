"""The *Design* tab in headless Chromium at 1366 x 768: a small map is computed (its progress line in the page),
*Load best design* loads the best design, and the *Parameters* tab then shows its dimensions; no script error; a
screenshot is kept (``TPM_VIZ_SCREENSHOTS``: a folder to copy it to)."""

from __future__ import annotations

import os
import shutil

import numpy as np
import pytest

from tests.support.browser import text_input
from tests.support.protocol import wait_for

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _open(page, name: str) -> None:
    """Open the tab ``name``, inside its group's tab when the panel groups its tabs."""
    tab = page.get_by_role("tab", name=name, exact=True)
    if not tab.first.is_visible():
        for group in ("Lab", "Setup", "Explore", "Teach"):
            handle = page.get_by_role("tab", name=group, exact=True)
            if handle.count():
                handle.first.click()
                if tab.first.is_visible():
                    break
    tab.first.click()


def _keep(path) -> None:
    folder = os.environ.get("TPM_VIZ_SCREENSHOTS")
    if folder:
        shutil.copy(path, folder)


def test_design_tab_computes_a_map_and_loads_a_design(app, browser, tmp_path):
    page = browser.new_page()
    page.set_viewport_size({"width": 1366, "height": 768})
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=90_000)  # a busy machine: the page may take long
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    dv = view.teaching.design

    _open(page, "Design")
    for key, text in (("x_count", "3"), ("y_count", "3")):
        field = text_input(page, dv.range_box.inputs[key])
        field.fill(text)
    page.get_by_role("button", name="Compute map").click()
    wait_for(lambda: dv.spec is not None and dv.done == 9, timeout=60, what="the map of 9 designs")
    page.locator("[data-q=design-progress]").first.wait_for(timeout=60_000)
    wait_for(
        lambda: "9 designs" in page.locator("[data-q=design-progress]").first.inner_text(), what="the progress line"
    )
    assert dv.spec.x.count == 3 and dv.spec.y.count == 3  # the typed counts were applied by the button

    gci = np.array([row["gci"] if row["feasible"] else -1.0 for row in dv.rows])
    best = dv.rows[int(np.argmax(gci))]
    page.get_by_role("button", name="Load best design").click()
    with view.hub.lock:
        before = view.session.state.params
    wait_for(
        lambda: (
            view.session.state.params.a == pytest.approx(best["a"]) and view.session.state.params.l_a == best["l_a"]
        ),
        what="the best design loaded",
    )
    page.locator("[data-q=design-cell]").first.wait_for(timeout=60_000)
    shot = tmp_path / "design-tab.png"
    page.screenshot(path=str(shot))
    _keep(shot)

    _open(page, "Parameters")
    a_field, l_field = (text_input(page, view.panel.params.inputs[k]) for k in ("a", "l_a"))
    wait_for(lambda: a_field.input_value() == f"{best['a'] * 1e3:g}", what="a shown in Parameters")
    wait_for(lambda: l_field.input_value() == f"{best['l_a'] * 1e3:g}", what="l_a shown in Parameters")
    assert (before.a, before.l_a) == (best["a"], best["l_a"]) or a_field.input_value() != "482"
    assert not errors, errors
