"""The teaching layer end to end in headless Chromium: choose the circle in the Player tab, play it, see the
platform move and the charts' time marker advance in the page (uPlot's own data, read through viser's test
point), upload a CSV, download the run. All GUI inputs share a 50 ms throttle in viser's client: we pause."""

from __future__ import annotations

import time

import numpy as np
import pytest

from tests.support.browser import WORKER_LOG_JS
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

PAUSE = 0.08  # s, longer than the client's 50 ms input throttle

MARKER_JS = """
(uuid) => {
  const tp = (window.__viserTestpoints || {}).uplots || {};
  const entry = tp[uuid];
  if (!entry) return null;
  const data = entry.chart.data;
  const marker = Array.from(data[data.length - 1]);
  return {n: data[0].length, k: marker.indexOf(1), tmax: data[0][data[0].length - 1]};
}
"""

PLATFORM_MOVES_JS = """
() => (window.__viserLog || []).filter(m => m.dir === "in" && m.type === "SetPositionMessage"
                                           && m.name === "/tpm/platform").length
"""


def _text(page, name: str) -> str:
    return page.locator(f"[data-q={name}]").first.inner_text()


def _pick(page, handle, option: str) -> None:
    page.locator(f'[id="{widget_uuid(handle)}"]').click()
    page.get_by_role("option", name=option, exact=True).click()
    time.sleep(PAUSE)


def test_play_a_trajectory_and_watch_the_platform_and_the_charts(app, browser, tmp_path):
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.add_init_script(WORKER_LOG_JS)
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_function("() => (window.__viserLog || []).some(m => m.type === 'ReplayDoneMessage')", timeout=20_000)
    page.wait_for_selector("[data-q=p1]", timeout=20_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    player = view.teaching.player

    open_tab(page, "Player")
    _pick(page, player.choice, "circle (Fig. 5)")
    page.get_by_text("circle (Fig. 5), T = 0.5 s").first.wait_for(timeout=10_000)
    wait_for(lambda: _text(page, "p1") == "100.0", what="the platform at the circle's start")
    forces = widget_uuid(player.charts.forces)
    wait_for(lambda: (page.evaluate(MARKER_JS, forces) or {}).get("k") == 0, what="the chart in the page")
    chart = page.evaluate(MARKER_JS, forces)
    n, last = chart["n"], chart["n"] - 1
    assert chart == {"n": len(player.charts.forces.data[0]), "k": 0, "tmax": 0.5} and n > 100

    _pick(page, player.speed, "0.2×")  # 0.5 s of motion in 2.5 s
    moves_before = page.evaluate(PLATFORM_MOVES_JS)
    page.get_by_role("button", name="Play", exact=True).click()
    # Mid-way: the platform has left the start in the page, the chart's marker has moved on.
    wait_for(lambda: _text(page, "p1") not in ("100.0", "99.9"), timeout=5, what="the platform to move")
    wait_for(lambda: 0 < page.evaluate(MARKER_JS, forces)["k"] < last, timeout=5, what="the marker to advance")
    assert page.evaluate(PLATFORM_MOVES_JS) > moves_before + 3
    # The end: one full turn, the marker on the last sample, the trace drawn.
    wait_for(lambda: page.evaluate(MARKER_JS, forces)["k"] == last, timeout=8, what="the end of the circle")
    wait_for(lambda: _text(page, "player-t") == "0.500", what="t = T in the summary")
    assert _text(page, "p1") == "100.0" and _text(page, "p2") in ("0.0", "-0.0")
    assert page.evaluate("() => (window.__viserLog||[]).some(m => m.name === '/player/trace')")
    for chart in player.charts.kinematics:
        assert page.evaluate(MARKER_JS, widget_uuid(chart))["k"] == last

    # A user's CSV, through the real file input of the upload button.
    t = np.linspace(0.0, 1.0, 21)
    rows = "".join(f"{a:.3f},{0.05 * np.sin(np.pi * a):.6f},{0.03 * np.sin(2 * np.pi * a):.6f}\n" for a in t)
    path = tmp_path / "wave.csv"
    path.write_text("t,p1,p2\n" + rows)
    page.set_input_files(f'[id="file_upload_{widget_uuid(player.upload)}"]', str(path))
    page.get_by_text("wave.csv, T = 1 s").first.wait_for(timeout=10_000)
    wait_for(lambda: _text(page, "p1") == "0.0", what="the platform at the CSV's start")

    # Download the run as CSV from the browser.
    with page.expect_download(timeout=10_000) as info:
        page.get_by_role("button", name="Download the run (CSV)").click()
    text = open(info.value.path(), encoding="utf-8").read()
    assert info.value.suggested_filename == "tpm-run-csv-T1s.csv"
    assert text.startswith("t,p1,p2,dp1,dp2,ddp1,ddp2,d1,d2,") and text.count("\n") == 402

    body = page.locator("body").inner_text().lower()
    assert "nan" not in body.split() and "inf" not in body.split()
    assert errors == []
    page.close()
