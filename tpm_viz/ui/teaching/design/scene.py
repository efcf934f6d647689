"""The Design area of one tab's scene: the heat map (a grid of coloured cells you click) and both arrangements
drawn beside it, each with its task rectangle.

Everything is in the tab's own scope under ``/design``, a frame at :data:`AREA` (in front of the live mechanism,
outside its camera framing), created the first time the *Design* tab draws and hidden by *Back to the mechanism*.
The map is one batched mesh of :data:`MAP_SIDE` square, one instance per design (column fastest, as
:class:`~.map.MapSpec` numbers them), so that viser's click event gives the design (``instance_index``). viser lights
every mesh (its materials are ``standard`` or ``toon``: the worst viridis row came out bright magenta, the rest
pastel), so the colours are an image laid over it (:func:`swatches`, unlit: the cells in the legend's colours, in
the floor's plane at any view), the lit mesh a little smaller beneath (it only takes the clicks). The axis labels
sit :data:`LABEL_GAP` outside the map, extending away from it (never over a cell or a ring), and
:meth:`DesignScene.look_map` frames the map large, seen from nearly straight above.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import numpy as np
import trimesh

from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.design.atlas import Row
from tpm_viz.design.indices import Task
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.ui.teaching.design.drawings import ArrangementDrawing, extent
from tpm_viz.ui.teaching.design.map import SWEPT, MapSpec, prototype_at
from tpm_viz.viserkit.core import point_camera

__all__ = [
    "AREA",
    "MAP_CORNER",
    "MAP_SIDE",
    "MARKS",
    "SWATCH_Z",
    "DesignScene",
    "comparison_designs",
    "map_cell_centres",
    "map_view",
    "swatches",
]

AREA = (0.0, -2.0)
"""World XY [m] of the Design area's origin."""
MAP_SIDE = 0.6
"""Side [m] of the heat map."""
MAP_CORNER = (-0.7, 0.0)
"""Lower-left corner [m] of the map in the area."""
MAP_Z = 0.002
SWATCH_Z = 0.006
"""Height [m] of the image of the cells' colours: over the lit cells (their top at 0.004 m), under the rings."""
MARK_Z = 0.008
SWATCH_PX = 20
"""Texels of one cell's side in that image (a gap of :data:`GAP_PX` on each side, the floor's colour)."""
GAP_PX = 1
FLOOR = (248, 250, 252)
LABEL_GAP = 0.05
"""Room [m] between the map's edge and an axis label's anchor (the label extends away from the map)."""
VIEW_TILT = math.radians(15.0)
"""How far from straight above :meth:`DesignScene.look_map` looks at the map."""
VIEW_MARGIN = 1.25
"""The framed map with its labels, and this much room around them."""
GAP = 0.12
"""Space [m] between the map and the drawings, and between the drawings."""
PENDING = (241, 245, 249)
"""A cell not computed yet."""
MARKS = {"best": (15, 23, 42), "picked": (37, 99, 235), "prototype": (220, 38, 38)}
"""The best design's ring (near black: the best cell is the yellow end of viridis), the picked one's, the cross."""


def map_cell_centres(spec: MapSpec) -> np.ndarray:
    """Centres ``(n, 3)`` [m, area coordinates] of the map's cells, design order (column fastest)."""
    w, h = MAP_SIDE / spec.x.count, MAP_SIDE / spec.y.count
    k = np.arange(spec.size)
    i, j = k % spec.x.count, k // spec.x.count
    return np.stack([MAP_CORNER[0] + (i + 0.5) * w, MAP_CORNER[1] + (j + 0.5) * h, np.full(len(k), MAP_Z)], -1)


def comparison_designs(
    compared: list[Row], case: str, params: Params, task: Task, loaded_parallel: Params | None, spec: MapSpec | None
) -> dict[Arrangement, tuple[Params | None, Task | None]]:
    """What each drawing shows: the compared rows of ``case`` (``given`` or ``optimum``) with their tasks, else the
    tab's mechanism ``params`` (a loaded parallel design for the parallel one) with ``task`` centred on the
    arrangement's home pose (the map's task for the map's arrangement); ``(None, None)``: nothing to draw."""
    out: dict[Arrangement, tuple[Params | None, Task | None]] = {}
    for kind in Arrangement:
        rows = [r for r in compared if r.get("arrangement") == kind.value and "a" in r]
        pick = [r for r in rows if r.get("case") == case] or rows
        if pick:
            row = pick[0]
            values = {k: float(row[k]) for k in ("a", "b", "l_a", "m_a", "m_b", "m_p", "stroke", "pivot_spacing")}
            out[kind] = (Params(**values), Task(*(float(row[f"task_{k}"]) for k in ("x0", "x1", "y0", "y1"))))
            continue
        mine = loaded_parallel if kind is Arrangement.PARALLEL and loaded_parallel is not None else params
        try:
            home = arr.home(kind, mine)
        except TpmVizError:
            out[kind] = (None, None)
            continue
        placed = task.centred_at(float(home[0]), float(home[1]))
        out[kind] = (mine, spec.task if spec is not None and spec.arrangement is kind else placed)
    return out


