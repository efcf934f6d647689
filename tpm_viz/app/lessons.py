"""Guided demonstrations for a lecture: pure data (frozen dataclasses) and the numbers behind each one.

Each :class:`Demo` sets the mechanism (parameter overrides of the paper's prototype, a pose or the start of a
motion, the assembly mode), the camera, the explorer map and the ellipses, and explains what to watch in one
paragraph. :func:`effect` computes, with the closed form only, the numbers that make the stated effect true
(forces growing towards the direct singularity, the workspace area shrinking, the 1/T² law, ...); the test
suite checks each of them, so the text cannot drift from the maths. No viser, no Pinocchio here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.moves import Pose
from tpm_viz.app.overlays import cached_map
from tpm_viz.app.runs import Source, build_run
from tpm_viz.errors import InputError
from tpm_viz.paper.ellipses import manipulability_ellipses
from tpm_viz.paper.jacobians import condition_number, jacobians
from tpm_viz.paper.kinematics import forward_kinematics, forward_kinematics_both
from tpm_viz.paper.workspace import workspace_area
from tpm_viz.params import Params

__all__ = ["DEMOS", "Camera", "Demo", "Motion", "demo_by_key", "demo_params", "demo_pose", "demo_source", "effect"]


@dataclass(frozen=True)
class Camera:
    """Camera position and look-at point [m] (Z up), centred on what the demo shows (the app shifts both
    sideways so that the scene is not hidden by its panel)."""

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]


@dataclass(frozen=True)
class Motion:
    """A trajectory for the player: the paper's ``"line"``/``"circle"`` or a ``"segment"`` start -> end [m]."""

    kind: str
    duration: float  # s
    start: tuple[float, float] | None = None
    end: tuple[float, float] | None = None


@dataclass(frozen=True)
class Demo:
    """One scene of the guided tour (SI units)."""

    key: str
    title: str
    text: str
    camera: Camera
    params: tuple[tuple[str, float], ...] = ()  # overrides of Params.paper()
    p: tuple[float, float] | None = None  # platform position, working mode (eq. 4)
    d: tuple[float, float] | None = None  # or actuator positions, with the assembly mode below
    mode: int = 1
    motion: Motion | None = None  # the pose is then the motion's start
    map_kind: str = "off"
    ellipses: bool = False
    compare: tuple[float, ...] = ()  # durations whose force peaks the effect compares


_Q3 = (-math.sqrt(0.5), -math.sqrt(0.5))  # unit vector towards the tangent-circle arc of eq. (12)
_LA = 0.260

