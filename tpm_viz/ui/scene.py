"""The 3D drawing of one mechanism: scene handles built once, then only moved and recoloured.

:class:`MechanismScene` adds every node under its ``root`` when it is created and re-adds geometry only in
:meth:`rebuild` (a parameter change). :meth:`update` assigns poses and props, and only those that changed since the
last call, so a drag sends a handful of small messages. Sliders and the platform are frames: their pins, labels,
constraint circles and force arrows are children and follow without messages of their own.

The shared mechanism is drawn ONCE, in viser's broadcast scope (``server.scene``, root ``/tpm``): a commit costs
one set of messages whatever the number of tabs. A private copy is drawn in its tab's own scope (``client.scene``,
root ``/own``). What one tab sees of them (its gizmo, its view options) is :mod:`.tabscene`.
"""

from __future__ import annotations

import numpy as np
import viser

from tpm_viz.app.overlays import arrow_length, arrow_vector
from tpm_viz.app.readouts import Readout
from tpm_viz.app.state import AppState
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.params import Params
from tpm_viz.drawing import meshes
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.ui.widgets.scene_shapes import circle, floor, made, part

__all__ = [
    "ARROW_SHORTEST",
    "COLORS",
    "FAMILIES",
    "GIZMO_Z",
    "LABEL_SCALE",
    "LINE_SCALE",
    "MechanismScene",
    "camera_pose",
    "line_width",
]

COLORS = PALETTE
"""RGB colours of the parts, the warning colours and the force arrows (:mod:`tpm_viz.drawing.palette`)."""

ARROW_SHORTEST = 1e-3
"""[m] A force arrow shorter than this is hidden. Lengths: :func:`tpm_viz.app.overlays.arrow_length` (linear for small
forces, bounded: every arrow stays near the mechanism however large the force near a singularity)."""
ARROW_Z = meshes.PIN_Z[1] + 0.02  # m, above every part so that no part hides an arrow
GIZMO_Z = meshes.PLATFORM_Z[1] + 0.02  # m
FAMILIES = ("labels", "loci", "circles", "forces")
"""The families of nodes a viewer may hide (*Class & view* tab); ``region`` (the workspace floor) is hidden while
the explorer shows a map."""
CIRCLE_WIDTH = 2.0  # screen px
LOCUS_WIDTH = 2.5  # screen px
LINE_SCALE = 2.0
"""Presentation mode: the lines (loci, leg circles) are this many times thicker."""
LABEL_SCALE = 1.6
"""Presentation mode: the 3D labels are this many times larger."""


def _mesh(scene: viser.SceneApi, name: str, mesh, color, **kwargs):
    return scene.add_mesh_simple(
        name,
        mesh.vertices,
        mesh.faces,
        color=color,
        flat_shading=True,
        cast_shadow=False,
        receive_shadow=False,
        **kwargs,
    )


