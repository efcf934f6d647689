"""The palette's colours that must be told apart are far apart (issue 40, item 8): leg 2 and the stroke end's pink
(leg 2's purple, lit in 3D, came out lilac next to the pink), the other assembly mode P′ and the blue square of
viser's drag handle (both were blue), and every pair of the guide's legend. Distances are CIELAB ΔE*ab (CIE 1976),
computed here from the sRGB definition (IEC 61966-2-1, D65); 25 is far more than a just noticeable difference
(about 2.3), and more than what separates two named hues of a chart."""

from __future__ import annotations

import itertools
import math

import pytest

from tpm_viz.classroom.text import LEGEND
from tpm_viz.drawing.palette import PALETTE, hex_colour
from tpm_viz.ui.panels import GUIDE_COLOURS

HANDLE_BLUE = (54, 142, 226)
"""The square of viser's transform gizmo (drei's PivotControls), as Chromium draws it (read from a screenshot)."""
APART = 25.0


def lab(rgb: tuple[int, int, int]) -> tuple[float, float, float]:
    """CIELAB of an sRGB colour (0-255), D65 white."""
    lin = [c / 255 / 12.92 if c / 255 <= 0.04045 else ((c / 255 + 0.055) / 1.055) ** 2.4 for c in rgb]
    x = 0.4124 * lin[0] + 0.3576 * lin[1] + 0.1805 * lin[2]
    y = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    z = 0.0193 * lin[0] + 0.1192 * lin[1] + 0.9505 * lin[2]

    def f(t: float) -> float:
        return t ** (1 / 3) if t > (6 / 29) ** 3 else t / (3 * (6 / 29) ** 2) + 4 / 29

    fx, fy, fz = f(x / 0.95047), f(y / 1.0), f(z / 1.08883)
    return 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)


def delta_e(a: tuple[int, int, int], b: tuple[int, int, int]) -> float:
    return math.dist(lab(a), lab(b))


def test_the_conversion_on_known_values() -> None:
    assert lab((255, 255, 255)) == pytest.approx((100.0, 0.0, 0.0), abs=0.05)
    assert lab((255, 0, 0)) == pytest.approx((53.24, 80.09, 67.20), abs=0.05)  # sRGB red, a published value


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("leg2", "stroke"),
        ("leg1", "leg2"),
        ("leg2", "circle"),
        ("leg2", "inverse"),
        ("leg1", "inverse"),
        ("circle", "direct"),
        ("circle", "inverse"),
        ("stroke", "direct"),
    ],
)
def test_colours_that_must_be_told_apart_are(a: str, b: str) -> None:
    assert delta_e(PALETTE[a], PALETTE[b]) >= APART, (a, b, delta_e(PALETTE[a], PALETTE[b]))


def test_the_other_assembly_mode_is_not_the_handles_blue() -> None:
    assert delta_e(PALETTE["circle"], HANDLE_BLUE) >= APART


def test_the_guides_legend_is_the_palette_and_its_colours_are_apart() -> None:
    keys = {"workspace": "workspace", "inverse singularity": "inverse", "direct singularity": "direct"}
    keys |= {"stroke end": "stroke", "other assembly mode P′": "circle"}
    assert {name: colour for colour, name in GUIDE_COLOURS} == {n: hex_colour(k) for n, k in keys.items()}
    for (_, x), (_, y) in itertools.combinations(keys.items(), 2):
        assert delta_e(PALETTE[x], PALETTE[y]) >= APART, (x, y)


def test_the_move_tabs_legend_is_the_palette_too() -> None:
    """The longer legend under the Move tab: the same colours (it still showed P′ in the old blue)."""
    keys = ("workspace", "inverse", "direct", "stroke", "circle")
    assert [colour for colour, _text in LEGEND[: len(keys)]] == [hex_colour(k) for k in keys]
