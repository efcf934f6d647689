"""One lesson of the guided tour as data: frozen dataclasses and the scene they describe (no files, no viser).

A :class:`Demo` sets the mechanism (parameter overrides of the paper's prototype, a pose or the start of a
motion, the assembly mode), the camera, the explorer map and the ellipses, and explains what to watch in one
paragraph per UI language. Lessons are written as TOML files (``assets/lessons``, read by
:mod:`tpm_viz.app.lesson_files`); :mod:`tpm_viz.app.lessons` holds the packaged tour and the numbers behind it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tpm_viz.app.exercises.model import Exercise
from tpm_viz.app.moves import Pose
from tpm_viz.app.runs import Source
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.paper.kinematics import forward_kinematics
from tpm_viz.paper.trajectories import Trajectory

__all__ = ["CHECK_NAMES", "LANGUAGES", "Camera", "Check", "Demo", "Motion", "demo_params", "demo_pose", "demo_source"]

LANGUAGES = ("en", "ko")
"""UI languages a lesson's text may be written in; ``en`` is required, the others optional."""

CHECK_NAMES = {
    "det_jx_start": "det J_x = cos(θ1+θ2) at the motion's start (eq. 12)",
    "det_jx_end": "det J_x at the motion's end",
    "force_start": "the larger |τ_i| at the motion's start [N]",
    "force_end": "the larger |τ_i| at the motion's end [N]",
    "force_ratio": "the larger |τ_i| at the end / at the start",
    "peak_force": "peak |τ_i| over the motion [N]",
    "peak_ratio": "peak |τ_i| at motion.compare[0] / at motion.compare[1]",
    "reference_gap": "largest |τ_Pinocchio - τ_paper| over the motion [N] (checked by the tests)",
    "det_jx": "det J_x at the pose",
    "cos_theta1": "cos θ1 at the pose (eq. 11)",
    "cos_theta2": "cos θ2 at the pose",
    "cond": "condition number of J at the pose",
    "velocity_min": "shortest radius of the velocity ellipse [m/s per m/s]",
    "velocity_max": "longest radius of the velocity ellipse",
    "force_ellipse_min": "shortest radius of the force ellipse [N per N]",
    "force_ellipse_max": "longest radius of the force ellipse",
    "p1_mm": "platform p1 at the pose [mm]",
    "p2_mm": "platform p2 at the pose [mm]",
    "other_p1_mm": "p1 of the other assembly mode at the same d [mm]",
    "other_p2_mm": "p2 of the other assembly mode [mm]",
    "other_det_jx": "det J_x of the other assembly mode",
    "workspace_cm2": "in-stroke workspace area with the lesson's parameters [cm²]",
    "reachable_cm2": "reachable square area with the lesson's parameters [cm²]",
    "paper_workspace_cm2": "in-stroke workspace area of the paper's prototype [cm²]",
    "paper_reachable_cm2": "reachable square area of the paper's prototype [cm²]",
}
"""The numbers a lesson's ``[checks]`` may state, computed from its scene by
:func:`tpm_viz.app.lessons.check_values`."""


@dataclass(frozen=True)
class Camera:
    """Camera position and look-at point [m] (Z up), centred on what the demo shows (the app shifts both
    sideways so that the scene is not hidden by its panel)."""

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]


@dataclass(frozen=True)
class Motion:
    """A trajectory for the player: the paper's ``"line"``/``"circle"``, a ``"segment"`` start -> end [m], or a
    ``"csv"`` file of timed positions (``t,p1,p2``, read when the lesson is loaded into ``trajectory``)."""

    kind: str
    duration: float  # s
    start: tuple[float, float] | None = None
    end: tuple[float, float] | None = None
    file: str = ""  # the CSV, as written in the lesson (relative to the lesson file)
    trajectory: Trajectory | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Check:
    """A number the lesson states: ``name`` (one of :data:`tpm_viz.app.lessons.CHECKS`), the stated ``value`` and
    the accepted absolute difference ``tol`` (``None``: the default of :func:`tpm_viz.app.lessons.tolerance`)."""

    name: str
    value: float
    tol: float | None = None


@dataclass(frozen=True)
class Demo:
    """One scene of the guided tour (SI units)."""

    key: str
    title: str
    text: str  # English
    camera: Camera | None  # None: the app's default view of the mechanism
    params: tuple[tuple[str, float], ...] = ()  # overrides of Params.paper()
    p: tuple[float, float] | None = None  # platform position, working mode (eq. 4)
    d: tuple[float, float] | None = None  # or actuator positions, with the assembly mode below
    mode: int = 1
    motion: Motion | None = None  # the pose is then the motion's start
    map_kind: str = "off"
    ellipses: bool = False
    compare: tuple[float, ...] = ()  # durations whose force peaks the effect compares
    texts: tuple[tuple[str, str], ...] = ()  # (language, text) for the languages other than English
    checks: tuple[Check, ...] = ()
    source: str = ""  # the file the lesson was read from
    exercises: tuple[Exercise, ...] = ()  # its [[exercise]] tables (tpm_viz.app.exercises)

    def text_in(self, language: str) -> str:
        """The paragraph in ``language`` if the lesson has it, else in English."""
        return dict(self.texts).get(language, self.text)


def demo_params(demo: Demo) -> Params:
    """The paper's prototype with the demo's overrides (validated)."""
    return Params.paper().replace(**dict(demo.params))


def demo_source(demo: Demo, duration: float | None = None) -> Source | None:
    """The demo's trajectory for the player, if it has one (``duration`` [s]: the same path in another time)."""
    m = demo.motion
    if m is None:
        return None
    T = m.duration if duration is None else duration
    label = demo.title.split(". ", 1)[-1].lower()
    if m.kind == "segment" and m.start is not None and m.end is not None:
        return Source.segment(m.start, m.end, T, label=f"{label}, T = {T:g} s")
    if m.kind == "csv":
        if m.trajectory is None:
            raise InputError(f"demo {demo.key!r}: its CSV motion {m.file!r} was not read")
        traj = m.trajectory
        scale = T / traj.duration
        timed = Trajectory(traj.name, traj.t * scale, traj.p, traj.dp / scale, traj.ddp / scale**2)
        return Source.from_trajectory(timed, label=m.file.rsplit("/", 1)[-1])
    return Source.paper(m.kind, T)


def demo_pose(demo: Demo, params: Params) -> Pose:
    """The pose the demo starts from: the motion's start, ``p`` (working mode) or ``d`` in ``mode``."""
    source = demo_source(demo)
    if source is not None:
        p, _, _ = source.motion(np.array([0.0]))
        return Pose.working(params, p[0])
    if demo.p is not None:
        return Pose.working(params, demo.p)
    if demo.d is not None:
        return Pose(forward_kinematics(params, demo.d, mode=demo.mode), np.asarray(demo.d))
    raise InputError(f"demo {demo.key!r} has no pose")