class MechanismScene:
    """Scene nodes of one mechanism under ``root`` in one scene API (``server.scene`` or a ``client.scene``).

    ``sink`` (the server or the client) groups each :meth:`update` into one atomic message window, sent at once
    if ``flush`` (a private copy is flushed with the rest of its tab, right after)."""

    def __init__(
        self, scene: viser.SceneApi, params: Params, root: str = "/tpm", sink=None, flush: bool = True
    ) -> None:
        self._scene = scene
        self.root = root
        self._sink = sink
        self._flush = flush
        self._sent: dict[str, object] = {}
        self._drawn: Snapshot | None = None  # the snapshot last drawn (a frame is drawn once, whoever asks)
        self.params: Params | None = None
        self.show = dict.fromkeys((*FAMILIES, "region"), True)
        self.presentation = False  # thicker lines and larger labels (a tab's private copy: :meth:`set_style`)
        self.slider_bodies: list = [None, None]
        self.circles: list = [None, None]
        self.loci: list = []
        self.region = None  # the workspace floor (one of the loci), None if the stroke holds no pose
        r = root
        self.root_node = scene.add_frame(r, show_axes=False)
        add_frame = scene.add_frame
        self.sliders = [add_frame(f"{r}/slider{i + 1}", show_axes=False) for i in range(2)]
        self.platform = add_frame(f"{r}/platform", show_axes=False)
        self.ghost = add_frame(f"{r}/ghost", show_axes=False)
        self.labels = [scene.add_label(f"{r}/label_O", "O", position=(0.02, -0.012, 0.002), anchor="top-left")]
        for i in range(2):
            self.labels.append(scene.add_label(f"{r}/slider{i + 1}/label", f"A{'₁₂'[i]}", anchor="bottom-right"))
            self.labels.append(scene.add_label(f"{r}/platform/label_B{i + 1}", f"B{'₁₂'[i]}", anchor="bottom-right"))
        self.label_p = scene.add_label(f"{r}/platform/label_P", "P", anchor="bottom-left")
        self.labels.append(self.label_p)
        # symbols only: the scene is drawn once for every tab, whatever its language (the legend says what P′ is)
        self.ghost_label = scene.add_label(f"{r}/ghost/label", "P′", anchor="center-center")
        self.labels.append(self.ghost_label)
        self.forces = [
            scene.add_arrows(
                f"{r}/slider{i + 1}/force",
                np.zeros((1, 2, 3)),
                COLORS["tau_pos"],
                shaft_radius=0.007,
                head_radius=0.018,
                head_length=0.035,
                visible=False,
            )
            for i in range(2)
        ]
        self.load_arrow = scene.add_arrows(
            f"{r}/platform/load",
            np.zeros((1, 2, 3)),
            COLORS["load"],
            shaft_radius=0.004,
            head_radius=0.011,
            head_length=0.022,
            visible=False,
        )
        self.rebuild(params)

    def family(self, what: str) -> list[str]:
        """Names of the nodes of a view family (:data:`FAMILIES` or ``region``): what a viewer hides."""
        r = self.root
        names = {
            "labels": [f"{r}/label_O", f"{r}/platform/label_P", f"{r}/ghost/label"]
            + [f"{r}/slider{i}/label" for i in (1, 2)]
            + [f"{r}/platform/label_B{i}" for i in (1, 2)],
            "loci": [f"{r}/loci/{kind}" for kind in ("workspace", "inverse", "direct")],
            "circles": [f"{r}/slider1/circle", f"{r}/slider2/circle", f"{r}/ghost"],
            "forces": [f"{r}/slider1/force", f"{r}/slider2/force", f"{r}/platform/load"],
            "region": [f"{r}/loci/workspace"],
        }
        return names[what]

    def remove(self) -> None:
        """Remove every node of this drawing (a private copy that its tab leaves)."""
        self.root_node.remove()

    def rebuild(self, params: Params) -> None:
        """(Re)add every node whose geometry depends on the parameters."""
        s, r = self._scene, self.root
        self.params = params
        self._sent.clear()
        lo, hi = meshes.base_extent(params)
        _mesh(s, f"{r}/base", made(meshes.base_plate, params), COLORS["base"])
        size = hi - lo
        s.add_grid(
            f"{r}/grid",
            size,
            size,
            plane="xy",
            cell_size=0.02,
            section_size=0.1,
            cell_color=(203, 213, 225),
            section_color=(148, 163, 184),
            position=((lo + hi) / 2, (lo + hi) / 2, 0.0005),
            shadow_opacity=0.0,
        )
        for i in range(2):
            _mesh(s, f"{r}/rail{i + 1}", made(meshes.rail, params, i), COLORS["rail"])
            _mesh(s, f"{r}/stops{i + 1}", made(meshes.end_stops, params, i), COLORS["stop"])
            body = made(meshes.slider, params, i)
            self.slider_bodies[i] = _mesh(s, f"{r}/slider{i + 1}/body", body, COLORS["slider"])
            offsets = meshes.slider_pin_offsets(params, i)
            self._pins(f"{r}/slider{i + 1}/pins", offsets)
            centre = np.zeros(3)
            centre[i] = params.b  # C_i = A_i + b e_i
            self.circles[i] = s.add_line_segments(
                f"{r}/slider{i + 1}/circle",
                circle(params.l_a) + centre,
                COLORS["circle"],
                thickness=CIRCLE_WIDTH * self._line_scale,
                thickness_units="screen",
                visible=self.show["circles"],
            )
            self.labels[1 + 2 * i].position = (0.0, 0.0, meshes.SLIDER_Z[1])
            b_label = meshes.platform_pin_offsets(params)[2 * i] + (0.0, 0.0, meshes.PLATFORM_Z[1])
            self.labels[2 + 2 * i].position = tuple(b_label)
        link = made(meshes.link, params)
        self.links = s.add_batched_meshes_simple(
            f"{r}/links",
            link.vertices,
            link.faces,
            batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (4, 1)),
            batched_positions=np.zeros((4, 3)),
            batched_colors=self._leg_colors((False, False)),
            flat_shading=True,
            cast_shadow=False,
            receive_shadow=False,
        )
        self.platform_body = _mesh(s, f"{r}/platform/body", made(meshes.platform, params), COLORS["platform"])
        _mesh(s, f"{r}/platform/marker", part(meshes.tool_marker), COLORS["marker"])
        self._pins(f"{r}/platform/pins", meshes.platform_pin_offsets(params))
        self.label_p.position = (0.0, 0.0, meshes.PLATFORM_Z[1] + 0.01)
        _mesh(s, f"{r}/ghost/body", made(meshes.platform, params), COLORS["circle"], opacity=0.22)
        self.ghost_label.position = (0.0, 0.0, meshes.PLATFORM_Z[1])
        self._loci(params)

    def _pins(self, name: str, offsets: np.ndarray) -> None:
        pin = part(meshes.pin)
        self._scene.add_batched_meshes_simple(
            name,
            pin.vertices,
            pin.faces,
            batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (len(offsets), 1)),
            batched_positions=offsets,
            batched_colors=COLORS["pin"],
            cast_shadow=False,
            receive_shadow=False,
        )

    def _loci(self, params: Params) -> None:
        """The floor overlay: the workspace inside the stroke (eq. 4), the inverse singularity square (eq. 11)
        and the direct singularity arcs (eq. 12), all in the working mode."""
        s, r = self._scene, self.root
        region, lines = floor(params)
        self.loci = []
        self.region = None
        if region is not None:
            self.region = _mesh(s, f"{r}/loci/workspace", region, COLORS["workspace"], opacity=0.45, side="double")
            self.loci.append(self.region)
        for kind, segments in lines.items():
            self.loci.append(
                s.add_line_segments(
                    f"{r}/loci/{kind}",
                    segments,
                    COLORS[f"locus_{kind}"],
                    thickness=LOCUS_WIDTH * self._line_scale,
                    thickness_units="screen",
                )
            )
        for handle in self.loci:
            handle.visible = self._locus_visible(handle)

    def _locus_visible(self, handle) -> bool:
        return self.show["loci"] and (handle is not self.region or self.show["region"])

    @staticmethod
    def _leg_colors(near_inverse) -> np.ndarray:
        legs = [COLORS["inverse"] if near_inverse[i] else COLORS[f"leg{i + 1}"] for i in range(2)]
        return np.array([legs[0], legs[0], legs[1], legs[1]], dtype=np.uint8)

    @property
    def _line_scale(self) -> float:
        return LINE_SCALE if self.presentation else 1.0

    def styled(self) -> list:
        """The nodes drawn thicker or larger in presentation mode: the singularity loci, the leg circles, the
        labels."""
        lines = [h for h in self.loci if h is not self.region]
        return [*lines, *self.circles, *self.labels]

    def set_style(self, presentation: bool) -> None:
        """Presentation mode for this drawing (a tab's private copy; the shared drawing is styled per tab by
        :mod:`.tabscene`): thicker lines, larger labels."""
        self.presentation = bool(presentation)
        for handle in self.styled():
            if isinstance(handle, viser.LabelHandle):
                handle.font_screen_scale = LABEL_SCALE if presentation else 1.0
            else:
                handle.thickness = line_width(handle) * self._line_scale

    def _set(self, key: str, handle, attr: str, value) -> None:
        """Assign ``handle.attr = value`` unless that exact value was the last one sent."""
        last = self._sent.get(key)
        if last is not None and np.array_equal(np.asarray(last), np.asarray(value)):
            return
        try:
            setattr(handle, attr, value)
        except RuntimeError as exc:  # viser 1.1.1 wakes its sender with asyncio.Event.set() from this thread, which
            if "mutated during iteration" not in str(exc):  # races the event loop; the message is queued already
                raise
        self._sent[key] = value

    def forget(self) -> None:
        """Send every pose again at the next :meth:`update`."""
        self._sent.clear()
        self._drawn = None

    def set_visible(self, what: str, visible: bool) -> None:
        """Show or hide a family of nodes (:data:`FAMILIES`, or ``region``: the workspace floor) of this drawing."""
        self.show[what] = bool(visible)
        if what == "labels":
            for label in self.labels:
                label.visible = visible
        elif what in ("loci", "region"):
            for locus in self.loci:
                if locus.visible != self._locus_visible(locus):
                    locus.visible = self._locus_visible(locus)
        elif what == "circles":
            for circle in self.circles:
                circle.visible = visible
        for key in [k for k in self._sent if k.endswith("_vis") or k.startswith("force_vis")]:
            del self._sent[key]  # re-evaluated at the next update
        self._drawn = None

    def update(self, frame: Snapshot) -> None:
        """Move every part to the frame's pose and recolour it from its alerts (nothing if ``frame`` is drawn)."""
        if frame is self._drawn:
            return
        if self._sink is None:
            self._update(frame)
        else:
            with self._sink.atomic():
                self._update(frame)
            if self._flush:
                self._sink.flush()
        self._drawn = frame

    def _update(self, frame: Snapshot) -> None:
        state, readout = frame.state, frame.readout
        params = state.params
        if params != self.params:
            self.rebuild(params)
        mp = frame.mechanism
        for i in range(2):
            a = np.array([mp.A[i, 0], mp.A[i, 1], 0.0])
            self._set(f"slider{i}", self.sliders[i], "position", a)
            color = COLORS["stroke"] if readout.stroke_end[i] else COLORS["slider"]
            self._set(f"slider_color{i}", self.slider_bodies[i], "color", color)
        p3 = np.array([readout.p[0], readout.p[1], 0.0])
        self._set("platform", self.platform, "position", p3)
        self._set(
            "platform_color",
            self.platform_body,
            "color",
            COLORS["direct"] if readout.near_direct else COLORS["platform"],
        )
        positions, wxyzs = frame.links
        self._set("links_pos", self.links, "batched_positions", positions)
        self._set("links_rot", self.links, "batched_wxyzs", wxyzs)
        self._set("links_color", self.links, "batched_colors", self._leg_colors(readout.near_inverse))
        ghost_visible = self.show["circles"] and readout.other_p is not None
        if readout.other_p is not None:
            self._set("ghost", self.ghost, "position", np.array([readout.other_p[0], readout.other_p[1], 0.0]))
        self._set("ghost_vis", self.ghost, "visible", ghost_visible)
        self._update_forces(state, readout)

    def _update_forces(self, state: AppState, readout: Readout) -> None:
        tau = readout.forces.tau
        params = state.params
        for i in range(2):
            value = 0.0 if tau is None else float(tau[i])
            length = float(arrow_length(value, params)) * float(np.sign(value))
            visible = self.show["forces"] and tau is not None and abs(length) > ARROW_SHORTEST
            self._set(f"force_vis{i}", self.forces[i], "visible", visible)
            if not visible:
                continue
            tip = np.zeros(3)
            tip[i] = length
            pts = np.array([[[0.0, 0.0, ARROW_Z], [tip[0], tip[1], ARROW_Z]]], dtype=np.float32)
            self._set(f"force{i}", self.forces[i], "points", pts)
            color = np.array([COLORS["tau_pos"] if value >= 0 else COLORS["tau_neg"]], dtype=np.uint8)
            self._set(f"force_color{i}", self.forces[i], "colors", color)
        f = np.array(state.load.f_ext) if state.load.mode == "static" else np.zeros(2)
        vec = arrow_vector(f, params)
        visible = self.show["forces"] and float(np.hypot(vec[0], vec[1])) > ARROW_SHORTEST
        self._set("load_vis", self.load_arrow, "visible", visible)
        if visible:
            z = meshes.PLATFORM_Z[1] + 0.006
            pts = np.array([[[0.0, 0.0, z], [vec[0], vec[1], z]]], dtype=np.float32)
            self._set("load", self.load_arrow, "points", pts)


def line_width(handle) -> float:
    """The normal width [screen px] of a line node: a singularity locus or a leg circle."""
    return LOCUS_WIDTH if handle.name.rsplit("/", 2)[-2] == "loci" else CIRCLE_WIDTH


def camera_pose(params: Params) -> tuple[np.ndarray, np.ndarray]:
    """Camera position and look-at point [m] that frame the base plate from the front, above."""
    lo, hi = meshes.base_extent(params)
    size = hi - lo
    centre = np.array([(lo + hi) / 2, (lo + hi) / 2, 0.0])
    look_at = centre + np.array([0.2, -0.1, 0.0]) * size
    return look_at + np.array([0.0, -0.36, 0.7]) * size, look_at