def map_view(fov: float, aspect: float) -> tuple[np.ndarray, np.ndarray]:
    """Camera ``(position, look_at)`` [m, world] that frames the map with its labels large in a canvas of vertical
    field of view ``fov`` [rad] and ``aspect`` (width / height), seen :data:`VIEW_TILT` from straight above."""
    cx, cy = AREA[0] + MAP_CORNER[0] + MAP_SIDE / 2, AREA[1] + MAP_CORNER[1] + MAP_SIDE / 2
    half = VIEW_MARGIN * (MAP_SIDE / 2 + LABEL_GAP + 0.03)  # the labels' height beyond the gap
    tan = math.tan(fov / 2) if 0.0 < fov < math.pi else math.tan(math.radians(37.5))
    distance = half / (tan * min(1.0, aspect if aspect > 0 else 1.0))
    look_at = np.array([cx, cy, 0.0])
    return look_at + distance * np.array([0.0, -math.sin(VIEW_TILT), math.cos(VIEW_TILT)]), look_at


def swatches(spec: MapSpec, cols: np.ndarray) -> np.ndarray:
    """The image ``(rows, columns, 3)`` uint8 of the map's colours ``cols`` ``(n, 3)`` (design order: column fastest,
    row 1 at the bottom): each cell a square of :data:`SWATCH_PX` texels with a gap of the floor's colour."""
    nx, ny, k = spec.x.count, spec.y.count, SWATCH_PX
    image = np.empty((ny * k, nx * k, 3), dtype=np.uint8)
    image[:] = FLOOR
    grid = np.asarray(cols, dtype=np.uint8).reshape(ny, nx, 3)  # viser lays the image's first row at its -y edge
    for j in range(ny):
        for i in range(nx):
            image[j * k + GAP_PX : (j + 1) * k - GAP_PX, i * k + GAP_PX : (i + 1) * k - GAP_PX] = grid[j, i]
    return image


def _square(cx: float, cy: float, w: float, h: float, z: float) -> np.ndarray:
    c = np.array(
        [[cx - w / 2, cy - h / 2], [cx + w / 2, cy - h / 2], [cx + w / 2, cy + h / 2], [cx - w / 2, cy + h / 2]]
    )
    segs = np.zeros((4, 2, 3), dtype=np.float32)
    segs[:, 0, :2], segs[:, 1, :2], segs[..., 2] = c, np.roll(c, -1, axis=0), z
    return segs


