"""Frames of a clip seen through a tab's own 3D camera: a deterministic software renderer of the 3D scene.

The same parts the browser draws (:mod:`tpm_viz.drawing.meshes`: base plate and its grid, rails, end stops, sliders,
pins, the four links, platform, tool marker; the run's path and the trace so far, as the player draws them over the
platform), posed at each of the run's times with the paper's kinematics
(:func:`~tpm_viz.paper.kinematics.mechanism_pose`, eqs. 2 and 4), seen through a pinhole :class:`Camera` (viser's
convention, as ``client.camera`` reports it: ``P_world = R p_camera + t`` with the camera's x right, y down, z forward;
a vertical field of view). Painter's algorithm: the base plate and the grid first, then every triangle and line in the
order of its depth (farthest first), back faces culled, flat shading from the face normal; the force arrows on the
sliders along ``e_i`` last, over everything (green ``τ_i > 0``, red ``< 0``, 30 % of ``a`` at full scale as in the CLI
clip). A box in the top-left corner holds the title, the time and both forces as text and as bars
(:class:`~tpm_viz.media.clips.BarGeometry`, the bars' colours :data:`~tpm_viz.media.clips.BAR_COLOURS`).

A clip frame of another shape than the tab's canvas keeps the whole of what the tab shows: the tab's vertical
field of view if the frame is wider, its horizontal one if it is narrower. Triangles closer than :data:`NEAR` to the
camera are left out (no clipping). Numbers in, pixels out: the frames are the run's times, so the same run and
camera give the same bytes. Colours come from the caller (the app's palette), so that this layer imports no app.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
import trimesh
from PIL import Image, ImageDraw, ImageFont

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.words import Phrase, T
from tpm_viz.drawing import meshes
from tpm_viz.media.clips import BAR_COLOURS, MAX_FRAMES, BarGeometry, ClipRun, parse_size
from tpm_viz.paper.kinematics import mechanism_pose

__all__ = ["COLOUR_KEYS", "NEAR", "Camera", "View3dRenderer", "focal_length", "project"]

NEAR = 0.01
"""[m] A triangle or line with a point closer than this to the camera (or behind it) is left out."""
COLOUR_KEYS = ("base", "rail", "stop", "slider", "leg1", "leg2", "pin", "platform", "marker", "tau_pos", "tau_neg")
"""The colours (RGB) a renderer needs, by the names of the app's palette; plus ``path`` and ``trace``."""
BACKGROUND = (255, 255, 255)
GRID = ((203, 213, 225), (148, 163, 184))  # cells of 20 mm, sections of 100 mm, as the scene's grid
TRACE_Z = meshes.PLATFORM_Z[1] + 0.003  # m, the player's path and trace, just over the platform
ARROW_Z = meshes.PIN_Z[1] + 0.02  # m, the scene's force arrows, over every part
LIGHT = np.array([-0.35, -0.5, 1.0]) / np.linalg.norm([-0.35, -0.5, 1.0])  # towards the light, world frame
_INK = (15, 23, 42)
_NO_CAMERA = T("the camera is not known yet: move the 3D view a little and try again")
_FONT = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSansMono.ttf"


