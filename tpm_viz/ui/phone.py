"""The drag handle on a touch screen: a handle a finger can hold, and a drag gain for fine moves.

On a phone the mechanism, framed whole in a 390 CSS px wide canvas, is about 2-3 mm per CSS px, and viser's
transform gizmo, sized in metres (:data:`~.tabscene.GIZMO_SCALE`), is a square of about 8 px to hold: a 30 px finger
move was 100 mm. A tab whose browser says it is a phone or a tablet (:func:`is_touch`: its user agent or its
``Sec-CH-UA-Mobile`` client hint) gets

- a handle of constant screen size (viser's ``fixed`` gizmo, :data:`TOUCH_GIZMO_PX` CSS px; the arrows are left out,
  the square that drags in the floor's plane is the handle: :data:`TOUCH_SQUARE` of it, at least 44 CSS px across
  seen from the default viewing direction, WCAG 2.2 target size AAA);
- a drag gain (:func:`drag_gain`): the platform moves ``gain`` times the finger's way on the floor, at most
  :data:`MM_PER_PX` mm per CSS px of the canvas (the finger's square runs ahead; it goes back under the platform
  when the drag ends).

The canvas size the page reports is its drawing buffer (CSS px times the device pixel ratio, which viser caps at 2), so
the metres per reported pixel are at most those per CSS px: the gain computed from them is at most the one that
gives :data:`MM_PER_PX` per CSS px (at a pixel ratio of 2, half of it).

:data:`TOUCH_CSS` keeps viser's "Software WebGL rendering detected" notice (a computer without a GPU, e.g. headless
Chromium) to a one-line strip of its title at the canvas's top edge, clear of the mechanism and the handle.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.markup import Html
from tpm_viz.viserkit.page import NOTICE_CSS

__all__ = ["MM_PER_PX", "TOUCH_CSS", "TOUCH_GIZMO_PX", "TOUCH_SQUARE", "drag_gain", "is_touch"]

TOUCH_GIZMO_PX = 400.0
"""Size of a touch tab's handle [CSS px] (viser's ``fixed`` gizmo: its arrows' length)."""
TOUCH_SQUARE = 0.225
"""Side of the gizmo's plane square as a fraction of its size (drei's ``PivotControls``, which viser draws)."""
MM_PER_PX = 1.0
"""Most platform travel [mm] per CSS px of a finger's drag on a touch tab."""
_MOBILE = re.compile(r"Mobi|Android|iPhone|iPad|iPod", re.IGNORECASE)

TOUCH_CSS = Html(f"<style>{NOTICE_CSS}</style>")
"""viser's software-WebGL notice as a one-line strip at the canvas's top-left corner in a touch tab, whatever its width
(the page script does the same in every window at most 36em wide or with a coarse pointer)."""


def is_touch(request: tuple[Any, Any] | None) -> bool:
    """Whether a tab's websocket handshake (``(address, headers)``, :func:`~tpm_viz.viserkit.core.connection_request`)
    comes from a phone or a tablet: its ``User-Agent`` or its ``Sec-CH-UA-Mobile: ?1`` client hint."""
    if request is None or request[1] is None:
        return False
    headers = request[1]
    agent = str(headers.get("User-Agent", ""))[:500]
    return bool(_MOBILE.search(agent)) or str(headers.get("Sec-CH-UA-Mobile", "")).strip() == "?1"


def drag_gain(camera_position: ArrayLike, target: ArrayLike, fov: float, height_px: float) -> float:
    """The gain (0, 1] that moves the platform at ``target`` [m] at most :data:`MM_PER_PX` mm per pixel of a drag,
    seen from ``camera_position`` [m] with a vertical field of view ``fov`` [rad] on a canvas ``height_px`` tall.

    A pixel spans ``2 r tan(fov / 2) / height`` across the line of sight at distance ``r``, and ``1 / |cos|`` times
    that along the floor in the picture's vertical (the floor seen at a slant, ``cos`` the line of sight's z part)."""
    offset = np.asarray(target, dtype=float) - np.asarray(camera_position, dtype=float)
    distance = float(np.linalg.norm(offset))
    if not (math.isfinite(distance) and distance > 0 and 0 < fov < math.pi and height_px > 0):
        return 1.0
    slant = max(abs(float(offset[2])) / distance, 0.1)  # a grazing view: 10x at most
    metres_per_px = 2.0 * distance * math.tan(fov / 2.0) / float(height_px) / slant
    return float(min(1.0, MM_PER_PX * 1e-3 / metres_per_px))