DEMOS: tuple[Demo, ...] = (
    Demo(
        key="direct",
        title="1. Approach the direct singularity",
        text=(
            "The platform moves in a straight line from the centre towards the red quarter circle of the third "
            "quadrant, where cos(θ1+θ2) = 0 (eq. 12) and the two assembly modes merge. The cubic time law gives "
            "the same magnitude of acceleration at the start and at the end, so the difference between the "
            "forces there is the Jacobian's doing: as det J_x falls towards 0 the matrix of eq. (29) becomes "
            "nearly singular, the Lagrange multipliers grow and the actuators push several times harder for the "
            "same motion. Press Play and watch τ in the chart, the colour under the platform (det J_x map) and "
            "the velocity ellipse stretching along the direction the actuators no longer control."
        ),
        camera=Camera((-0.09, -0.42, 0.68), (-0.09, -0.1, 0.0)),
        motion=Motion("segment", 0.5, (0.0, 0.0), (0.95 * _LA * _Q3[0], 0.95 * _LA * _Q3[1])),
        map_kind="det_jx",
        ellipses=True,
    ),
    Demo(
        key="workspace",
        title="2. Shorter links, smaller workspace",
        text=(
            "The links are shortened from l_a = 260 mm to 200 mm. Every leg confines the platform to a circle of "
            "radius l_a about its slider, so the reachable square |p1|, |p2| < l_a shrinks with l_a², and the "
            "part of it the 300 mm stroke can serve (green) shrinks too. The red arcs and the amber square, the "
            "singularity loci, move inwards with l_a. (Between 260 and 240 mm the in-stroke area hardly changes: "
            "there the stroke, not the links, is the limit.) Parameters -> Paper values brings the prototype back."
        ),
        camera=Camera((-0.08, -0.33, 0.92), (-0.08, -0.06, 0.0)),
        params=(("l_a", 0.200),),
        p=(0.0, 0.0),
        map_kind="workspace",
    ),
    Demo(
        key="speed",
        title="3. The circle at two speeds",
        text=(
            "The circle of Fig. 5 is loaded with T = 0.5 s. Play it and note the force peak; then set the "
            "duration to 1.0 s in the Player and play again. The path is the same; every velocity is halved and "
            "every acceleration quartered. With no gravity and no friction every term of eqs. (29) and (31) is "
            "either an acceleration or a product of two velocities, so every force is divided by exactly 4: the "
            "peak force goes as 1/T². The Player's summary line keeps the previous run's peak for comparison."
        ),
        camera=Camera((-0.05, -0.5, 0.72), (-0.05, -0.1, 0.0)),
        motion=Motion("circle", 0.5),
        compare=(0.5, 1.0),
    ),
    Demo(
        key="agreement",
        title="4. Paper vs Pinocchio",
        text=(
            "The line of Fig. 4 (T = 0.2 s). Solid curves: the paper's closed form, eqs. (29)-(31). Dotted: an "
            "independent closed-loop multibody model built with Pinocchio from the same masses and lengths (all "
            "four parallelogram links, loop-closure constraints), playing the role ADAMS played in the paper. The "
            "paper reports agreement within 9 N; here the two agree to about 1e-13 N, once the paper's sign "
            "error in eq. (15) is corrected (see the Equations tab, errata): the dotted curves lie exactly on the "
            "solid ones."
        ),
        camera=Camera((-0.05, -0.5, 0.72), (-0.05, -0.1, 0.0)),
        motion=Motion("line", 0.2),
    ),
    Demo(
        key="modes",
        title="5. The two assembly modes",
        text=(
            "With both actuators at d = 50 mm the two leg circles (blue) meet twice: the mechanism can be "
            "assembled in two ways. The platform P is in the working mode (det J_x > 0); the translucent P′ is "
            "the other one (det J_x < 0), mirrored across the red arc. Move -> Switch assembly mode jumps between "
            "them. Drive both actuators down towards 22 mm (d1, d2 sliders): P and P′ approach each other and "
            "merge on the red arc, where the forward kinematics has a double root: the direct singularity, "
            "eq. (12). The det J_x map shows the sign change across the arc."
        ),
        camera=Camera((-0.17, -0.42, 0.75), (-0.17, -0.15, 0.0)),
        d=(0.050, 0.050),
        mode=1,
        map_kind="det_jx",
    ),
    Demo(
        key="inverse",
        title="6. Near an inverse singularity",
        text=(
            "Leg 1's links are almost perpendicular to its rail: cos θ1 → 0 (eq. 11), so J = J_q⁻¹ J_x blows up. "
            "Along leg 1's links (nearly along e2) a large slider speed buys only a small platform speed (the "
            "velocity ellipse, blue, collapses in that direction) while a small actuator force holds a large "
            "platform force (the force ellipse, orange, grows). With the paper's 300 mm stroke the only poses "
            "this close to an inverse singularity are in the corner of the third quadrant, beyond the "
            "direct-singularity arc; the condition-number map shows where the mechanism is well conditioned "
            "(light) and where it is not."
        ),
        camera=Camera((-0.2, -0.52, 0.74), (-0.2, -0.2, 0.0)),
        p=(-0.2252, -0.2582),
        map_kind="cond",
        ellipses=True,
    ),
)
"""The guided tour, in order."""


def demo_by_key(key: str) -> Demo:
    """The demo with this key."""
    for demo in DEMOS:
        if demo.key == key:
            return demo
    raise InputError(f"unknown demo {key!r}; known: {', '.join(d.key for d in DEMOS)}")