@dataclass(frozen=True)
class Camera:
    """A tab's camera: ``position`` [m] and orientation ``wxyz`` (``R`` in ``P_world = R p_camera + position``;
    camera x right, y down, z forward), vertical field of view ``fov`` [rad] and the canvas's ``aspect`` (w/h)."""

    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]
    fov: float
    aspect: float

    def __post_init__(self) -> None:
        values = (*self.position, *self.wxyz, self.fov, self.aspect)
        if len(self.position) != 3 or len(self.wxyz) != 4 or not all(math.isfinite(float(v)) for v in values):
            raise InputError(_NO_CAMERA)
        if not (0.0 < self.fov < math.pi and 0.0 < self.aspect < 100.0 and math.hypot(*self.wxyz) > 1e-9):
            raise InputError(_NO_CAMERA)

    @classmethod
    def looking_at(cls, position, look_at, up, fov: float, aspect: float) -> Camera:
        """The camera at ``position`` looking at ``look_at`` [m] with ``up`` up on the screen (viser's orbit camera;
        ``up`` along the view: the world axis least along it)."""
        position, look_at, up = (np.asarray(v, float) for v in (position, look_at, up))
        z = look_at - position
        if not np.all(np.isfinite(z)) or np.linalg.norm(z) == 0.0:
            raise InputError(_NO_CAMERA)
        z = z / np.linalg.norm(z)
        y = -(up - (up @ z) * z)
        if np.linalg.norm(y) < 1e-9:
            axis = np.eye(3)[int(np.argmin(np.abs(z)))]
            y = -(axis - (axis @ z) * z)
        y = y / np.linalg.norm(y)
        return cls(tuple(position), _wxyz(np.column_stack([np.cross(y, z), y, z])), float(fov), float(aspect))

    def rotation(self) -> np.ndarray:
        """``R`` (3, 3): the camera's axes (right, down, forward) as columns, world frame."""
        return _matrix(self.wxyz)


def _matrix(wxyz) -> np.ndarray:
    """The rotation matrix (3, 3) of a quaternion ``wxyz`` (any non-zero length)."""
    return trimesh.transformations.quaternion_matrix(np.asarray(wxyz, float))[:3, :3]


def _wxyz(m: np.ndarray) -> tuple[float, float, float, float]:
    """The unit quaternion ``wxyz`` of a rotation matrix (3, 3)."""
    full = np.eye(4)
    full[:3, :3] = m
    w, x, y, z = trimesh.transformations.quaternion_from_matrix(full)
    return float(w), float(x), float(y), float(z)


def focal_length(camera: Camera, size: tuple[int, int]) -> float:
    """[px] The pinhole's focal length for a frame of ``size`` = (width, height) [px] that shows all the tab shows."""
    half = math.tan(camera.fov / 2.0)
    return min(size[1] / (2.0 * half), size[0] / (2.0 * half * camera.aspect))


def project(camera: Camera, size: tuple[int, int], points) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates ``(u, v)`` (N, 2) [px, from the frame's top-left corner; pixel ``(i, j)`` covers
    ``[i, i + 1) x [j, j + 1)``] and depths (N,) [m] along the view of world ``points`` (N, 3) [m]."""
    cam = (np.asarray(points, float) - np.asarray(camera.position)) @ camera.rotation()
    f, z = focal_length(camera, size), cam[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = np.column_stack([size[0] / 2.0 + f * cam[:, 0] / z, size[1] / 2.0 + f * cam[:, 1] / z])
    return uv, z


def _triangles(mesh, longest: float = 0.04) -> np.ndarray:
    """The triangles (k, 3, 3) [m] of a trimesh, each split in two across its longest edge until no edge is longer
    than ``longest`` [m]: the painter's order of small triangles (by their centres' depth) is the visible one where
    parts touch (a marker on the platform, a slider on its rail)."""
    tris = np.asarray(mesh.vertices, float)[np.asarray(mesh.faces)]
    for _ in range(32):
        edges = np.linalg.norm(tris[:, [1, 2, 0]] - tris, axis=2)  # edge j runs from vertex j to vertex j + 1
        long = edges.max(axis=1) > longest
        if not long.any():
            break
        split, j = tris[long], edges[long].argmax(axis=1)
        rows = np.arange(len(split))
        a, b, c = split[rows, j], split[rows, (j + 1) % 3], split[rows, (j + 2) % 3]
        mid = (a + b) / 2.0
        tris = np.concatenate([tris[~long], np.stack([a, mid, c], axis=1), np.stack([mid, b, c], axis=1)])
    return tris


def _grid_segments(params) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The scene's floor grid (viser's ``add_grid`` over the base plate) as (k, 2, 3) segments and their colours:
    cells of 20 mm, then sections of 100 mm over them."""
    lo, hi = meshes.base_extent(params)
    centre, out, colours = (lo + hi) / 2.0, [], []
    for cell, colour in zip((0.02, 0.1), GRID, strict=True):
        count = int((hi - lo) / 2 / cell)
        for x in centre + cell * np.arange(-count, count + 1):
            out += [[(x, lo, 0.0005), (x, hi, 0.0005)], [(lo, x, 0.0005), (hi, x, 0.0005)]]
            colours += [colour, colour]
    return np.asarray(out, float), colours


