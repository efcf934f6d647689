"""The player's charts follow a tab's presentation mode
(:meth:`tpm_viz.ui.teaching.player.charts.Charts.set_presentation`), through viser's protocol: what the tab's uPlot
charts are sent, measured against DejaVu Sans (the widest of the usual sans fonts, shipped with matplotlib) with Pillow,
not with the module's own width estimate. The browser's drawing is checked in
``tests/e2e/test_browser_chart_presentation.py``.
"""

from __future__ import annotations

import re

import pytest
from matplotlib import font_manager
from PIL import ImageFont

from tests.support.protocol import wait_for
from tpm_viz.app.runs import Source
from tpm_viz.ui.teaching.player.charts import NARROWEST_PX

SIZE = 18  # [px] the presentation font asked for: at least 16 px on a projector
TICK, GAP = 10, 5  # [px] uPlot's tick length and the gap to its label, as the charts send them


def _font(bold: bool) -> ImageFont.FreeTypeFont:
    path = font_manager.findfont(font_manager.FontProperties(family="DejaVu Sans", weight="bold" if bold else "normal"))
    return ImageFont.truetype(path, SIZE)


def _px(font_text: str) -> float:
    """The size [px] in a CSS font such as ``bold 18px "Segoe UI", sans-serif``."""
    return float(re.search(r"(\d+(?:\.\d+)?)px", font_text).group(1))


def _large(view) -> bool:
    """Whether every axis of the tab's charts has been given a font (the large look)."""
    return all("font" in axis for h in view.teaching.player.charts.handles for axis in h.axes)


def _load(view, duration: float = 0.5) -> None:
    view.teaching.services.runs.load(view.session, Source.paper("circle", duration), origin=view)
    charts = view.teaching.player.charts
    wait_for(lambda: charts.forces.visible and charts.forces.data[0][-1] == duration, what="the run in the charts")


def test_presentation_mode_sends_large_dark_axes_with_room_for_them_and_takes_them_back(connect):
    client, view = connect()
    _other_client, other = connect()
    _load(view)
    charts = view.teaching.player.charts
    before = [(h.axes, h.height, h.padding) for h in charts.handles]
    assert all("font" not in axis for h in charts.handles for axis in h.axes)  # uPlot's own 12 px, viser's grey

    client.set_value(view.panel.presentation, True)
    wait_for(lambda: _large(view), what="the large axes sent")
    regular, bold = _font(False), _font(True)
    for handle in charts.handles:
        x, y = handle.axes
        for axis in (x, y):
            assert _px(axis["font"]) >= 16 and _px(axis["labelFont"]) >= 16 and axis["labelFont"].startswith("bold")
            colour = axis["stroke"].lstrip("#")
            assert max(int(colour[k : k + 2], 16) for k in (0, 2, 4)) < 64  # near-black on the white chart
            assert axis["labelSize"] >= bold.getbbox("Ty")[3]  # room for one line of the bold title
        # every y label within the y axis, past its tick and gap
        assert max(regular.getlength(v) for v in y["values"]) <= y["size"] - TICK - GAP
        # the time labels, one line, within the time axis
        assert TICK + GAP + regular.getbbox("0,5")[3] <= x["size"]
        # neighbouring time labels apart on the narrowest chart (a phone), at least a third of an em between them
        top, right = handle.padding[0], handle.padding[1]
        plot = NARROWEST_PX - right - y["labelSize"] - y["size"]
        lo, hi = handle.scales["x"]["range"]
        step_px = plot * (x["splits"][1] - x["splits"][0]) / (hi - lo)
        widths = [regular.getlength(v) for v in x["values"]]
        assert len(x["values"]) >= 3 and step_px - max(widths) >= SIZE / 3
        # the rotated y title no taller than the plot (English; Korean is measured in the browser test)
        assert bold.getlength(y["label"]) <= handle.height - top - x["size"]
    assert all("font" not in axis for h in other.teaching.player.charts.handles for axis in h.axes)  # this tab only

    _load(view, 2.0)  # a new run in presentation mode keeps the large axes
    assert all(_px(axis["font"]) >= 16 for h in charts.handles for axis in h.axes)

    client.set_value(view.panel.presentation, False)
    wait_for(lambda: not any("font" in a for h in charts.handles for a in h.axes), what="the usual axes sent")
    _load(view)
    assert [(h.axes, h.height, h.padding) for h in charts.handles] == before


@pytest.mark.parametrize("duration", [0.01, 0.0137, 100.0])
def test_large_axes_keep_three_time_ticks_for_any_run_length(connect, duration):
    client, view = connect()
    client.set_value(view.panel.presentation, True)
    wait_for(lambda: _large(view), what="the large axes sent")
    _load(view, duration)
    for handle in view.teaching.player.charts.handles:
        x = handle.axes[0]
        assert len(x["values"]) >= 3 and x["splits"][0] == 0.0 and x["splits"][-1] <= duration


def test_the_control_and_planner_charts_follow_presentation_mode_too(connect):
    """The *Control* and *Planner* tabs' time charts (ui/teaching/motion.py): large, near-black axes with room for
    the 18 px labels (the y title, rotated, within the plot in English and Korean, measured with DejaVu Sans), and
    exactly their usual axes, height and padding again when presentation mode is turned off."""
    client, view = connect()
    charts = (*view.teaching.control.charts, *view.teaching.planner.charts)
    assert len(charts) == 3
    before = [(c.handle.axes, c.handle.height, c.handle.padding) for c in charts]
    client.set_value(view.panel.presentation, True)
    grown = lambda: all(c.handle.height > b[1] for c, b in zip(charts, before, strict=True))  # noqa: E731 - set last
    wait_for(lambda: all("font" in a for c in charts for a in c.handle.axes) and grown(), what="the large axes sent")
    bold = _font(True)
    hangul = ImageFont.truetype(font_manager.findfont(font_manager.FontProperties(family="NanumGothic")), SIZE)
    for chart, (axes0, height0, _padding0) in zip(charts, before, strict=True):
        x, y = chart.handle.axes
        for axis in (x, y):
            assert _px(axis["font"]) >= 16 and axis["labelFont"].startswith("bold")
            colour = axis["stroke"].lstrip("#")
            assert max(int(colour[k : k + 2], 16) for k in (0, 2, 4)) < 64
            assert axis["labelSize"] >= bold.getbbox("Ty")[3]
            assert axis["ticks"]["size"] == TICK  # uPlot takes the ticks whole: without a size it draws no values
        assert TICK + GAP + _font(False).getbbox("0,5")[3] <= x["size"]
        assert y["size"] >= 1.5 * axes0[1]["size"]  # the value labels grow with the font
        room = chart.handle.height - chart.handle.padding[0] - x["size"]
        assert bold.getlength(y["label"]) <= room and chart.handle.height > height0
        assert hangul.getlength("힘 (N)") <= room  # the Korean title of the force charts
    client.set_value(view.panel.presentation, False)
    back = lambda: all(c.handle.height == b[1] for c, b in zip(charts, before, strict=True))  # noqa: E731 - set last
    wait_for(lambda: not any("font" in a for c in charts for a in c.handle.axes) and back(), what="the usual axes")
    assert [(c.handle.axes, c.handle.height, c.handle.padding) for c in charts] == before
