"""The player's scene nodes in one tab: the whole path of the loaded run (yellow, sent once per run) and the trace
the platform leaves behind it (dark, re-sent as it grows, at most 150 segments).

Both are drawn just over the platform's top face, so the trace visibly leaves the tool marker at ``P``.
"""

from __future__ import annotations

import numpy as np
import viser

from tpm_viz.app.runs import Run
from tpm_viz.drawing import meshes

__all__ = ["PATH_COLOUR", "TRACE_COLOUR", "PathTrace", "segments"]

TRACE_Z = meshes.PLATFORM_Z[1] + 0.003  # m
PATH_COLOUR = (234, 179, 8)  # the tool marker's yellow: where P will go
TRACE_COLOUR = (15, 23, 42)
PATH_SEGMENTS, TRACE_SEGMENTS = 400, 150


def segments(p: np.ndarray, z: float, max_segments: int) -> np.ndarray:
    """A polyline through ``p`` (``(n, 2)`` [m], decimated to ``max_segments``) as ``(k, 2, 3)`` float32 segments
    at height ``z`` (the last point always kept; one degenerate segment for a single point)."""
    step = max(1, int(np.ceil((len(p) - 1) / max_segments)))
    pts = p[np.unique(np.r_[np.arange(0, len(p), step), len(p) - 1])]
    segs = np.zeros((max(len(pts) - 1, 1), 2, 3), dtype=np.float32)
    if len(pts) >= 2:
        segs[:, 0, :2], segs[:, 1, :2] = pts[:-1], pts[1:]
    else:
        segs[:, :, :2] = pts[0]
    segs[..., 2] = z
    return segs


class PathTrace:
    """Path and trace nodes of one tab (``client.scene``), created at the first run."""

    def __init__(self, scene: viser.SceneApi) -> None:
        self._scene = scene
        self.path: viser.LineSegmentsHandle | None = None
        self.trace: viser.LineSegmentsHandle | None = None

    def show_run(self, run: Run | None) -> None:
        """Draw the whole path of ``run`` (None hides both nodes)."""
        if run is None:
            for handle in (self.path, self.trace):
                if handle is not None and handle.visible:
                    handle.visible = False
            return
        self.path = self._scene.add_line_segments(
            "/player/path",
            segments(run.p, TRACE_Z, PATH_SEGMENTS),
            PATH_COLOUR,
            thickness=2.5,
            thickness_units="screen",
        )
        if self.trace is None:
            self.trace = self._scene.add_line_segments(
                "/player/trace",
                segments(run.p[:2], TRACE_Z + 0.0005, 1),
                TRACE_COLOUR,
                thickness=4.0,
                thickness_units="screen",
                visible=False,
            )

    def show_time(self, run: Run | None, t: float | None) -> None:
        """The trace from the start to ``t`` [s] (hidden at ``t = 0`` or off the path)."""
        if self.trace is None:
            return
        if run is None or t is None or t <= 0.0:
            if self.trace.visible:
                self.trace.visible = False
            return
        k = run.index_at(t)
        _, p_now, _, _ = run.state_at(t)
        self.trace.points = segments(np.vstack([run.p[: k + 1], p_now[None]]), TRACE_Z + 0.0005, TRACE_SEGMENTS)
        if not self.trace.visible:
            self.trace.visible = True
