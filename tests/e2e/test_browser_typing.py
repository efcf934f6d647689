"""Typed numbers and upload messages in headless Chromium, with the real keyboard and the real file input.

``5e-1`` typed key by key into the Player's Duration (viser's number inputs dropped the ``e``: T became 0.01 s)
gives T = 0.5 s, shown in the player's summary; a refused CSV gets its refusal under the upload button and never
the page's own green "File uploaded successfully" toast (hidden by ``viserkit/transport.py`` before the last part is
acknowledged), and a later good file clears the refusal. All GUI inputs share a 50 ms throttle in viser's
client: we pause.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from tests.support.browser import text_input
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

PAUSE = 0.08  # s, longer than the client's 50 ms input throttle
SUCCESS_TOAST = "File uploaded successfully"


def _text(page, name: str) -> str:
    return page.locator(f"[data-q={name}]").first.inner_text()


def _toast_seen(page, seconds: float) -> bool:
    """Whether the page shows viser's success toast at any moment of the next ``seconds`` (polled every 10 ms)."""
    return page.evaluate(
        """([text, ms]) => new Promise((done) => {
             const t0 = performance.now();
             const poll = () => {
               if (document.body.innerText.includes(text)) return done(true);
               if (performance.now() - t0 > ms) return done(false);
               setTimeout(poll, 10);
             };
             poll();
           })""",
        [SUCCESS_TOAST, seconds * 1000],
    )


def test_typing_5e_minus_1_into_duration_and_a_refused_upload(app, browser, tmp_path):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=20_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    player = view.teaching.player

    open_tab(page, "Player")
    page.locator(f'[id="{widget_uuid(player.choice)}"]').click()
    page.get_by_role("option", name="line (Fig. 4)", exact=True).click()
    page.get_by_text("line (Fig. 4), T = 0.2 s").first.wait_for(timeout=10_000)
    time.sleep(PAUSE)

    field = text_input(page, player.duration.inputs["T"])
    field.click()
    field.press("Control+a")
    page.keyboard.type("5e-1", delay=60)  # one key at a time, as a person types
    time.sleep(0.3)
    assert view.session.state.trajectory.duration == pytest.approx(0.2)  # nothing applied mid-typing
    field.press("Enter")
    page.get_by_text("line (Fig. 4), T = 0.5 s").first.wait_for(timeout=10_000)
    # the field keeps what was typed, without the Enter's line break: it means the value in use (the form's submit
    # may settle the group before the text with the line break arrives; that text is then written back without it)
    wait_for(lambda: field.input_value() == "5e-1", what="the typed text, written back without the line break")
    runs = view.teaching.services.runs  # the label shows first in "Computing ..., T = 0.5 s…": wait for the run
    wait_for(lambda: (r := runs.of(view.session).run) is not None and r.duration == 0.5, what="the run of T = 0.5 s")
    wait_for(lambda: "of 0.500 s" in page.locator("body").inner_text(), what="T = 0.5 s in the summary")

    far = tmp_path / "far.csv"
    far.write_text("t,p1,p2\n0,0,0\n0.1,0.1,0\n0.2,0.4,0\n0.3,0.1,0\n")  # 400 mm: out of reach
    page.set_input_files(f'[id="file_upload_{widget_uuid(player.upload)}"]', str(far))
    assert not _toast_seen(page, 2.0)
    page.get_by_text("Refused: the trajectory far.csv").first.wait_for(timeout=10_000)
    refusal = page.get_by_text("Refused: the trajectory far.csv").first.bounding_box()
    button = page.get_by_role("button", name="Upload CSV (t, p1, p2 in s, m)").bounding_box()
    assert 0 <= refusal["y"] - (button["y"] + button["height"]) < 40  # right under the upload button

    t = np.linspace(0.0, 1.0, 21)
    wave = tmp_path / "wave.csv"
    wave.write_text("t,p1,p2\n" + "".join(f"{a:.3f},{0.05 * np.sin(np.pi * a):.6f},0\n" for a in t))
    time.sleep(PAUSE)
    page.set_input_files(f'[id="file_upload_{widget_uuid(player.upload)}"]', str(wave))
    page.get_by_text("wave.csv, T = 1 s").first.wait_for(timeout=10_000)
    wait_for(lambda: page.get_by_text("Refused: the trajectory far.csv").count() == 0, what="the refusal cleared")
    assert errors == []
