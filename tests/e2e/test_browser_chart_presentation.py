"""The player's charts in presentation mode, as Chromium draws them on a 1024×768 projector (issue 13, "readable
everywhere"): tick labels and axis titles large and dark, none of them cut, in English and in Korean, and back to
uPlot's usual 12 px grey when presentation mode is turned off.

uPlot draws its axes on a canvas, so what is measured is what the page's uPlot instances are configured with (viser's
test point): the font size of the tick labels and of the axis titles (uPlot keeps ``[font, size in device px]``),
the colour of the axis text (its ``stroke``), and, with the page's own text measurement in those fonts, everything
:func:`tests.e2e.test_browser_charts._check_chart` checks (labels apart and inside the canvas, y labels within
the y axis, the rotated y title within the plot in both languages). The screenshots (English and Korean, the
Player tab) are kept in a temporary folder named in the test's output; they were looked at when this was written.
"""

from __future__ import annotations

import os
import tempfile

import pytest

from tests.e2e.test_browser_charts import _check_chart, open_with_a_run
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, open_tab
from tpm_viz.core.words import Lang, catalogue
from tpm_viz.ui.teaching.player.charts import FORCES, KINEMATICS
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

LEAST_PX = 16.0
"""Smallest font of a tick label or an axis title in presentation mode [CSS px] (read from the back of a room)."""
LEAST_CONTRAST = 15.0
"""Least contrast ratio of the axis text on the chart's white in presentation mode (WCAG 2: AAA asks 7; the usual
grey, viser's gray[7], has about 8)."""

FONTS_JS = """
(uuid) => {
  const entry = ((window.__viserTestpoints || {}).uplots || {})[uuid];
  if (!entry) return null;
  const u = entry.chart;
  const ratio = window.devicePixelRatio || 1;
  return u.axes.map((a, i) => ({
    tick: a.font[1] / ratio, title: a.labelFont[1] / ratio,
    stroke: typeof a.stroke === "function" ? a.stroke(u, i) : a.stroke,
  }));
}
"""

SCROLL_JS = """(uuid) => window.__viserTestpoints.uplots[uuid].chart.root.scrollIntoView({block: "start"})"""


def _contrast(colour: str) -> float:
    """WCAG 2 contrast ratio of a CSS colour ``#rrggbb`` or ``rgb(r, g, b)`` on white (1 to 21)."""
    colour = colour.strip()
    if colour.startswith("#"):
        rgb = [int(colour[k : k + 2], 16) / 255 for k in (1, 3, 5)]
    else:
        rgb = [float(v) / 255 for v in colour[colour.index("(") + 1 : colour.index(")")].split(",")[:3]]
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb]
    return 1.05 / (0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2] + 0.05)


def _fonts(page, charts, least: float | None, most: float | None) -> list[dict]:
    """The fonts of every axis of the four charts, once the page draws them in the size asked for."""

    def drawn():
        out = []
        for handle in charts.handles:
            axes = page.evaluate(FONTS_JS, widget_uuid(handle))
            if not axes or any(least is not None and a["tick"] < least for a in axes):
                return None
            if any(most is not None and a["tick"] > most for a in axes):
                return None
            out.extend(axes)
        return out

    return wait_for(drawn, what=f"the charts' axes drawn between {least} and {most} px")


def _check_all(page, charts, where: str) -> None:
    """Every chart whole as the page draws it (:func:`tests.e2e.test_browser_charts._check_chart`)."""
    y_labels = [FORCES[1], *(label for _attr, _title, label, _scale in KINEMATICS)]
    for k, (handle, y_label) in enumerate(zip(charts.handles, y_labels, strict=True)):
        _check_chart(handle, page, y_label, f"{where}, chart {k}")


def _unfold(page) -> None:
    """Presentation mode folds the panel to its rail: one click on the rail brings it back."""
    rail = page.locator('[aria-label^="Expand"]')
    wait_for(lambda: rail.count() > 0, what="the panel folded to its rail")
    rail.first.click()
    wait_for(lambda: rail.count() == 0, what="the panel back")


def test_presentation_mode_draws_the_chart_axes_large_and_dark_and_whole(app, browser):
    shots = tempfile.mkdtemp(prefix="tpm-viz-chart-presentation-")
    print(f"screenshots in {shots}")
    page, errors, view = open_with_a_run(app, browser)
    charts = view.teaching.player.charts

    normal = _fonts(page, charts, None, 13.0)  # before: uPlot's 12 px in viser's grey
    assert {a["tick"] for a in normal} == {12.0} and {a["title"] for a in normal} == {12.0}
    assert max(_contrast(a["stroke"]) for a in normal) < LEAST_CONTRAST  # grey

    open_tab(page, "Class & view")
    page.locator(f'[id="{widget_uuid(view.panel.presentation)}"]').click()
    wait_for(lambda: view.look.presentation, what="presentation mode on the server")
    _unfold(page)
    open_tab(page, "Player")
    for lang in (Lang.EN, Lang.KO):
        if lang is Lang.KO:
            page.locator(f'[id="{widget_uuid(view.words.selector)}"]').click()
            page.get_by_role("option", name=Lang.KO.label, exact=True).click()
            wait_for(lambda: view.lang is Lang.KO, what="the tab in Korean")
        large = _fonts(page, charts, LEAST_PX, None)
        assert min(a["tick"] for a in large) >= LEAST_PX and min(a["title"] for a in large) >= LEAST_PX
        assert min(_contrast(a["stroke"]) for a in large) >= LEAST_CONTRAST  # near-black
        _check_all(page, charts, f"presentation mode, {lang.value}")
        for name, handle in (("forces", charts.forces), ("accelerations", charts.kinematics[-1])):
            page.evaluate(SCROLL_JS, widget_uuid(handle))
            page.screenshot(path=os.path.join(shots, f"1024x768-{lang.value}-presentation-{name}.png"))

    ko = catalogue(Lang.KO)  # Korean names now
    open_tab(page, ko["Class & view"], group=ko[GROUP_OF["Class & view"]])
    page.locator(f'[id="{widget_uuid(view.panel.presentation)}"]').click()
    wait_for(lambda: not view.look.presentation, what="presentation mode off on the server")
    back = _fonts(page, charts, None, 13.0)
    assert {a["tick"] for a in back} == {12.0} and [a["stroke"] for a in back] == [a["stroke"] for a in normal]
    assert not errors
