"""The design map agrees with its legend (issue 40, item 4), read from headless Chromium's screenshots (software
WebGL) on a 1024×768 projector in presentation mode (the panel open), a 1366×768 laptop in English and a 390×844
touch phone in Korean.

The default map (7 × 7 designs, coloured by GCI) is computed in the page. Then, in one screenshot:

- each feasible cell's colour, read at its centre projected through the tab's camera (a pinhole written here), is
  the legend's colour at the cell's place on the scale, read from the legend's own bar in the panel (the browser's
  CSS gradient) at ``t = (GCI - worst) / (best - worst)``, GCI the library's value of that design: an RGB distance
  of at most :data:`WITHIN` (viser lit the cells: the worst row came out (177, 25, 198) for (68, 1, 84));
- the best design's ring is dark on its yellow cell (darker by more than 60 of 255), and the axis labels are
  outside the map, apart from every cell and ring (their anchors projected beyond the map's edges, on the side
  they extend to);
- the map is framed large: it spans at least half the canvas, across or up (whichever the canvas's shape limits);
- a click on a cell's centre picks that design (the image of the colours lets the clicks through to the cells).

Screenshots in a temporary folder named in the output.
"""

from __future__ import annotations

import io
import os
import tempfile

import numpy as np
import pytest
from PIL import Image

from tests.e2e.test_browser_layout import chromium  # noqa: F401  (fixture)
from tests.e2e.test_browser_phone import CANVAS, _project, _settled
from tests.e2e.test_browser_stage import _open, _presentation_on
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, STAGE, open_tab
from tpm_viz.core.words import Lang, shown
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.teaching.design.scene import AREA, LABEL_GAP, MAP_CORNER, MAP_SIDE, SWATCH_Z, map_cell_centres
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = [pytest.mark.browser, pytest.mark.slow]

WITHIN = 12.0
"""Largest RGB distance between a cell and the legend at its value (8-bit rounding, texture filtering)."""
LEGEND_BAR = """() => { const bar = document.querySelector('[data-q=design-legend] div[style*="linear-gradient"]');
  if (!bar) return null; bar.scrollIntoView({block: 'nearest'}); const r = bar.getBoundingClientRect();
  return [r.left, r.top, r.right, r.bottom]; }"""


@pytest.fixture
def served():
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


def _shot(page) -> np.ndarray:
    """The page as RGB [0-255], once two screenshots in a row agree."""
    last: list[np.ndarray] = []

    def steady():
        last.append(np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), dtype=float))
        return len(last) > 1 and np.array_equal(last[-1], last[-2])

    wait_for(steady, timeout=30.0, interval=0.2, what="a steady page")
    return last[-1]


def _at(image: np.ndarray, xy) -> np.ndarray:
    """The median colour of the 5 × 5 pixels around ``xy`` [CSS px; the screenshots are at 1 px per CSS px]."""
    x, y = round(float(xy[0])), round(float(xy[1]))
    return np.median(image[y - 2 : y + 3, x - 2 : x + 3].reshape(-1, 3), axis=0)


def _darkest(image: np.ndarray, xy) -> float:
    """The darkest pixel's mean of R, G, B among the 9 × 9 around ``xy`` [CSS px] (a thin line crosses there)."""
    x, y = round(float(xy[0])), round(float(xy[1]))
    return float(image[y - 4 : y + 5, x - 4 : x + 5].mean(axis=-1).min())


def _world(points) -> np.ndarray:
    """Area coordinates of the Design area [m] -> world coordinates."""
    out = np.array(points, dtype=float, ndmin=2)
    out[:, 0] += AREA[0]
    out[:, 1] += AREA[1]
    return out


