"""The two screenshots of the app that the README and the docs show are made here, in headless Chromium (software
WebGL), with the settings their captions state:

- ``screenshot.png`` (1400×860, the README and ``docs/index.md``): the paper's prototype on the circle of Fig. 5
  (T = 0.5 s) chosen in the *Player* tab and scrubbed to t = 0.17 s, shown on the *Move* tab (readouts, both models'
  forces);
- ``teaching.png`` (1400×900, ``docs/teaching.md``): Demo 1 (*Approach the direct singularity*) shown from the *Demos*
  tab, scrubbed to t = 0.42 s, on the *Player* tab (its force chart and time marker; the ``det J_x`` map and the
  ellipses come from the lesson).

Each waits until the page shows the state (the platform position of the circle at 0.17 s, the player's time), so the
picture is of that state. ``TPM_VIZ_SCREENSHOTS=docs python -m pytest tests/e2e/test_browser_docs_figures.py`` writes
them where the docs show them; without it they go to a temporary folder.
"""

from __future__ import annotations

import io
import os
import pathlib

import pytest
from PIL import Image

import tpm_viz as tv
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser


def _folder(tmp_path) -> pathlib.Path:
    folder = pathlib.Path(os.environ.get("TPM_VIZ_SCREENSHOTS") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _text(page, name: str) -> str:
    return page.locator(f"[data-q={name}]").first.inner_text()


def _open(app, browser, size):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.set_viewport_size({"width": size[0], "height": size[1]})
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=60_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    got_it = page.get_by_role("button", name="Got it", exact=True)
    if got_it.count():
        got_it.first.click()  # the first visit's guide, hidden as a returning lecturer has it
    return page, view, errors


WEBGL_NOTICE = "#webgl-software-rendering"
"""viser's notice of software WebGL (this machine has no GPU; a lecturer's laptop does not show it)."""


def _settle(page) -> None:
    """The notice of software WebGL closed, and a few frames of the 3D view drawn."""
    notice = page.locator(WEBGL_NOTICE)
    if notice.count():
        notice.locator("button[aria-label=Close]").click()
        notice.wait_for(state="detached", timeout=30_000)
    page.wait_for_timeout(500)  # the 3D view's next frames (software WebGL)


def _save(page, path: pathlib.Path) -> None:
    """The page as a PNG of 256 colours (a third of the size; the docs' pictures are in git)."""
    Image.open(io.BytesIO(page.screenshot())).convert("RGB").quantize(256).save(path, optimize=True)
    assert Image.open(path).size == tuple(page.viewport_size.values())


def _scrub(page, view, t: float) -> None:
    """The player at ``t`` [s], as its *Time* slider does it, then shown in the page."""
    player = view.teaching.player
    player.runs.seek(view.session, t, origin=view)
    wait_for(lambda: _text(page, "player-t") == f"{t:.3f}", timeout=30, what=f"t = {t} s in the page")


def test_the_apps_screenshot_is_the_circle_at_0_17_s(app, browser, tmp_path):
    page, view, errors = _open(app, browser, (1400, 860))
    open_tab(page, "Player")
    player = view.teaching.player
    page.locator(f'[id="{widget_uuid(player.choice)}"]').click()
    page.get_by_role("option", name="circle (Fig. 5)", exact=True).click()
    page.get_by_text("circle (Fig. 5), T = 0.5 s").first.wait_for(timeout=30_000)
    run = lambda: player.runs.of(view.session).run  # noqa: E731
    wait_for(lambda: run() is not None and run().source.kind == "circle", timeout=60, what="the circle's run")
    _scrub(page, view, 0.17)
    p = tv.circle_state(0.17, 0.5)[0] * 1e3  # mm
    open_tab(page, "Move")
    wait_for(lambda: (_text(page, "p1"), _text(page, "p2")) == (f"{p[0]:.1f}", f"{p[1]:.1f}"), what="p at 0.17 s")
    _settle(page)
    _save(page, _folder(tmp_path) / "screenshot.png")
    assert not errors, errors


def test_the_teaching_screenshot_is_demo_1_at_0_42_s(app, browser, tmp_path):
    page, view, errors = _open(app, browser, (1400, 900))
    open_tab(page, "Demos")
    page.get_by_role("button", name="Show this one", exact=True).click()
    demos = view.teaching.demos
    wait_for(lambda: demos.runs.of(view.session).extra is not None, what="demo 1's motion loaded")
    open_tab(page, "Player")
    page.get_by_text("approach the direct singularity, T = 0.5 s").first.wait_for(timeout=30_000)
    _scrub(page, view, 0.42)
    _settle(page)
    _save(page, _folder(tmp_path) / "teaching.png")
    assert not errors, errors