def demo_params(demo: Demo) -> Params:
    """The paper's prototype with the demo's overrides (validated)."""
    return Params.paper().replace(**dict(demo.params))


def demo_source(demo: Demo) -> Source | None:
    """The demo's trajectory for the player, if it has one."""
    m = demo.motion
    if m is None:
        return None
    if m.kind == "segment":
        return Source.segment(m.start, m.end, m.duration, label=f"{demo.title[3:].lower()}, T = {m.duration:g} s")
    return Source.paper(m.kind, m.duration)


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


def _tau_norms(params: Params, source: Source) -> tuple[float, float]:
    run = build_run(params, source, samples=201)
    return float(np.linalg.norm(run.tau[0])), float(np.linalg.norm(run.tau[-1]))


def effect(demo: Demo) -> str:
    """One line of numbers that shows the demo's effect (closed form; see the module docstring)."""
    params = demo_params(demo)
    if demo.key == "direct":
        source, motion = demo_source(demo), demo.motion
        assert source is not None and motion is not None  # the direct-singularity demo has a motion
        start, end = _tau_norms(params, source)
        det = float(jacobians(params, np.array(motion.end)).det_jx)
        return (
            f"|τ| at the start {start:.0f} N, at the end {end:.0f} N (×{end / start:.1f}) for the same |p̈|; "
            f"det J_x falls from 1.00 to {det:.2f}"
        )
    if demo.key == "workspace":
        before, after = cached_map(Params.paper()), cached_map(params)
        cm2 = 1e4
        return (
            f"in-stroke workspace {workspace_area(before) * cm2:.0f} → {workspace_area(after) * cm2:.0f} cm²; "
            f"reachable square {workspace_area(before, 'reachable') * cm2:.0f} → "
            f"{workspace_area(after, 'reachable') * cm2:.0f} cm² (l_a {Params.paper().l_a * 1e3:.0f} → "
            f"{params.l_a * 1e3:.0f} mm)"
        )
    if demo.key == "speed":
        t1, t2 = demo.compare
        p1, p2 = (build_run(params, Source.paper("circle", t), samples=401).peak for t in (t1, t2))
        return (
            f"peak |τ| {p1:.1f} N at T = {t1:g} s, {p2:.1f} N at T = {t2:g} s: ratio {p1 / p2:.3f} "
            f"= (T2/T1)² = {(t2 / t1) ** 2:.3f}"
        )
    if demo.key == "agreement":
        agreement = demo_source(demo)
        assert agreement is not None  # the agreement demo plays the paper's line
        run = build_run(params, agreement)
        return f"closed-form peak |τ| {run.peak:.1f} N; the Pinocchio curves are drawn dotted on top"
    if demo.key == "modes":
        assert demo.d is not None  # the assembly-modes demo is given by actuator positions
        sol = forward_kinematics_both(params, demo.d)
        mm = 1e3
        dets = [float(jacobians(params, q, demo.d).det_jx) for q in (sol.plus, sol.minus)]
        return (
            f"d = ({demo.d[0] * mm:.0f}, {demo.d[1] * mm:.0f}) mm: P = ({sol.plus[0] * mm:.1f}, {sol.plus[1] * mm:.1f})"
            f" mm with det J_x = {dets[0]:+.2f}, P′ = ({sol.minus[0] * mm:.1f}, {sol.minus[1] * mm:.1f}) mm with "
            f"det J_x = {dets[1]:+.2f}"
        )
    if demo.key == "inverse":
        pose = demo_pose(demo, params)
        jac = jacobians(params, pose.p)
        cos = np.array([jac.jq[0, 0], jac.jq[1, 1]])
        cond = float(condition_number(params, pose.p))
        ell = manipulability_ellipses(params, pose.p)
        v, f = ell.velocity.radii, ell.force.radii
        return (
            f"cos θ1 = {cos[0]:.3f}, cond J = {cond:.1f}; velocity ellipse {v.min():.2f} × {v.max():.2f}, "
            f"force ellipse {f.min():.2f} × {f.max():.2f} (per unit actuator speed / force)"
        )
    return ""
