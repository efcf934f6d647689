"""The polish of issue 40, item 8, as the page shows it in headless Chromium, at the stage tests' sizes: a 1024×768
projector in presentation mode (the panel open), a 1366×768 laptop, a 390×844 touch phone in Korean.

- The first visit's guide names the blue square (not "the arrows"), and its colour chips are the palette's (read from
  the page's computed styles).
- At a stroke end, leg 2 and the stroke end's pink are told apart as the lit 3D view draws them (pixels at the
  projected middle of a leg-2 link and on slider 1's top): CIELAB hue angles at least 45° apart and a distance ΔE*ab
  of at least 50 (the old purple, lit, was lilac (216, 160, 235): 34° and 44 from the pink (250, 81, 165); the
  indigo, lit, is (189, 177, 232): 52° and 60).
- The Move tab's fields show what the readout shows: one decimal of a millimetre.
- The Planner's "F_max, force limit (N)" never breaks inside F_max (the lines of the symbol's own text, measured
  with a DOM range, are one).
- One tab connected is "1 tab connected" (English), "탭 1개" (Korean).
Screenshots in a temporary folder named in the output.
"""

from __future__ import annotations

import io
import math
import os
import tempfile

import numpy as np
import pytest
import viser.transforms as tf
from PIL import Image

from tests.drawing.test_palette import lab
from tests.e2e.test_browser_layout import chromium  # noqa: F401  (fixture)
from tests.e2e.test_browser_phone import CANVAS, _project, _settled
from tests.e2e.test_browser_stage import _open, _presentation_on
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, STAGE, open_tab
from tpm_viz.core.words import Lang, shown
from tpm_viz.drawing import meshes
from tpm_viz.drawing.palette import hex_colour
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.panels import GUIDE_COLOURS, GUIDE_LINES

pytestmark = [pytest.mark.browser, pytest.mark.slow]

CASES = [
    ((1024, 768), "en-US", Lang.EN, True),
    ((1366, 768), "en-US", Lang.EN, False),
    ((390, 844), "ko-KR", Lang.KO, False),
]
CHIPS = """() => [...document.querySelectorAll('[data-guide] span > span:first-child')]
  .map(e => getComputedStyle(e).backgroundColor)"""
SYMBOL_LINES = """(symbol) => {  // the distinct line tops of "symbol" in each shown label holding it (viser puts a
  // <wbr> after every underscore and slash of a label: the symbol's text may be in several nodes)
  const lines = [];
  for (const label of document.querySelectorAll('label')) {
    const box = label.getBoundingClientRect();
    const at = label.textContent.indexOf(symbol);
    if (at < 0 || box.width < 20 || box.height < 5) continue;  // the typed field's own label: screen readers only
    const walk = document.createTreeWalker(label, NodeFilter.SHOW_TEXT);
    const range = document.createRange();
    let seen = 0;
    for (let n = walk.nextNode(); n; n = walk.nextNode()) {
      const len = n.nodeValue.length;
      if (seen <= at && at < seen + len) range.setStart(n, at - seen);
      if (seen < at + symbol.length && at + symbol.length <= seen + len) range.setEnd(n, at + symbol.length - seen);
      seen += len;
    }
    lines.push(new Set([...range.getClientRects()].filter(r => r.width > 0).map(r => Math.round(r.top))).size);
  }
  return lines; }"""


@pytest.fixture
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


def _rgb(css: str) -> str:
    r, g, b = (int(v) for v in css[css.index("(") + 1 : css.index(")")].split(",")[:3])
    return f"#{r:02x}{g:02x}{b:02x}"


def _hue(rgb) -> float:
    _l, a, b = lab(tuple(int(v) for v in rgb))
    return math.degrees(math.atan2(b, a)) % 360


def _pixel(image: np.ndarray, xy) -> np.ndarray:
    x, y = round(float(xy[0])), round(float(xy[1]))
    return np.median(image[y - 1 : y + 2, x - 1 : x + 2].reshape(-1, 3), axis=0)