def _thinned(p: np.ndarray, most: int) -> np.ndarray:
    """At most ``most`` segments of the polyline ``p`` (n, 2) at :data:`TRACE_Z`, as (k, 2, 3)."""
    step = max(1, math.ceil((len(p) - 1) / most))
    pts = p[np.unique(np.r_[np.arange(0, len(p), step), len(p) - 1])]
    pts3 = np.column_stack([pts, np.full(len(pts), TRACE_Z)])
    return np.stack([pts3[:-1], pts3[1:]], axis=1)


def _force_scale(tau: np.ndarray) -> float:
    """Half-width of the bars' scale [N]: the run's peak with 10 % room, rounded up to 1, 2 or 5 x 10^k."""
    peak = max(float(np.max(np.abs(np.nan_to_num(tau, nan=0.0, posinf=0.0, neginf=0.0)))) * 1.1, 1e-3)
    exp = 10.0 ** math.floor(math.log10(peak))
    return next(m * exp for m in (1.0, 2.0, 5.0, 10.0) if m * exp >= peak)


class View3dRenderer:
    """Draws the frames of one run at ``size`` = (width, height) [px] through ``camera``; ``title`` names the run,
    ``colours`` maps :data:`COLOUR_KEYS`, ``path`` and ``trace`` to RGB."""

    def __init__(
        self, run: ClipRun, title: str, size: tuple[int, int], camera: Camera, colours: Mapping[str, tuple]
    ) -> None:
        n = len(run.t)
        if not 2 <= n <= MAX_FRAMES:
            raise InputError(Phrase("a clip has 2 to {hi} frames (one per run sample), got {n}", hi=MAX_FRAMES, n=n))
        self.size = parse_size(f"{size[0]}x{size[1]}")
        self.run, self.camera, self.title = run, camera, title
        self._eye, self._turn, self._f = (
            np.asarray(camera.position, float),
            camera.rotation(),
            focal_length(camera, self.size),
        )
        self.colours = {k: tuple(int(c) for c in colours[k]) for k in (*COLOUR_KEYS, "path", "trace")}
        params = run.params
        self.scale = _force_scale(run.tau)
        step = float(np.min(np.diff(run.t)))
        self._digits = int(np.clip(math.ceil(-math.log10(max(step, 1e-9))) + 1, 3, 7))
        self._static = [(_triangles(meshes.base_plate(params), longest=1.0), "base")]  # drawn first: not split
        self._parts = [(_triangles(meshes.rail(params, i)), "rail") for i in range(2)]
        self._parts += [(_triangles(meshes.end_stops(params, i)), "stop") for i in range(2)]
        self._slider = [_triangles(meshes.slider(params, i)) for i in range(2)]
        self._slider_pins = [meshes.slider_pin_offsets(params, i) for i in range(2)]
        self._pin, self._link = _triangles(meshes.pin()), _triangles(meshes.link(params))
        self._platform = [
            (_triangles(meshes.platform(params)), "platform"),
            (_triangles(meshes.tool_marker()), "marker"),
        ]
        self._platform += [(self._pin + offset, "pin") for offset in meshes.platform_pin_offsets(params)]
        self._grid = _grid_segments(params)
        self._path = _thinned(np.asarray(run.p, float), 400)
        self._font_px = max(10, round(14 * self.size[1] / 360))
        self._fonts = (
            ImageFont.truetype(str(_FONT), max(8, round(self._font_px * 0.8))),
            ImageFont.truetype(str(_FONT), self._font_px),
        )
        self._box = self._layout()

    def __len__(self) -> int:
        return len(self.run.t)

    # -- the overlay -----------------------------------------------------------------------------------------
    def _layout(self) -> dict[str, int]:
        """Pixel geometry of the box of the time and forces (the same in every frame)."""
        fp, w = self._font_px, self.size[0]
        pad = max(6, fp // 2)
        inner = max(round(0.28 * w), round(self._fonts[1].getlength("τ1 = +000.00 N")))
        half = inner // 2
        line, bar = round(fp * 1.3), max(5, round(fp * 0.5))
        top = pad + round(fp * 0.8 * 1.6)  # under the title
        rows = (top + 2 * line + bar // 2 + 2, top + 4 * line + bar // 2 + 2)
        return dict(
            left=pad, top=pad, right=pad + inner + 2 * pad, bottom=rows[1] + bar + round(fp * 1.2) + pad,
            x=2 * pad, zero=2 * pad + half, half=half, line=line, bar=bar, text=top, row1=rows[0], row2=rows[1],
        )  # fmt: skip

    def geometry(self) -> BarGeometry:
        """The bars' pixel geometry (identical in every frame)."""
        b = self._box
        return BarGeometry(
            zero_x=float(b["zero"]),
            px_per_newton=b["half"] / self.scale,
            rows=(b["row1"], b["row2"]),
            height=b["bar"],
        )

    def texts(self, k: int) -> tuple[str, str, str]:
        """The time and the two forces as frame ``k`` shows them."""
        t, tau = float(self.run.t[k]), self.run.tau[k]
        signed = [("+" + s if s[:1].isdigit() else s) for s in (fixed(float(v), ".2f") for v in tau)]
        return (f"t = {t:.{self._digits}f} s", f"τ1 = {signed[0]} N", f"τ2 = {signed[1]} N")

    def _overlay(self, image: Image.Image, k: int) -> None:
        b, small, large = self._box, *self._fonts
        box = (b["left"], b["top"], min(b["right"], self.size[0]), min(b["bottom"], self.size[1]))
        behind = image.crop(box)
        image.paste(Image.blend(behind, Image.new("RGB", behind.size, BACKGROUND), 0.85), box)
        draw = ImageDraw.Draw(image)
        title = self.title
        while len(title) > 1 and small.getlength(title) > b["right"] - b["left"] - 2 * (b["x"] - b["left"]):
            title = title[:-2] + "…"
        draw.text((b["x"], b["top"] + 2), title, fill=_INK, font=small)
        clock, *values = self.texts(k)
        draw.text((b["x"], b["text"]), clock, fill=_INK, font=large)
        for i, value in enumerate(values):
            row = b[f"row{i + 1}"]
            draw.text((b["x"], row - b["bar"] // 2 - b["line"] - 1), value, fill=BAR_COLOURS[i], font=large)
            draw.rectangle((b["zero"] - b["half"], row - b["bar"] // 2, b["zero"] + b["half"] - 1, row + b["bar"] // 2),
                           fill=(241, 245, 249))  # fmt: skip
        zero, half = b["zero"], b["half"]
        draw.line((zero, b["row1"] - b["bar"], zero, b["row2"] + b["bar"]), fill=(100, 116, 139), width=1)
        for i in range(2):
            length = round(float(np.clip(np.nan_to_num(self.run.tau[k, i] / self.scale), -1.0, 1.0)) * half)
            row = b[f"row{i + 1}"]
            if length:
                lo, hi = sorted((zero, zero + length))
                draw.rectangle((lo, row - b["bar"] // 2, hi - 1, row + b["bar"] // 2), fill=BAR_COLOURS[i])
        under = b["row2"] + b["bar"]
        scale = fixed(self.scale, "g")
        draw.text((zero - half, under), f"-{scale}", fill=_INK, font=small)
        draw.text((zero + half, under), f"+{scale} N", fill=_INK, font=small, anchor="ra")

    # -- the scene -------------------------------------------------------------------------------------------
    def _posed(self, k: int) -> list[tuple[np.ndarray, str]]:
        """The moving parts' triangles in the world at frame ``k`` (eqs. 2 and 4)."""
        run = self.run
        pose = mechanism_pose(run.params, run.p[k], run.d[k])
        out: list[tuple[np.ndarray, str]] = list(self._parts)
        for i in range(2):
            a = np.array([pose.A[i, 0], pose.A[i, 1], 0.0])
            out.append((self._slider[i] + a, "slider"))
            out += [(self._pin + a + offset, "pin") for offset in self._slider_pins[i]]
        positions, wxyzs = meshes.link_instances(pose)
        for j, (position, wxyz) in enumerate(zip(positions, wxyzs, strict=True)):
            out.append((self._link @ _matrix(wxyz).T + position, "leg1" if j < 2 else "leg2"))
        p = np.array([run.p[k, 0], run.p[k, 1], 0.0])
        out += [(tris + p, name) for tris, name in self._platform]
        return out

    def _camera_space(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) [m] in the camera's frame (x right, y down, z forward) [m]."""
        return (points - self._eye) @ self._turn

    def _shaded(self, parts: list[tuple[np.ndarray, str]]) -> tuple[np.ndarray, list]:
        """The front-facing triangles (k, 3, 3) in the camera's frame, and their flat-shaded colours."""
        tris = np.concatenate([t for t, _ in parts])
        base = np.concatenate([np.tile(self.colours[name], (len(t), 1)) for t, name in parts]).astype(float)
        cam = self._camera_space(tris)
        normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
        to_eye = self._eye - tris.mean(axis=1)
        to_eye /= np.maximum(np.linalg.norm(to_eye, axis=1, keepdims=True), 1e-12)
        facing = np.einsum("ij,ij->i", normal, to_eye)
        keep = (facing > 0.0) & np.all(cam[:, :, 2] > NEAR, axis=1)
        head = np.clip(-(normal @ self._turn[:, 2]), 0.0, 1.0)  # a headlight: the same on a whole face
        light = 0.5 + 0.35 * np.clip(normal @ LIGHT, 0.0, 1.0) + 0.15 * head
        rgb = np.clip(np.rint(base * light[:, None]), 0, 255).astype(int)[keep]
        return cam[keep], [tuple(c) for c in rgb.tolist()]

    def _lines(self, segments: np.ndarray, colours: list) -> tuple[np.ndarray, list]:
        """The segments (k, 2, 3) in front of the camera, in its frame, and their colours."""
        cam = self._camera_space(segments)
        seen = np.all(cam[:, :, 2] > NEAR, axis=1)
        return cam[seen], [colours[j] for j in np.flatnonzero(seen).tolist()]

    def _screen(self, cam: np.ndarray) -> np.ndarray:
        """Camera-frame points (..., 3) [m] in pixels (..., 2) (PIL fills the pixels whose centres, at ``i + 0.5``,
        are inside a polygon: the same pixel coordinates as :func:`project`)."""
        u = self.size[0] / 2.0 + self._f * cam[..., 0] / cam[..., 2]
        v = self.size[1] / 2.0 + self._f * cam[..., 1] / cam[..., 2]
        return np.clip(np.stack([u, v], axis=-1), -1e6, 1e6)

    def _paint(self, draw: ImageDraw.ImageDraw, shapes: np.ndarray, fills: list, width: int, lines: int = 0) -> None:
        """Triangles (k, 3, 3) in the camera's frame, farthest first (painter's algorithm); the last ``lines`` are
        segments (their third point repeats the second), drawn ``width`` px wide. Shapes wholly beside the frame
        are skipped."""
        uv = self._screen(shapes)
        margin = width + 1
        inside = (
            (uv[:, :, 0].max(axis=1) >= -margin)
            & (uv[:, :, 1].max(axis=1) >= -margin)
            & (uv[:, :, 0].min(axis=1) <= self.size[0] + margin)
            & (uv[:, :, 1].min(axis=1) <= self.size[1] + margin)
        )
        kept = np.flatnonzero(inside)
        order = kept[np.argsort(-shapes[kept, :, 2].mean(axis=1), kind="stable")]
        first_line = len(shapes) - lines
        for j, flat in zip(order.tolist(), uv[order].reshape(len(order), -1).tolist(), strict=True):
            if j < first_line:
                draw.polygon(flat, fill=fills[j])
            else:
                draw.line(flat[:4], fill=fills[j], width=width)

    def frame(self, k: int) -> np.ndarray:
        """Frame ``k`` (the run at ``t[k]``) as an RGB array ``(height, width, 3)`` of uint8."""
        image = Image.new("RGB", self.size, BACKGROUND)
        draw = ImageDraw.Draw(image)
        above = self.camera.position[2] > 0.0  # from under the floor the plate is sorted with the rest
        if above:
            floor, floor_rgb = self._shaded(self._static)
            self._paint(draw, floor, floor_rgb, 1)
            grid, grid_rgb = self._lines(*self._grid)
            for seg, colour in zip(self._screen(grid).reshape(len(grid), 4).tolist(), grid_rgb, strict=True):
                draw.line(seg, fill=colour, width=1)
        tris, rgb = self._shaded(self._posed(k) + ([] if above else self._static))
        run = self.run
        path, path_rgb = self._lines(self._path, [self.colours["path"]] * len(self._path))
        trace = _thinned(np.asarray(run.p[: k + 1], float), 150) if k else np.zeros((0, 2, 3))
        mark, mark_rgb = self._lines(trace, [self.colours["trace"]] * len(trace))
        lines = np.concatenate([path, mark])  # drawn as triangles with a repeated point: one sort for all
        shapes = np.concatenate([tris, np.concatenate([lines, lines[:, 1:]], axis=1)])
        shapes[len(tris) + len(path) :, :, 2] -= 1e-4  # the trace over the path
        fills = rgb + path_rgb + mark_rgb
        self._paint(draw, shapes, fills, max(2, round(self.size[1] / 300)), lines=len(lines))
        self._arrows(draw, k)
        self._overlay(image, k)
        return np.asarray(image)

    def _arrows(self, draw: ImageDraw.ImageDraw, k: int) -> None:
        """The force arrows on the sliders along ``e_i`` (30 % of ``a`` at full scale), over every part."""
        run = self.run
        pose = mechanism_pose(run.params, run.p[k], run.d[k])
        for i in range(2):
            tau = float(run.tau[k, i])
            length = 0.3 * run.params.a * tau / self.scale  # m
            if not abs(length) >= 1e-3 or not math.isfinite(length):  # NaN: no arrow
                continue
            along, across = np.eye(3)[i], np.eye(3)[1 - i]
            root = np.array([pose.A[i, 0], pose.A[i, 1], ARROW_Z])
            tip = root + along * length
            head = min(0.035, 0.5 * abs(length)) * np.sign(length)
            pts = np.array([root, tip - along * head, tip, tip - along * head + across * 0.018,
                            tip - along * head - across * 0.018])  # fmt: skip
            cam = self._camera_space(pts)
            if np.any(cam[:, 2] <= NEAR):
                continue
            uv = [tuple(p) for p in self._screen(cam).tolist()]
            colour = self.colours["tau_pos" if tau >= 0 else "tau_neg"]
            draw.line([uv[0], uv[1]], fill=colour, width=max(3, round(self.size[1] / 120)))
            draw.polygon([uv[2], uv[3], uv[4]], fill=colour)
