"""What a tab takes out of the room: the material of its Player, Control or Planner run, and a clip
recorded a few frames at a time.

:class:`Material` is what *Record clip* and *Download report* need of a tab: the frames' arrays (a
:class:`~tpm_viz.media.clips.ClipRun`, at most :data:`APP_FRAMES` samples), a title, a file name stem, and a function
that builds the report in the worker (the run with the Pinocchio forces and the tab's results). A
:class:`Recording` renders and encodes :data:`CHUNK_FRAMES` frames per :meth:`Recording.step`, so that the app's
fair worker serves the other tabs between two steps (a whole clip is 5-30 s of computation). At most
:data:`MAX_RECORDINGS` recordings run in the whole server at once (:data:`SLOTS`); each is bounded in frames
(:data:`APP_FRAMES`), size (the presets up to 1920×1080) and bytes (:data:`tpm_viz.media.videos.MAX_CLIP_BYTES`).

The clip is seen through the tab's own 3D camera (its :class:`~tpm_viz.media.views3d.Camera` when *Record clip* was
clicked): :class:`tpm_viz.media.views3d.View3dRenderer` draws the scene's parts in the scene's colours
(:data:`SCENE_COLOURS`) on the server, deterministically, without moving the tab's view. ``tpm-viz clip`` keeps the
top view (:mod:`tpm_viz.media.clips`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.runs import Run, Source, build_run
from tpm_viz.core.params import Params
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.media.clips import ClipRun
from tpm_viz.media.report import Section
from tpm_viz.media.videos import ClipWriter, clip_writer
from tpm_viz.media.views3d import Camera, View3dRenderer
from tpm_viz.multibody import inverse_dynamics
from tpm_viz.paper.kinematics import inverse_kinematics
from tpm_viz.paper.trajectories import trajectory_from_samples
from tpm_viz.ui.teaching.player.trace import PATH_COLOUR, TRACE_COLOUR

__all__ = [
    "APP_FRAMES",
    "CHUNK_FRAMES",
    "MAX_RECORDINGS",
    "SCENE_COLOURS",
    "SLOTS",
    "Frames",
    "Material",
    "Recording",
    "frames_of",
    "report_of_path",
]

APP_FRAMES = 401
"""Most frames of a clip recorded in the app (a run's samples, evenly thinned to this many)."""
CHUNK_FRAMES = 4
"""Frames rendered and encoded per worker job (`benchmarks/bench_clip.py`: one job's time is what another tab's
job may wait behind it)."""
MAX_RECORDINGS = 3
"""Clips recorded at once in the whole server (each holds a canvas and its encoder)."""
SLOTS = threading.BoundedSemaphore(MAX_RECORDINGS)
"""The server's recording slots: a tab takes one for its clip and gives it back when the clip ends in any way."""
SCENE_COLOURS = {**PALETTE, "path": PATH_COLOUR, "trace": TRACE_COLOUR}
"""The 3D scene's colours (RGB) of the parts, the force arrows and the player's path and trace."""


@dataclass(frozen=True)
class Frames:
    """The arrays of a clip (SI units): times ``t`` (n,) [s], platform ``p``, actuators ``d`` [m] and forces
    ``tau`` [N], each (n, 2)."""

    params: Params
    t: np.ndarray
    p: np.ndarray
    d: np.ndarray
    tau: np.ndarray


def frames_of(params: Params, t, p, tau, most: int = APP_FRAMES) -> Frames:
    """At most ``most`` samples of ``(t, p, tau)``, evenly spaced by index (first and last kept); ``d`` from the
    inverse kinematics, eq. (4)."""
    t, p, tau = np.asarray(t, float), np.asarray(p, float), np.asarray(tau, float)
    keep = np.unique(np.rint(np.linspace(0, len(t) - 1, min(len(t), most))).astype(int))
    return Frames(params, t[keep], p[keep], inverse_kinematics(params, p[keep]), tau[keep])


@dataclass(frozen=True)
class Material:
    """What a tab takes out: the clip's arrays, its title, a file name stem, and the report's run and sections
    (``report()`` runs in the worker: it may compute the Pinocchio forces)."""

    clip: ClipRun
    title: str
    stem: str
    report: Callable[[], tuple[Run, tuple[Section, ...]]]


def report_of_path(params: Params, t, p, label: str) -> Run:
    """A run through timed samples (a control reference, a plan) with the Pinocchio forces, for a report."""
    t, p = np.asarray(t, float), np.asarray(p, float)
    keep = np.unique(np.rint(np.linspace(0, len(t) - 1, min(len(t), 2000))).astype(int))
    source = Source.from_trajectory(trajectory_from_samples(t[keep], p[keep], label), label)
    return build_run(params, source, inverse_dynamics)


class Recording:
    """One clip being recorded through ``camera`` (the tab's, when it was asked for): :meth:`step` until it returns
    True, then :attr:`data` holds the file."""

    def __init__(self, material: Material, size: tuple[int, int], fmt: str, fps: int, camera: Camera) -> None:
        self.material, self.size, self.fmt, self.fps, self.camera = material, size, fmt, fps, camera
        self.total = len(material.clip.t)
        self.done = 0
        self.data: bytes | None = None
        self._renderer: View3dRenderer | None = None
        self._writer: ClipWriter | None = None

    @property
    def name(self) -> str:
        """The file name offered to the browser."""
        return f"{self.material.stem}-{self.size[0]}x{self.size[1]}-{self.fps}fps.{self.fmt}"

    def step(self) -> bool:
        """Render and encode the next :data:`CHUNK_FRAMES` frames (the first step also sets up); True when the
        clip is finished (:attr:`data`)."""
        if self._renderer is None:
            clip, title = self.material.clip, self.material.title
            self._renderer = View3dRenderer(clip, title, self.size, self.camera, SCENE_COLOURS)
            self._writer = clip_writer(self.fmt, self.fps, self._renderer.frame, self.total)
            return False
        assert self._writer is not None
        for _ in range(CHUNK_FRAMES):
            if self.done == self.total:
                break
            self._writer.add(self._renderer.frame(self.done))
            self.done += 1
        if self.done < self.total:
            return False
        self.data = self._writer.finish()
        self.close()
        return True

    def close(self) -> None:
        """Let go of the canvas and the encoder (idempotent)."""
        writer, self._writer, self._renderer = self._writer, None, None
        close = getattr(writer, "close", None)
        if close is not None:
            close()
