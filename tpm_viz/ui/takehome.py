"""The lesson's 3D scene for the offline page: viser's own client with the lesson's motion recorded in it.

viser 1.1.1 records the messages a server sends to its scene (``ViserServer.get_scene_serializer``, with
``insert_sleep`` between the frames of an animation) and writes the recording into its self-contained client
(``StateSerializer.as_html``: the client's ``index.html`` with the recording as base64 in
``window.__VISER_EMBED_DATA__``; the client plays it with its own player: play, pause, a time slider, the speed). No
server is needed to view it. To record, :func:`record_lesson` draws the lesson with the app's own drawing code
(:class:`~tpm_viz.ui.scene.MechanismScene`: the mechanism, its force arrows, the singularity loci;
:class:`~tpm_viz.ui.teaching.player.trace.PathTrace`: the path and the trace) on a private viser server that is never
served: it listens on a free loopback port (viser has no server without one) for the time of the recording and is
stopped before the function returns, and no client ever connects.

A lesson with a ``[motion]`` is recorded at :data:`FPS` frames per second of the motion's time (at least
:data:`MIN_FRAMES`, at most :data:`MAX_FRAMES`), frame ``k`` at ``t_k`` exactly (so the player's clock is the motion's
time), each frame the pose at ``p(t_k)`` and the actuator forces of eq. (31) for ``ṗ(t_k), p̈(t_k)``; a lesson that is
one pose is one frame at rest. :class:`Recording` also carries the frames' states, so that the page's calculator shows
the numbers of the frame the player shows.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import viser

from tpm_viz.app.demos import Demo, demo_pose, demo_source
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.runs import Run, build_run
from tpm_viz.app.state import AppState
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.params import Params
from tpm_viz.ui.scene import MechanismScene, camera_pose
from tpm_viz.ui.teaching.player.trace import PathTrace
from tpm_viz.viserkit.core import check_viser, disable_share_url

__all__ = ["FPS", "MAX_FRAMES", "MIN_FRAMES", "Recording", "frame_times", "record_lesson"]

FPS = 60.0
"""Frames per second of the motion's time."""
MIN_FRAMES = 61
"""Fewest frames of a motion (a 0.2 s line still has a smooth time slider)."""
MAX_FRAMES = 601
"""Most frames of a motion (a long CSV motion is recorded at a lower rate; the page stays small)."""


@dataclass(frozen=True)
class Recording:
    """viser's client with the lesson recorded in it (``html``) and the state of each frame: times ``t`` [s] (n,),
    platform position ``p`` [m], velocity ``dp`` [m/s] and acceleration ``ddp`` [m/s²] (n, 2)."""

    html: str
    t: np.ndarray
    p: np.ndarray
    dp: np.ndarray
    ddp: np.ndarray

    @property
    def duration(self) -> float:
        """The recording's length [s] (0 for a pose)."""
        return float(self.t[-1])


def frame_times(duration: float) -> np.ndarray:
    """The frame times [s] of a motion of ``duration`` [s] (module docstring): uniform, from 0 to ``duration``."""
    frames = int(np.clip(round(duration * FPS) + 1, MIN_FRAMES, MAX_FRAMES))
    return np.linspace(0.0, duration, frames)


@contextlib.contextmanager
def _server(params: Params, demo: Demo) -> Iterator[viser.ViserServer]:
    """A private viser server on a free loopback port, never served, with the lesson's camera; stopped on exit."""
    check_viser()
    with contextlib.redirect_stdout(io.StringIO()):  # viser's banner
        server = viser.ViserServer(host="127.0.0.1", port=0, label="tpm-viz", verbose=False)
    try:
        disable_share_url(server)
        server.scene.configure_environment_map(None)  # no environment map: nothing to fetch
        server.scene.world_axes.visible = False
        position, look_at = camera_pose(params) if demo.camera is None else (demo.camera.position, demo.camera.look_at)
        server.initial_camera.position = (float(position[0]), float(position[1]), float(position[2]))
        server.initial_camera.look_at = (float(look_at[0]), float(look_at[1]), float(look_at[2]))
        yield server
    finally:
        with contextlib.redirect_stdout(io.StringIO()):  # "(viser) Server stopped"
            server.stop()


def _draw(scene: MechanismScene, params: Params, pose: Pose, load: Load) -> None:
    scene.update(Snapshot(AppState(params=params, pose=pose, load=load), evaluate(params, pose, load)))


def _states(run: Run, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    states = [run.state_at(float(t)) for t in times]
    return tuple(np.array([s[k] for s in states], dtype=float) for k in (1, 2, 3))  # type: ignore[return-value]


def record_lesson(demo: Demo, params: Params) -> Recording:
    """The lesson ``demo`` with the mechanism ``params`` (its own, or changed with ``--set``) recorded in viser's
    client (module docstring). A motion the mechanism cannot follow is refused with one line
    (:func:`tpm_viz.app.runs.build_run`)."""
    source = demo_source(demo)
    run = None if source is None else build_run(params, source)
    if run is None:
        pose = demo_pose(demo, params)
        times, p = np.zeros(1), pose.p[None, :].astype(float)
        dp = ddp = np.zeros((1, 2))
    else:
        times = frame_times(run.duration)
        p, dp, ddp = _states(run, times)
        pose = Pose.working(params, p[0])
    with _server(params, demo) as server:
        scene = MechanismScene(server.scene, params, sink=server)
        path = PathTrace(server.scene)
        path.show_run(run)
        load = Load() if run is None else Load("dynamic", dp=tuple(dp[0]), ddp=tuple(ddp[0]))
        _draw(scene, params, pose, load)
        serializer = server.get_scene_serializer()
        for k in range(1, len(times)):
            serializer.insert_sleep(float(times[k] - times[k - 1]))
            load = Load("dynamic", dp=tuple(dp[k]), ddp=tuple(ddp[k]))
            _draw(scene, params, Pose.working(params, p[k]), load)
            path.show_time(run, float(times[k]))
        html = serializer.as_html()
    return Recording(html, times, p, dp, ddp)