@pytest.mark.parametrize(("size", "locale", "lang", "presentation"), CASES, ids=["1024-presentation", "1366", "390-ko"])
def test_the_polish_as_the_page_shows_it(served, chromium, size, locale, lang, presentation):  # noqa: F811
    shots = tempfile.mkdtemp(prefix="tpm-viz-polish-")
    context, page, view = _open(served, chromium, size, locale=locale)
    try:
        if presentation:
            _presentation_on(page, view)
            page.locator('[aria-label^="Expand"]').first.click()
            wait_for(lambda: page.evaluate(STAGE)["rows"], what="the panel back")
        open_tab(page, shown(lang, "Move"), shown(lang, GROUP_OF["Move"]))
        guide = page.locator("[data-guide]")
        guide.wait_for()
        assert shown(lang, GUIDE_LINES[0]) in " ".join(guide.inner_text().split())
        assert lang is not Lang.EN or "blue square" in guide.inner_text()
        assert [_rgb(c) for c in page.evaluate(CHIPS)] == [colour for colour, _name in GUIDE_COLOURS]
        assert GUIDE_COLOURS[-1][0] == hex_colour("circle")

        page.get_by_role("button", name=shown(lang, "At a stroke end"), exact=True).click()
        wait_for(lambda: view.session.state.pose.d[0] == 0.0, what="slider 1 at its stroke end")
        fields = [
            page.locator(f'textarea[aria-label="{shown(lang, k)}"]') for k in ("Platform p1 (mm)", "Platform p2 (mm)")
        ]
        readout = [page.locator(f"[data-q={q}]").first for q in ("p1", "p2")]

        def same() -> bool:
            shown_numbers = [r.inner_text().replace("(", "").replace(")", "").replace(",", "").strip() for r in readout]
            return [f.input_value() for f in fields] == shown_numbers

        wait_for(same, what="the Move fields as the readout")
        assert all(len(f.input_value().split(".")[-1]) == 1 for f in fields)

        if not presentation:  # the canvas is the free part of the window
            _settled(page, view)  # the camera framed for the canvas the page shows
            image = np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), dtype=float)
            page.screenshot(path=os.path.join(shots, f"stroke-end-{size[0]}.png"))
            params, frame = view.session.state.params, view.session.frame
            positions, wxyzs = frame.links
            link = np.asarray(positions[2]) + tf.SO3(np.asarray(wxyzs[2])).as_matrix() @ [params.l_a / 2, 0.0, 0.0]
            link[2] += 0.002  # its top
            a1 = np.array([frame.mechanism.A[0, 0], frame.mechanism.A[0, 1], meshes.SLIDER_Z[1]])
            on_slider = [a1 + np.array([dx, params.pivot_spacing / 2, 0.0]) for dx in (-0.02, -0.01, 0.01, 0.02)]
            px = _project(view, [link, *on_slider], page.evaluate(CANVAS))
            leg2 = _pixel(image, px[0])
            pink = max((_pixel(image, p) for p in px[1:]), key=lambda c: float(c[0] - c[1]))  # the pinkest
            gap = abs((_hue(leg2) - _hue(pink) + 180) % 360 - 180)
            print(f"{size}: leg 2 {leg2}, stroke end {pink}: hues {gap:.0f}° apart")
            distance = math.dist(lab(tuple(int(v) for v in leg2)), lab(tuple(int(v) for v in pink)))
            print(f"{size}: CIELAB distance {distance:.0f}")
            assert gap >= 45 and distance >= 50, (leg2, pink, gap, distance)

        open_tab(page, shown(lang, "Planner"), shown(lang, GROUP_OF["Planner"]))
        page.get_by_text("F_max", exact=False).first.wait_for()
        lines = page.evaluate(SYMBOL_LINES, "F_max")
        assert lines and all(n == 1 for n in lines), lines
        open_tab(page, shown(lang, "Class & view"), shown(lang, GROUP_OF["Class & view"]))
        line = page.locator("body")
        want = "1 tab connected, 1 on the shared mechanism." if lang is Lang.EN else "탭 1개 연결됨"
        wait_for(lambda: want in line.inner_text(), what="one tab, counted")
        page.screenshot(path=os.path.join(shots, f"class-line-{size[0]}.png"))
        print(f"screenshots: {shots}")
    finally:
        context.close()
