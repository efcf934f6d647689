"""The player's charts as Chromium draws them: time ticks for every run length, no axis text cut, no ``-0``.

uPlot draws its axes on a canvas, so their text is not in the DOM. What is measurable, and checked here for each of
the four charts, from the uPlot instance of the page (viser's test point) and the page's own text measurement
(``measureText`` with the axis fonts uPlot uses):

- the time axis has the ticks and labels the server decided (>= 3, uPlot's ``_splits`` / ``_values``), spanning
  the run, and neighbouring labels leave half an em between them, on a laptop (1024×768) and on two phones
  (390×844, 320×568);
- the first and last time labels and the time axis title fit inside the canvas;
- every y tick label fits the y axis' width; the rotated y axis title, in English and in Korean, is no taller
  than the plot it is centred on (the cut 'acceleration (mm/s' of issue 13);
- no label reads as a negative zero; each chart's DOM title (``.u-title``) is not wider than its box.

Not measured: how the glyphs look (the canvas pixels); the screenshots were looked at by hand when this was written.
"""

from __future__ import annotations

import re
import time

import pytest

from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.app.runs import Source
from tpm_viz.core.words import Lang, say
from tpm_viz.ui.teaching.player.charts import FORCES, KINEMATICS
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

PAUSE = 0.08  # s, longer than the client's 50 ms input throttle
LABEL_GAP = 6.0  # px: the least empty room between two time labels (half an em of the 12 px font)

MEASURE_JS = """
([uuid, extra]) => {
  const entry = ((window.__viserTestpoints || {}).uplots || {})[uuid];
  if (!entry) return null;
  const u = entry.chart;
  u.root.scrollIntoView({block: "nearest"});
  const ratio = window.devicePixelRatio || 1;
  const ctx = document.createElement("canvas").getContext("2d");
  const width = (font, text) => { ctx.font = font; return ctx.measureText(text).width / ratio; };
  const axes = u.axes.map(a => ({
    values: (a._values || []).map(String),
    splits: Array.from(a._splits || []),
    pos: Array.from(a._splits || []).map(s => u.valToPos(s, a.scale)),
    widths: (a._values || []).map(v => width(a.font[0], String(v))),
    label: a.label, labelWidth: width(a.labelFont[0], a.label || ""),
    extraWidths: extra.map(t => width(a.labelFont[0], t)),
    size: a._size, tick: a.ticks.size, gap: a.gap,
  }));
  const title = u.root.querySelector(".u-title");
  return {
    plot: {left: u.bbox.left / ratio, top: u.bbox.top / ratio, width: u.bbox.width / ratio,
           height: u.bbox.height / ratio},
    width: u.width, height: u.height, x: [u.scales.x.min, u.scales.x.max], axes,
    title: title ? {scroll: title.scrollWidth, client: title.clientWidth} : null,
  };
}
"""

_ZERO = re.compile(r"^[\u2212-][0.,]*(×10.*)?$")


def _labels_everywhere(y_label) -> list[str]:
    return [say(lang, y_label) for lang in Lang]


def _check_chart(handle, page, y_label, where: str) -> None:
    """Every claim of the module docstring for one chart, as the page has drawn it."""
    server_x = handle.axes[0]
    m = wait_for(
        lambda: (
            (r := page.evaluate(MEASURE_JS, [widget_uuid(handle), _labels_everywhere(y_label)]))
            and r["axes"][0]["values"] == list(server_x["values"])
            and r["x"] == list(handle.scales["x"]["range"])
            and r["plot"]["width"] > 0
            and r
        ),
        what=f"{where}: the chart drawn with the server's time axis",
    )
    x, y = m["axes"]
    plot = m["plot"]
    # The time axis: the server's ticks, at least 3, inside the run, labels apart and inside the canvas.
    assert len(x["values"]) >= 3 and len(x["values"]) == len(x["splits"])
    assert all(m["x"][0] - 1e-12 <= s <= m["x"][1] + 1e-12 for s in x["splits"]), where
    for k in range(len(x["pos"]) - 1):
        room = x["pos"][k + 1] - x["pos"][k] - (x["widths"][k] + x["widths"][k + 1]) / 2
        assert room >= LABEL_GAP, f"{where}: time labels {x['values'][k : k + 2]} {room:.1f} px apart"
    assert plot["left"] + x["pos"][0] - x["widths"][0] / 2 >= 0, where
    assert plot["left"] + x["pos"][-1] + x["widths"][-1] / 2 <= m["width"], f"{where}: last time label cut"
    assert x["labelWidth"] <= m["width"], where
    # The y axis: every tick label within the axis' width; its title within the plot's height, in every language.
    assert len(y["values"]) >= 2
    assert max(y["widths"]) <= y["size"] - y["tick"] - y["gap"], f"{where}: y labels {y['values']} wider than the axis"
    assert y["labelWidth"] <= plot["height"], f"{where}: y title {y['label']!r} taller than the plot"
    assert max(y["extraWidths"]) <= plot["height"], f"{where}: a translated y title taller than the plot"
    # No negative zero anywhere; the DOM title fits its box.
    for label in (*x["values"], *y["values"]):
        assert not _ZERO.match(label), f"{where}: {label!r}"
    assert m["title"] is None or m["title"]["scroll"] <= m["title"]["client"] + 1, where


def open_with_a_run(app, browser):
    """A 1024x768 page on ``app`` that loaded the circle of Fig. 5 (0.5 s) through the real UI: ``(page, the page's
    errors, the tab's view)``."""
    page = browser.new_page()
    page.set_viewport_size({"width": 1024, "height": 768})
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=30_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    charts = view.teaching.player.charts
    open_tab(page, "Player")
    page.locator(f'[id="{widget_uuid(view.teaching.player.choice)}"]').click()
    page.get_by_role("option", name="circle (Fig. 5)", exact=True).click()
    time.sleep(PAUSE)
    wait_for(lambda: charts.forces.visible and charts.forces.data[0][-1] == 0.5, what="the run")
    return page, errors, view


def test_chart_axes_are_whole_on_a_laptop_and_on_a_phone(app, browser):
    y_labels = [FORCES[1], *(label for _attr, _title, label, _scale in KINEMATICS)]
    page, errors, view = open_with_a_run(app, browser)
    player = view.teaching.player
    runs = app.services.runs
    for size in ({"width": 1024, "height": 768}, {"width": 390, "height": 844}, {"width": 320, "height": 568}):
        page.set_viewport_size(size)
        open_tab(page, "Player")
        for duration in (0.5, 0.01, 0.0137, 100.0):
            runs.load(view.session, Source.paper("circle", duration), origin=view)
            wait_for(lambda d=duration: player.charts.forces.data[0][-1] == d, what=f"the run of {duration} s")
            for k, (handle, y_label) in enumerate(zip(player.charts.handles, y_labels, strict=True)):
                _check_chart(handle, page, y_label, f"{size['width']} px, T = {duration} s, chart {k}")
    assert not errors