class DesignScene:
    """The Design area of one tab (``client``: its viser client handle)."""

    def __init__(self, client) -> None:
        self.client = client
        self.area = None
        self.cells = None
        self._cells_for: MapSpec | None = None
        self.drawings: dict[Arrangement, ArrangementDrawing] = {}
        self._drawn_for: tuple | None = None

    @property
    def shown(self) -> bool:
        return self.area is not None and bool(self.area.visible)

    def show(self) -> bool:
        """Create (the first time: True) or show the area."""
        first = self.area is None
        if self.area is None:
            scene = self.client.scene
            self.area = scene.add_frame("/design", show_axes=False, position=(*AREA, 0.0), visible=True)
            scene.add_frame("/design/map", show_axes=False)
        elif not self.area.visible:
            self.area.visible = True
        return first

    def hide(self) -> None:
        if self.area is not None and self.area.visible:
            self.area.visible = False

    def look_map(self) -> None:
        """Point the tab's camera at the map, framed large for its canvas (:func:`map_view`; shown)."""
        self.show()
        camera = self.client.camera
        try:
            fov, aspect = float(camera.fov), camera.image_width / max(camera.image_height, 1)
        except AssertionError:  # no camera message yet
            fov, aspect = math.radians(75.0), 1.0
        point_camera(camera, *map_view(fov, aspect))

    def look(self) -> None:
        """Point the tab's camera at the area (shown)."""
        self.show()
        centre = np.array([AREA[0] + 0.5, AREA[1] + 0.3, 0.0])
        self.client.camera.position = centre + np.array([0.0, -1.3, 1.6])  # first: viser moves look_at with it
        self.client.camera.look_at = centre

    def draw_map(
        self, spec: MapSpec, cols: np.ndarray, best: int | None, picked: int | None, on_click: Callable
    ) -> None:
        """The cells coloured ``cols`` ``(n, 3)``, the axis labels and the marks."""
        scene = self.client.scene
        if self._cells_for != spec or self.cells is None:
            w, h = MAP_SIDE / spec.x.count, MAP_SIDE / spec.y.count
            box = trimesh.creation.box(extents=(0.8 * w, 0.8 * h, 0.004))  # under its swatch: the clicks
            self.cells = cells = scene.add_batched_meshes_simple(
                "/design/map/cells",
                box.vertices,
                box.faces,
                batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (spec.size, 1)),
                batched_positions=map_cell_centres(spec),
                batched_colors=cols,
                lod="off",
                flat_shading=True,
                cast_shadow=False,
                receive_shadow=False,
            )
            cells.on_click(on_click)
            self._cells_for = spec
            x0, y0 = MAP_CORNER
            for axis, y, anchor, arrow in (
                ("x", y0 - LABEL_GAP, "top-left", "→"),
                ("y", y0 + MAP_SIDE + LABEL_GAP, "bottom-left", "↑"),
            ):
                a = spec.x if axis == "x" else spec.y
                text = f"{arrow} {SWEPT[a.name]} {a.start * 1e3:.0f}–{a.stop * 1e3:.0f} mm"
                scene.add_label(f"/design/map/{axis}", text, position=(x0, y, MAP_Z), anchor=anchor)
        else:
            self.cells.batched_colors = cols
        x0, y0 = MAP_CORNER
        scene.add_image(  # the colours, unlit (module docstring)
            "/design/map/swatches",
            swatches(spec, cols),
            MAP_SIDE,
            MAP_SIDE,
            format="png",
            position=(x0 + MAP_SIDE / 2, y0 + MAP_SIDE / 2, SWATCH_Z),
            cast_shadow=False,
            receive_shadow=False,
        )
        self._marks(spec, best, picked)

    def _marks(self, spec: MapSpec, best: int | None, picked: int | None) -> None:
        """Ring the best cell (near black) and the picked one (blue), cross the prototype (red)."""
        w, h = MAP_SIDE / spec.x.count, MAP_SIDE / spec.y.count
        centres = map_cell_centres(spec)
        segs, cols = [], []
        for kind, k in (("best", best), ("picked", picked)):
            if k is not None:
                segs.append(_square(centres[k, 0], centres[k, 1], 0.96 * w, 0.96 * h, MARK_Z))
                cols += [MARKS[kind]] * 4
        proto = prototype_at(spec)
        if proto is not None:
            cx, cy = MAP_CORNER[0] + (proto[0] + 0.5) * w, MAP_CORNER[1] + (proto[1] + 0.5) * h
            r, z = 0.3 * min(w, h), MARK_Z + 0.001
            segs.append(
                np.array([[[cx - r, cy - r, z], [cx + r, cy + r, z]], [[cx - r, cy + r, z], [cx + r, cy - r, z]]])
            )
            cols += [MARKS["prototype"]] * 2
        scene = self.client.scene
        if not segs:
            scene.add_line_segments("/design/map/marks", np.zeros((1, 2, 3), np.float32), (0, 0, 0), visible=False)
            return
        points = np.concatenate(segs).astype(np.float32)
        colours = np.repeat(np.array(cols, dtype=np.uint8)[:, None, :], 2, axis=1)
        scene.add_line_segments("/design/map/marks", points, colours, thickness=4.0, thickness_units="screen")

    def draw_comparison(
        self, designs: Mapping[Arrangement, tuple[Params | None, Task | None]], labels: Mapping[Arrangement, str]
    ) -> None:
        """Each arrangement's mechanism and task beside the map, left to right; one that cannot be drawn (no
        design, or the dimensions do not make that arrangement) is hidden. Nothing is sent when nothing changed."""
        key = (tuple(designs.items()), tuple(labels.items()))
        if self.area is None or key == self._drawn_for:
            return
        self._drawn_for = key
        left = MAP_CORNER[0] + MAP_SIDE + GAP
        for kind in Arrangement:
            params, task = designs[kind]
            drawing = self.drawings.get(kind)
            if params is None:
                if drawing is not None:
                    drawing.set_visible(False)
                continue
            lo, hi = extent(kind, params)
            offset = (left - float(lo[0]), -float(lo[1]))
            if drawing is None:
                drawing = self.drawings[kind] = ArrangementDrawing(self.client.scene, f"/design/{kind.value}", kind)
            drawing.move(offset)
            try:
                drawing.draw(params, task, labels[kind])
            except TpmVizError:
                drawing.set_visible(False)
            else:
                drawing.set_visible(True)
            left += float(hi[0] - lo[0]) + GAP

    def forget(self) -> None:
        """Send the comparison again at the next draw (the tab's language changed)."""
        self._drawn_for = None
