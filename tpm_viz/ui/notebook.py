"""The mechanism and a trajectory run inline in Jupyter, with viser's scene embedding (``docs/notebook.md``).

viser 1.1.1 records the messages a server sends to its scene (``ViserServer.get_scene_serializer``, with
``insert_sleep`` between frames of an animation) and shows the recording as a self-contained HTML viewer: inline
in a notebook (an ``<iframe srcdoc>`` through IPython, which viser imports itself only when it runs in a kernel),
else in the web browser. :class:`Embed` draws the app's own 3D mechanism (:class:`~tpm_viz.ui.scene.MechanismScene`)
on a private loopback server, so the picture is the app's: still poses with :meth:`Embed.show_pose`, a
:class:`~tpm_viz.app.runs.Run` played with its force arrows with :meth:`Embed.show_run`, or the HTML of either
(:meth:`Embed.pose_html`, :meth:`Embed.run_html`) to save or test. The live, interactive app is another story:
``tpm_viz.ui.app.main(block=False)`` and an IFrame on its URL (``docs/notebook.md``).

Nothing here imports IPython or Jupyter: they are the optional ``notebook`` extra, used by viser when present.
"""

from __future__ import annotations

import contextlib
import io

import numpy as np
import viser

from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.runs import Run
from tpm_viz.app.state import AppState
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.ui.scene import MechanismScene, camera_pose
from tpm_viz.viserkit.core import check_viser, disable_share_url

__all__ = ["MAX_FRAMES", "Embed"]

MAX_FRAMES = 600
"""Most frames of one embedded animation (the HTML holds every frame)."""


class Embed:
    """A private viser server (loopback, any free port) that draws one mechanism for embedding; :meth:`close`
    it when done (or use it as a context manager)."""

    def __init__(self, params: Params | None = None) -> None:
        check_viser()
        self.params = Params.paper() if params is None else params
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner
            self.server = viser.ViserServer(host="127.0.0.1", port=0, label="tpm-viz", verbose=False)
        disable_share_url(self.server)
        self.server.scene.configure_environment_map(None)
        self.server.scene.world_axes.visible = False
        self.scene = MechanismScene(self.server.scene, self.params, sink=self.server)
        position, look_at = camera_pose(self.params)
        self.server.initial_camera.position = position
        self.server.initial_camera.look_at = look_at
        self.draw(Pose.working(self.params, (0.0, 0.0)))

    def __enter__(self) -> Embed:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Stop the server (its port is free again)."""
        with contextlib.redirect_stdout(io.StringIO()):  # "(viser) Server stopped"
            self.server.stop()

    def draw(self, pose: Pose, load: Load = Load(), params: Params | None = None) -> None:
        """Draw the mechanism at ``pose`` under ``load`` (force arrows: the closed-form actuator forces)."""
        params = self.params if params is None else params
        state = AppState(params=params, pose=pose, load=load)
        self.scene.update(Snapshot(state, evaluate(params, pose, load)))

    def pose_html(self, p=(0.0, 0.0), dark_mode: bool = False) -> str:
        """A standalone HTML page with the mechanism at platform position ``p`` [m] (working mode)."""
        self.draw(Pose.working(self.params, p))
        return self.server.get_scene_serializer().as_html(dark_mode)

    def show_pose(self, p=(0.0, 0.0), height: int = 420) -> None:
        """Show the mechanism at ``p`` [m]: inline in a notebook, else in the web browser."""
        self.draw(Pose.working(self.params, p))
        self.server.get_scene_serializer().show(height)

    def record(self, run: Run, fps: float = 30.0):
        """viser's serializer holding ``run`` played in real time at ``fps`` frames per second (each frame: the
        pose and the actuator forces of eq. 31). At most :data:`MAX_FRAMES` frames."""
        if not np.isfinite(fps) or fps <= 0:
            raise InputError(f"fps must be a positive number, got {fps!r}")
        frames = int(np.clip(round(run.duration * fps) + 1, 2, MAX_FRAMES))
        times = np.linspace(0.0, run.duration, frames)
        index = np.searchsorted(run.t, times).clip(0, len(run.t) - 1)
        self.draw(Pose(run.p[0], run.d[0]), params=run.params)
        serializer = self.server.get_scene_serializer()
        step = run.duration / (frames - 1)
        for k in index:
            load = Load("dynamic", dp=tuple(run.dp[k]), ddp=tuple(run.ddp[k]))
            self.draw(Pose(run.p[k], run.d[k]), load, run.params)
            serializer.insert_sleep(step)
        return serializer

    def run_html(self, run: Run, fps: float = 30.0, dark_mode: bool = False) -> str:
        """A standalone HTML page that plays ``run``."""
        return self.record(run, fps).as_html(dark_mode)

    def show_run(self, run: Run, fps: float = 30.0, height: int = 420) -> None:
        """Play ``run`` inline in a notebook (else in the web browser)."""
        self.record(run, fps).show(height)