@pytest.mark.parametrize(
    ("size", "locale", "lang", "presentation"),
    [
        ((1024, 768), "en-US", Lang.EN, True),
        ((1366, 768), "en-US", Lang.EN, False),
        ((390, 844), "ko-KR", Lang.KO, False),
    ],
    ids=["1024-presentation", "1366-en", "390-ko"],
)
def test_the_maps_cells_are_the_legends_colours_and_the_marks_stand_apart(
    served,
    chromium,  # noqa: F811
    size,
    locale,
    lang,
    presentation,
):
    shots = tempfile.mkdtemp(prefix="tpm-viz-design-map-")
    context, page, view = _open(served, chromium, size, locale=locale)
    try:
        page.get_by_role("button", name=shown(lang, "Got it"), exact=True).click()
        if presentation:  # the projector: presentation mode, the panel opened again to work in it
            _presentation_on(page, view)
            page.locator('[aria-label^="Expand"]').first.click()
            wait_for(lambda: page.evaluate(STAGE)["rows"], what="the panel back")
        open_tab(page, shown(lang, "Design"), shown(lang, GROUP_OF["Design"]))
        dv = view.teaching.design
        page.locator(f'[id="{widget_uuid(dv.compute)}"]').click()
        wait_for(lambda: dv.spec is not None and dv.done == dv.spec.size, timeout=180, what="the map computed")
        spec = dv.spec
        gci = np.array([r["gci"] if r is not None and r["feasible"] else np.nan for r in dv.rows])
        ok = np.isfinite(gci)
        assert ok.sum() >= 10, gci
        worst, best = float(np.nanmin(gci)), float(np.nanmax(gci))  # GCI: higher is better
        best_k = int(np.nanargmax(gci))

        page.wait_for_selector("[data-q=design-legend]")
        bar = page.evaluate(LEGEND_BAR)
        assert bar is not None
        rect = _settled(page, view)
        image = _shot(page)
        bar = page.evaluate(LEGEND_BAR)  # the page did not move since
        rect = page.evaluate(CANVAS)
        page.screenshot(path=os.path.join(shots, f"design-map-{lang.value}.png"))

        centres = _world(map_cell_centres(spec))
        centres[:, 2] = SWATCH_Z
        px = _project(view, centres, rect)
        worst_distance = 0.0
        for k in np.flatnonzero(ok):
            t = (gci[k] - worst) / (best - worst)
            legend = _at(image, (bar[0] + 2 + t * (bar[2] - bar[0] - 4), (bar[1] + bar[3]) / 2))
            cell = _at(image, px[k])
            distance = float(np.linalg.norm(cell - legend))
            worst_distance = max(worst_distance, distance)
            assert distance <= WITHIN, f"cell {k}: {cell} on the map, {legend} in the legend at t = {t:.3f}"
        print(f"{lang.value}: {int(ok.sum())} cells, largest distance to the legend {worst_distance:.1f}")

        w, h = MAP_SIDE / spec.x.count, MAP_SIDE / spec.y.count
        cx, cy = map_cell_centres(spec)[best_k, :2]
        ring = _project(view, _world([(cx, cy + 0.48 * h, SWATCH_Z), (cx - 0.48 * w, cy, SWATCH_Z)]), rect)
        inside = _at(image, px[best_k]).mean()  # the best cell: the legend's yellow end
        assert all(_darkest(image, xy) < inside - 60 for xy in ring), (inside, [_darkest(image, xy) for xy in ring])

        x0, y0 = MAP_CORNER
        edges = _project(view, _world([(x0, y0, 0.0), (x0, y0 + MAP_SIDE, 0.0)]), rect)
        labels = _project(view, _world([(x0, y0 - LABEL_GAP, 0.0), (x0, y0 + MAP_SIDE + LABEL_GAP, 0.0)]), rect)
        assert labels[0][1] >= edges[0][1] + 10, (labels, edges)  # the x label's top below the map's bottom edge
        assert labels[1][1] <= edges[1][1] - 10, (labels, edges)  # the y label's bottom above the map's top edge
        corners = _project(view, _world([(x, y, 0.0) for x in (x0, x0 + MAP_SIDE) for y in (y0, y0 + MAP_SIDE)]), rect)
        width, height = np.ptp(corners[:, 0]), np.ptp(corners[:, 1])
        share = max(width / (rect[2] - rect[0]), height / (rect[3] - rect[1]))
        assert share >= 0.5, (corners, rect)  # framed large: half the canvas or more, across or up

        k = int(np.flatnonzero(ok)[len(np.flatnonzero(ok)) // 2])
        page.mouse.click(float(px[k][0]), float(px[k][1]))
        wait_for(lambda: dv.picked == k, what=f"the design of cell {k} picked by a click")
        print(f"screenshots: {shots}")
    finally:
        context.close()
