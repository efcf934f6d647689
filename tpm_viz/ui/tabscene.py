"""What one browser tab sees of the mechanism: its gizmo, its view options, and which drawing it shows.

The shared mechanism is one :class:`~.scene.MechanismScene` in viser's broadcast scope, drawn once per commit for
every tab. A tab changes what *it* sees with viser's scope shadowing (viser 1.1.1: a client-scoped node with the
name of a broadcast node replaces it for that one client, and the broadcast node comes back when the client's node
is removed):

- a view option turned off (labels, loci, circles, forces) or the workspace floor under an explorer map: an
  invisible client-scoped frame over each node of that family (its broadcast children are hidden with it);
- a private copy: an invisible client-scoped frame over the whole shared root, and the copy drawn under ``/own``
  in the tab's own scope, where the view options are plain visibility flags;
- presentation mode (:mod:`.look`): a client-scoped copy of each shared line (loci, leg circles) and label, thicker
  and larger (:func:`styled_copy`), drawn again when the shared drawing is rebuilt; a private copy is restyled in
  place (:meth:`~.scene.MechanismScene.set_style`).

The gizmo is always the tab's own (each student drags their own handle); it is written back to the platform's pose
when this tab is not the one dragging. On a phone or a tablet (:meth:`TabScene.set_touch`) it is a handle of constant
screen size a finger can hold, and a drag moves the platform by a gain (:mod:`.phone`): at most 1 mm per CSS px.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import viser

from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.params import Params
from tpm_viz.ui.phone import TOUCH_CSS, TOUCH_GIZMO_PX, drag_gain
from tpm_viz.ui.scene import FAMILIES, GIZMO_Z, LABEL_SCALE, LINE_SCALE, MechanismScene, line_width
from tpm_viz.viserkit.core import drop_gizmo_echo

__all__ = ["GIZMO_SCALE", "PRIVATE_ROOT", "TabScene"]

GIZMO_SCALE = 0.16
"""Size of the gizmo [m] with a mouse (its arrows' length in the scene)."""

PRIVATE_ROOT = "/own"
"""Where a tab draws its private copy (its own scope)."""


class TabScene:
    """The gizmo, view options and shadows of one tab; ``shared`` is the broadcast drawing of the shared mechanism."""

    def __init__(self, client: viser.ClientHandle, shared: MechanismScene) -> None:
        self._client = client
        self._api = client.scene
        self.shared = shared
        self.private: MechanismScene | None = None
        self.show = dict.fromkeys(FAMILIES, True)
        self.region_hidden = False
        self.presentation = False
        """True while the explorer shows a map on the floor (the workspace region would cover it)."""
        self._shadows: dict[str, viser.FrameHandle] = {}  # broadcast node name -> the invisible client frame over it
        self._cover: viser.FrameHandle | None = (
            None  # the invisible client frame over the shared root while the private copy is shown
        )
        self._styled: dict[str, Any] = {}  # broadcast node name -> this tab's styled copy (presentation mode)
        self._styled_for: Params | None = None  # the shared parameters those copies were drawn for
        self._gizmo_at: np.ndarray | None = None
        self.touch = False
        """A phone or a tablet: the handle of constant screen size and the drag gain (:meth:`set_touch`)."""
        self._placed = np.zeros(2)  # where the gizmo was last written [m]: where a drag starts from
        self._anchor: tuple[np.ndarray, np.ndarray, float] | None = (
            None  # a geared drag: (gizmo, platform) at start, gain
        )
        self.gizmo = self._api.add_transform_controls(
            "/gizmo",
            scale=GIZMO_SCALE,
            active_axes=(True, True, False),
            disable_rotations=True,
            depth_test=False,
            position=(0.0, 0.0, GIZMO_Z),
        )
        drop_gizmo_echo(self.gizmo)

    @property
    def mechanism(self) -> MechanismScene:
        """The drawing this tab shows: its private copy, or the shared mechanism."""
        return self.private if self.private is not None else self.shared

    def __getattr__(self, name: str):
        """The nodes of the drawing this tab shows (``platform``, ``sliders``, ``links``, ...)."""
        if name.startswith("_") or name in ("shared", "private"):
            raise AttributeError(name)
        return getattr(self.mechanism, name)

    # -- which drawing -------------------------------------------------------------------------------------
    def open_private(self, params: Params) -> MechanismScene:
        """Hide the shared mechanism in this tab and draw a private copy (returned: the new session's scene)."""
        self._set_shadows(set(), style=False)
        if self._cover is None:
            self._cover = self._api.add_frame(self.shared.root, show_axes=False, visible=False)
        if self.private is None:  # each update one atomic window of this tab (flushed by the tab's render)
            self.private = MechanismScene(self._api, params, root=PRIVATE_ROOT, sink=self._client, flush=False)
            if self.presentation:  # a new drawing is in the normal style, everything shown: only what differs
                self.private.set_style(True)
            for what in FAMILIES:
                if not self.show[what]:
                    self.private.set_visible(what, False)
            if self.region_hidden:
                self.private.set_visible("region", False)
        return self.private

    def close_private(self) -> None:
        """Remove the private copy: the shared mechanism (in its latest state) shows again."""
        if self.private is not None:
            self.private.remove()
            self.private = None
        if self._cover is not None:
            self._cover.remove()
            self._cover = None
        self._sync_shadows()

    # -- view options --------------------------------------------------------------------------------------
    def set_visible(self, what: str, visible: bool) -> None:
        """Show or hide a family of nodes (:data:`~.scene.FAMILIES`) in this tab only."""
        self.show[what] = bool(visible)
        if self.private is not None:
            self.private.set_visible(what, visible)
        else:
            self._sync_shadows()

    def set_region_hidden(self, hidden: bool) -> None:
        """Hide the workspace floor in this tab (the explorer draws a map there)."""
        if bool(hidden) == self.region_hidden:
            return
        self.region_hidden = bool(hidden)
        if self.private is not None:
            self.private.set_visible("region", not self.region_hidden)
        else:
            self._sync_shadows()

    def hidden(self) -> set[str]:
        """Names of the shared mechanism's nodes hidden in this tab (everything under the root for a private copy)."""
        if self._cover is not None:
            return {self.shared.root}
        return set(self._shadows)

    def _sync_shadows(self) -> None:
        wanted: set[str] = set()
        for what in FAMILIES:
            if not self.show[what]:
                wanted.update(self.shared.family(what))
        if self.region_hidden:
            wanted.update(self.shared.family("region"))
        self._set_shadows(wanted)

    def _set_shadows(self, wanted: set[str], style: bool = True) -> None:
        """Hide the shared nodes named in ``wanted``, and in presentation mode (and ``style``) draw this tab's styled
        copy of every other line and label (none while the private copy is shown)."""
        styled: dict[str, object] = {}
        if self.presentation and style and self._cover is None:
            styled = {h.name: h for h in self.shared.styled() if h.name not in wanted}
            if self._styled_for is not self.shared.params:  # the shared drawing was rebuilt: copy it again
                styled_now, self._styled = self._styled, {}
                for handle in styled_now.values():
                    handle.remove()
                self._styled_for = self.shared.params
        for name in [n for n in self._styled if n not in styled]:
            self._styled.pop(name).remove()
        for name in [n for n in self._shadows if n not in wanted]:
            self._shadows.pop(name).remove()
        for name in sorted(wanted - set(self._shadows)):
            self._shadows[name] = self._api.add_frame(name, show_axes=False, visible=False)
        for name in sorted(set(styled) - set(self._styled)):
            self._styled[name] = styled_copy(self._api, styled[name])

    def set_presentation(self, on: bool) -> None:
        """Presentation mode in this tab: thicker lines and larger labels (the shared drawing through this tab's own
        styled copies of its lines and labels, a private copy directly)."""
        self.presentation = bool(on)
        if self.private is not None:
            self.private.set_style(self.presentation)
        else:
            self._sync_shadows()

    # -- per frame -----------------------------------------------------------------------------------------
    def update(self, frame: Snapshot, dragging: bool = False) -> None:
        """Put the gizmo on the platform, unless this tab is dragging it (the browser moves it itself)."""
        if dragging:
            self._gizmo_at = None  # written again once the drag is over
            return
        if self.presentation and self.private is None and self._styled_for is not self.shared.params:
            self._sync_shadows()  # the shared drawing was rebuilt (new parameters): its styled copies too
        at = np.array([frame.readout.p[0], frame.readout.p[1], GIZMO_Z])
        if self._gizmo_at is None or not np.array_equal(at, self._gizmo_at):
            self.gizmo.position = at
            self._gizmo_at = at
            self._placed = at[:2].copy()

    def forget(self) -> None:
        """Write the gizmo (and a private copy) again at the next :meth:`update` (a refused drag goes back)."""
        self._gizmo_at = None
        self._anchor = None
        if self.private is not None:
            self.private.forget()

    # -- touch -----------------------------------------------------------------------------------------------
    def set_touch(self, on: bool) -> None:
        """A phone or a tablet (:func:`~.phone.is_touch`): the gizmo becomes a handle of :data:`~.phone.TOUCH_GIZMO_PX`
        CSS px (viser's ``fixed`` size; the square in the floor's plane only, no arrows), and drags are geared."""
        if bool(on) == self.touch:
            return
        self.touch = bool(on)
        gizmo = self.gizmo
        gizmo.fixed = self.touch
        gizmo.scale = TOUCH_GIZMO_PX if self.touch else GIZMO_SCALE
        gizmo.disable_axes = self.touch
        gizmo.line_width = 4.0 if self.touch else 2.5
        if self.touch:
            self._client.gui.add_html(str(TOUCH_CSS))

    def geared(self, phase: str, position: object, platform: object) -> object:
        """Where a drag event's gizmo ``position`` [m] moves the platform (at ``platform`` [m] now): on a touch tab the
        platform's start plus the gain times the gizmo's way since the drag started; elsewhere ``position`` itself.
        The gain is fixed when the drag starts (:func:`~.phone.drag_gain` at the tab's camera)."""
        if not self.touch:
            return position
        try:
            g = np.asarray(position, dtype=float).reshape(-1)[:2]
        except (TypeError, ValueError):
            return position  # refused downstream, in one line
        if g.shape != (2,) or not np.all(np.isfinite(g)):
            return position
        if self._anchor is None:
            start = np.asarray(platform, dtype=float).reshape(-1)[:2]
            self._anchor = (self._placed.copy(), start, self._gain(start))
        g0, p0, gain = self._anchor
        if phase == "end":
            self._anchor = None
        return p0 + gain * (g - g0)

    def _gain(self, at: np.ndarray) -> float:
        """The drag gain at the platform ``at`` [m] for this tab's camera (1 before the tab reported one)."""
        try:
            camera = self._client.camera
            position, fov, height = np.asarray(camera.position, dtype=float), float(camera.fov), camera.image_height
        except AssertionError:  # no camera message yet
            return 1.0
        return drag_gain(position, (float(at[0]), float(at[1]), GIZMO_Z), fov, float(height))


def styled_copy(scene: viser.SceneApi, handle: Any) -> Any:
    """A copy of a line or label node of the shared drawing in ``scene`` (a tab's own), under the same name, in the
    presentation style (:data:`~.scene.LINE_SCALE` times thicker, :data:`~.scene.LABEL_SCALE` times larger)."""
    common = {"position": handle.position, "wxyz": handle.wxyz, "visible": handle.visible}
    if isinstance(handle, viser.LabelHandle):
        return scene.add_label(handle.name, handle.text, anchor=handle.anchor, font_screen_scale=LABEL_SCALE, **common)
    return scene.add_line_segments(
        handle.name,
        handle.points,
        handle.colors,
        thickness=line_width(handle) * LINE_SCALE,
        thickness_units="screen",
        **common,
    )
