"""The report's path plot has axes (issue 40, item 8): p1 and p2 in mm with ticks and numbers, one scale for both.

Read back from the SVG of the report: the numbers of the ticks are round values inside the plot, at least three per
axis, and the map from millimetres to the drawing's pixels that they define (fitted from the ticks alone) puts every
point of the run's path, in mm from the run itself, on the drawn polyline, and the start and end marks on its ends;
its scale is the same on both axes (the circle of Fig. 5 stays a circle)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.app.runs import Source, build_run
from tpm_viz.media.report import nice_ticks, report_html

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module", params=["circle", "line"])
def run(request):
    return build_run(Params.paper(), Source.paper(request.param), reference=None)


def _path_svg(run) -> ET.Element:
    page = report_html(run, "en")
    figure = page[page.index("<h2>The path</h2>") :]
    return ET.fromstring(figure[figure.index("<svg") : figure.index("</svg>") + 6])


def _fit(ticks: list[ET.Element], attr: str) -> tuple[float, float]:
    """``(offset, px per mm)`` of the ticks' positions against their numbers (least squares)."""
    mm = np.array([float(t.get("data-mm")) for t in ticks])
    px = np.array([float(t.get(attr)) for t in ticks])
    assert np.allclose(mm, [float(t.text) for t in ticks])  # the shown number is the tick's value
    slope, offset = np.polyfit(mm, px, 1)
    assert np.allclose(offset + slope * mm, px, atol=0.01)  # evenly mapped
    return float(offset), float(slope)


def test_the_axes_carry_the_path_in_mm(run) -> None:
    svg = _path_svg(run)
    texts = svg.findall(f"{SVG}text")
    xs = [t for t in texts if t.get("data-axis") == "x"]
    ys = [t for t in texts if t.get("data-axis") == "y"]
    assert len(xs) >= 3 and len(ys) >= 3
    assert any(t.text == "p1 (mm)" for t in texts) and any(t.text == "p2 (mm)" for t in texts)
    ox, kx = _fit(xs, "x")
    oy, ky = _fit(ys, "y")
    oy -= 4.0  # the numbers of the y axis sit 4 px under their tick (centred on it)
    assert kx > 0 and ky < 0 and kx == pytest.approx(-ky, rel=1e-9)  # y up, one scale
    drawn = np.array([[float(v) for v in pt.split(",")] for pt in svg.find(f"{SVG}polyline").get("points").split()])
    path_mm = run.p * 1e3
    expected = np.stack([ox + kx * path_mm[:, 0], oy + ky * path_mm[:, 1]], axis=1)
    np.testing.assert_allclose(drawn, expected, atol=0.01)
    start = svg.find(f"{SVG}circle")
    assert (float(start.get("cx")), float(start.get("cy"))) == pytest.approx(tuple(expected[0]), abs=0.01)
    frame = svg.find(f"{SVG}rect")
    left, top = float(frame.get("x")), float(frame.get("y"))
    right, bottom = left + float(frame.get("width")), top + float(frame.get("height"))
    assert np.all((drawn[:, 0] > left) & (drawn[:, 0] < right) & (drawn[:, 1] > top) & (drawn[:, 1] < bottom))


@pytest.mark.parametrize(
    ("lo", "hi", "want"),
    [
        (-56.0, 56.0, [-40, -20, 0, 20, 40]),
        (0.0, 1.0, [0, 0.2, 0.4, 0.6, 0.8, 1.0]),
        (93.0, 207.0, [100, 120, 140, 160, 180, 200]),
    ],
)
def test_nice_ticks(lo: float, hi: float, want: list[float]) -> None:
    got = nice_ticks(lo, hi)
    assert got == pytest.approx(want)
    assert all(lo <= v <= hi for v in got)
    assert all(re.fullmatch(r"-?\d+(\.\d)?", f"{v:g}") for v in got)
