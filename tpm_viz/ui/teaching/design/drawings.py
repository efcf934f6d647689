"""Still 3D drawings of either 2-PPa arrangement for the *Design* view: the paper's perpendicular mechanism and the
parallel one (``docs/parallel.md``), each beside the other with the task rectangle it must cover.

:func:`tpm_viz.drawing.meshes.posed_parts` places every part of either mechanism at a platform position ``p`` [m],
where :class:`~tpm_viz.ui.scene.MechanismScene` puts the live one's (sliders at ``A_i``, links by
:func:`tpm_viz.drawing.meshes.link_instances`, the platform at ``P``). :class:`ArrangementDrawing`
draws one such mechanism in a tab's own scene under its own root, moved by ``offset`` (the Design view's area, away from
the live mechanism), with the task rectangle as lines at the tool's height; it keeps the joints it drew (``joints``).
"""

from __future__ import annotations

import functools
from typing import cast

import numpy as np
import trimesh

from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.design.indices import Task
from tpm_viz.drawing import meshes
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["TASK_COLOUR", "TASK_Z", "ArrangementDrawing", "drawn_pose", "extent", "task_segments"]

TASK_Z = meshes.PLATFORM_Z[1] + 0.004
"""Height [m] of the task rectangle's lines: at the tool's height, over the platform (which would hide it)."""
TASK_COLOUR = (219, 39, 119)
COLOURS = {
    "base": PALETTE["base"],
    "rails": PALETTE["rail"],
    "stops": PALETTE["stop"],
    "sliders": PALETTE["slider"],
    "leg1": PALETTE["leg1"],
    "leg2": PALETTE["leg2"],
    "platform": PALETTE["platform"],
    "pins": PALETTE["pin"],
    "tool": PALETTE["marker"],
}
"""Colour of each group of parts (the live mechanism's palette)."""
GROUPS = {
    "base": ("base",),
    "rails": ("rail1", "rail2"),
    "stops": ("stops1", "stops2"),
    "sliders": ("slider1", "slider2"),
    "leg1": ("link1_0", "link1_1"),
    "leg2": ("link2_0", "link2_1"),
    "platform": ("platform",),
    "pins": ("pins",),
    "tool": ("tool",),
}
"""The parts of :func:`tpm_viz.drawing.meshes.posed_parts` drawn as one mesh per colour."""


@functools.lru_cache(maxsize=16)
def _grouped(arrangement: Arrangement, params: Params, p: tuple[float, float]) -> dict[str, trimesh.Trimesh]:
    parts = meshes.posed_parts(arrangement, params, np.asarray(p))
    return {
        group: cast(trimesh.Trimesh, trimesh.util.concatenate([parts[name] for name in names]))
        for group, names in GROUPS.items()
    }


def drawn_pose(arrangement: Arrangement, params: Params, task: Task | None) -> np.ndarray:
    """Where the platform is drawn [m]: the task's centre if the mechanism reaches it inside the stroke, else the
    arrangement's home pose."""
    if task is not None:
        centre = task.centre
        try:
            d = arr.inverse_kinematics(arrangement, params, centre)
            if bool(np.all(np.isfinite(d))) and bool(arr.in_stroke(arrangement, params, d)):
                return centre
        except TpmVizError:
            pass
    return np.asarray(arr.home(arrangement, params), dtype=float)


def extent(arrangement: Arrangement, params: Params) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper XY corners [m] of the arrangement's base plate."""
    if Arrangement.parse(arrangement) is Arrangement.PARALLEL:
        return meshes.parallel.base_extent(params)
    lo, hi = meshes.base_extent(params)
    return np.array([lo, lo]), np.array([hi, hi])


def task_segments(task: Task, z: float = TASK_Z) -> np.ndarray:
    """The task rectangle's four sides as line segments ``(4, 2, 3)`` [m]."""
    corners = np.array(
        [[task.x0, task.y0], [task.x1, task.y0], [task.x1, task.y1], [task.x0, task.y1]], dtype=np.float32
    )
    segs = np.zeros((4, 2, 3), dtype=np.float32)
    segs[:, 0, :2], segs[:, 1, :2] = corners, np.roll(corners, -1, axis=0)
    segs[..., 2] = z
    return segs


class ArrangementDrawing:
    """One still mechanism of ``arrangement`` in ``scene`` under ``root``, its world origin moved to ``offset`` [m]
    (XY): the mechanism at :func:`drawn_pose`, the task rectangle and a label (symbols and the arrangement's
    name, written by the caller)."""

    def __init__(self, scene, root: str, arrangement: Arrangement, offset=(0.0, 0.0)) -> None:
        self.scene = scene
        self.root = root
        self.arrangement = Arrangement.parse(arrangement)
        self.offset = np.array([float(offset[0]), float(offset[1]), 0.0])
        self.node = scene.add_frame(root, show_axes=False, position=tuple(self.offset), visible=True)
        self.params: Params | None = None
        self.task: Task | None = None
        self.p = np.zeros(2)
        self.joints: tuple[np.ndarray, np.ndarray] = (np.zeros((2, 3)), np.zeros((2, 3)))
        """The slider joints ``A_i`` and platform joints ``B_i`` drawn, world coordinates [m], rows ``i``."""
        self.label = None
        self._drawn: tuple | None = None
        self._handles: list = []

    def draw(self, params: Params, task: Task | None, label: str = "") -> None:
        """Draw the mechanism with ``params`` at :func:`drawn_pose` and the task rectangle (nothing is sent again
        when nothing changed)."""
        key = (params, task, label)
        if key == self._drawn:
            return
        p = drawn_pose(self.arrangement, params, task)
        pose = arr.mechanism_pose(self.arrangement, params, p)
        groups = _grouped(self.arrangement, params, (float(p[0]), float(p[1])))
        r = self.root
        self._handles = [
            self.scene.add_mesh_simple(
                f"{r}/{name}",
                mesh.vertices,
                mesh.faces,
                color=COLOURS[name],
                flat_shading=True,
                cast_shadow=False,
                receive_shadow=False,
            )
            for name, mesh in groups.items()
        ]
        if task is not None:
            self._handles.append(
                self.scene.add_line_segments(
                    f"{r}/task", task_segments(task), TASK_COLOUR, thickness=3.0, thickness_units="screen"
                )
            )
        lo, _hi = extent(self.arrangement, params)
        self.label = self.scene.add_label(f"{r}/label", label, position=(float(lo[0]), float(lo[1]), 0.002))
        z = np.zeros((2, 1))
        self.joints = (np.hstack([pose.A, z]) + self.offset, np.hstack([pose.B, z]) + self.offset)
        self.params, self.task, self.p = params, task, p
        self._drawn = key

    def move(self, offset) -> None:
        """Move the drawing's origin to ``offset`` [m] (XY, in its parent's frame): the joints move with it."""
        new = np.array([float(offset[0]), float(offset[1]), 0.0])
        if np.array_equal(new, self.offset):
            return
        shift = new - self.offset
        self.offset = new
        self.node.position = tuple(new)
        self.joints = (self.joints[0] + shift, self.joints[1] + shift)

    def set_visible(self, visible: bool) -> None:
        """Show or hide the whole drawing."""
        if self.node.visible != visible:
            self.node.visible = visible

    def remove(self) -> None:
        """Remove every node of the drawing."""
        self.node.remove()
        self._drawn = None
