"""The one palette of tpm-viz: every named colour as RGB (0-255), and as CSS hex through :func:`hex_colour`.

The 3D scene, the panel's HTML, the charts and the floor maps take their colours from here, so that a leg, a
warning or a force has the same colour everywhere (teal leg 1, indigo leg 2, amber inverse singularity, red direct
singularity, pink stroke end, brown for the other assembly mode P′ and its circles, green/red positive/negative force).
Colours that must be told apart are far apart in CIELAB (``tests/drawing/test_palette.py``), also as the lit 3D view
shows them: leg 2 was a purple that the lights made lilac, next to the stroke end's pink, and P′ was the blue of
viser's drag handle.
"""

from __future__ import annotations

__all__ = ["PALETTE", "hex_colour"]

PALETTE: dict[str, tuple[int, int, int]] = {
    "base": (226, 232, 240),
    "rail": (148, 163, 184),
    "stop": (71, 85, 105),
    "slider": (51, 65, 85),
    "leg1": (13, 148, 136),
    "leg2": (67, 56, 202),
    "pin": (30, 41, 59),
    "platform": (100, 116, 139),
    "marker": (250, 204, 21),
    "inverse": (245, 158, 11),
    "direct": (220, 38, 38),
    "stroke": (219, 39, 119),
    "ok": (16, 185, 129),
    "tau_pos": (22, 163, 74),
    "tau_neg": (220, 38, 38),
    "tau1": (37, 99, 235),
    "tau2": (220, 38, 38),
    "load": (71, 85, 105),
    "circle": (146, 64, 14),
    "locus_direct": (220, 38, 38),
    "locus_inverse": (245, 158, 11),
    "workspace": (34, 197, 94),
}
"""RGB of the parts, the warning levels, the force arrows and chart series."""


def hex_colour(name: str) -> str:
    """``"#rrggbb"`` of a palette colour."""
    r, g, b = PALETTE[name]
    return f"#{r:02x}{g:02x}{b:02x}"
