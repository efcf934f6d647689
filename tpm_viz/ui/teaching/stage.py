"""Which run's drawing a tab shows on the floor, and the control lab's scene nodes.

The Player (the loaded trajectory's path and trace), the Control lab (reference and actual paths, the ghost) and
the Planner (the planned path, force bars) each draw in the tab's own scope. Drawn all at once they hide one another
(the Planner tab showed the control lab's ghost and an uploaded path over the planned one), so a tab shows one of
them: the one it used last (:func:`bring`: a run computed, loaded, played, scrubbed or its settings changed), kept
per view in a weak map (a closed tab's entry goes with it).
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np
import viser

from tpm_viz.core.params import Params
from tpm_viz.drawing import meshes
from tpm_viz.ui.teaching.player.trace import TRACE_Z, segments

__all__ = ["CONTROL", "PLAN", "PLAYER", "ControlNodes", "bring", "front"]

PLAYER, CONTROL, PLAN = "player", "control", "plan"
GHOST_COLOUR = (34, 197, 94)
REF_COLOUR, ACTUAL_COLOUR = (34, 197, 94), (220, 38, 38)

_FRONT: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()


def bring(view: Any, what: str, redraw: bool = False) -> None:
    """``what`` (:data:`PLAYER`, :data:`CONTROL` or :data:`PLAN`) is the run ``view`` shows from now on.
    ``redraw``: draw the tab's teaching layer again at once if that changed (a user event; not from a render)."""
    if _FRONT.get(view) == what:
        return
    _FRONT[view] = what
    if redraw:
        with view.hub.locked():
            frame = getattr(view.session, "frame", None)
            if frame is not None and not view.closed:
                view.teaching.render(frame)
                view.client.flush()


def front(view: Any, default: str | None = None) -> str | None:
    """The run ``view`` shows (``default`` before any)."""
    return _FRONT.get(view, default)


def show(handle: Any, visible: bool) -> None:
    """Set a node's visibility, sending nothing when it is already so."""
    if handle is not None and bool(handle.visible) != visible:
        handle.visible = visible


class ControlNodes:
    """The control lab's nodes in one tab's scene: reference path (green), actual path (red), the ghost platform
    that follows the reference (translucent green)."""

    def __init__(self, scene: viser.SceneApi) -> None:
        self._scene = scene
        self.ghost: viser.BoxHandle | None = None
        self.paths: dict[str, viser.LineSegmentsHandle] = {}

    def draw(self, params: Params, reference: np.ndarray, actual: np.ndarray) -> None:
        """The two paths (``(n, 2)`` [m]) and a hidden ghost sized for ``params``."""
        for name, pts, colour in (("reference", reference, REF_COLOUR), ("actual", actual, ACTUAL_COLOUR)):
            z = TRACE_Z + (0.001 if name == "actual" else 0.0)
            self.paths[name] = self._scene.add_line_segments(
                f"/control/{name}", segments(pts, z, 400), colour, thickness=2.5, thickness_units="screen"
            )
        half = meshes.platform_half_size(params)
        thick = meshes.PLATFORM_Z[1] - meshes.PLATFORM_Z[0]
        self.ghost = self._scene.add_box(
            "/control/ghost",
            GHOST_COLOUR,
            (2 * half, 2 * half, thick),
            opacity=0.45,
            cast_shadow=False,
            receive_shadow=False,
            position=(0.0, 0.0, float(np.mean(meshes.PLATFORM_Z)) + 0.002),
            visible=False,
        )

    def hide(self) -> None:
        """Hide every node (a discarded run)."""
        for handle in (self.ghost, *self.paths.values()):
            show(handle, False)

    def place(self, in_front: bool, ghost_at: Any) -> None:
        """Paths shown while the control lab is in front; the ghost too, at ``ghost_at`` (x, y) [m] (None: hidden)."""
        for handle in self.paths.values():
            show(handle, in_front)
        ghost = self.ghost
        if ghost is None:
            return
        if not in_front or ghost_at is None:
            show(ghost, False)
            return
        ghost.position = (float(ghost_at[0]), float(ghost_at[1]), ghost.position[2])
        show(ghost, True)
