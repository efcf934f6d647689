"""Guided demonstrations for a lecture: the packaged tour (``assets/lessons/*.toml``) and the numbers behind it.

The lessons are data files (format: ``assets/lessons/README.md``), read by :mod:`tpm_viz.app.lesson_files` into
the frozen dataclasses of :mod:`tpm_viz.app.demos`; :data:`DEMOS` is the packaged tour and :data:`PROBLEMS` says
which packaged file was refused, if any (a lecturer's folder is read with :func:`load_lessons`). Each lesson may
state numbers in ``[checks]``; :func:`check_values` recomputes them from its scene with the closed form only and
:func:`verify` compares (the test suite runs it on every lesson, so the text cannot drift from the maths).
:func:`effect` is the line of numbers shown under a lesson's paragraph. No viser, no Pinocchio here (the reference
model is passed in as a function).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from functools import cached_property

import numpy as np

from tpm_viz.app.demos import CHECK_NAMES, Camera, Check, Demo, Motion, demo_params, demo_pose, demo_source
from tpm_viz.app.lesson_files import assets_dir, load_lesson, load_lessons, load_preset
from tpm_viz.app.moves import Pose
from tpm_viz.app.overlays import cached_map
from tpm_viz.app.readouts import Reference
from tpm_viz.app.runs import Run, build_run
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.ellipses import ManipulabilityEllipses, manipulability_ellipses
from tpm_viz.paper.jacobians import Jacobians, condition_number, jacobians
from tpm_viz.paper.kinematics import forward_kinematics_both
from tpm_viz.paper.workspace import workspace_area

__all__ = [
    "CHECKS",
    "DEMOS",
    "PROBLEMS",
    "Camera",
    "Check",
    "Demo",
    "Motion",
    "assets_dir",
    "check_values",
    "demo_by_key",
    "demo_params",
    "demo_pose",
    "demo_source",
    "effect",
    "load_lesson",
    "load_lessons",
    "load_preset",
    "tolerance",
    "verify",
]

DEMOS, PROBLEMS = load_lessons(assets_dir() / "lessons")
"""The guided tour, in file-name order, and the packaged files refused (empty when the package is sound)."""

CM2 = 1e4  # cm² per m²


class _Scene:
    """What the checks of one lesson are computed from, each part computed once and only if asked for."""

    def __init__(self, demo: Demo, reference: Reference | None) -> None:
        self.demo = demo
        self.params = demo_params(demo)
        self.reference = reference

    @cached_property
    def pose(self) -> Pose:
        return demo_pose(self.demo, self.params)

    @cached_property
    def run(self) -> Run:
        source = demo_source(self.demo)
        if source is None:
            raise InputError(f"lesson {self.demo.key!r} has no motion to check")
        return build_run(self.params, source, self.reference)

    def peak_at(self, index: int) -> float:
        if len(self.demo.compare) != 2:
            raise InputError(f"lesson {self.demo.key!r}: peak_ratio needs motion.compare = [T1, T2]")
        source = demo_source(self.demo, self.demo.compare[index])
        assert source is not None  # compare needs a motion (lesson_files)
        return build_run(self.params, source).peak

    @cached_property
    def jac(self) -> Jacobians:
        return jacobians(self.params, self.pose.p, self.pose.d)

    @cached_property
    def ellipses(self) -> ManipulabilityEllipses:
        return manipulability_ellipses(self.params, self.pose.p)

    @cached_property
    def other(self) -> np.ndarray:
        sol = forward_kinematics_both(self.params, self.pose.d)
        return np.asarray(sol.minus if self.pose.mode(self.params) > 0 else sol.plus, dtype=float)

    def reference_gap(self) -> float:
        if self.reference is None:
            raise InputError("reference_gap needs the reference (Pinocchio) model")
        run = self.run
        assert run.tau_ref is not None, run.ref_note
        return float(np.max(np.abs(run.tau_ref - run.tau)))

    def area(self, params: Params, which: str) -> float:
        return workspace_area(cached_map(params), which) * CM2


def _tau(run: Run, k: int) -> float:
    """The larger actuator force ``max_i |τ_i|`` [N] at sample ``k``: what the panel and the Player show, per
    actuator (never the norm of the vector)."""
    return float(np.max(np.abs(run.tau[k])))


CHECKS: dict[str, Callable[[_Scene], float]] = {
    "det_jx_start": lambda s: float(jacobians(s.params, s.run.p[0]).det_jx),
    "det_jx_end": lambda s: float(jacobians(s.params, s.run.p[-1]).det_jx),
    "force_start": lambda s: _tau(s.run, 0),
    "force_end": lambda s: _tau(s.run, -1),
    "force_ratio": lambda s: _tau(s.run, -1) / _tau(s.run, 0),
    "peak_force": lambda s: s.run.peak,
    "peak_ratio": lambda s: s.peak_at(0) / s.peak_at(1),
    "reference_gap": _Scene.reference_gap,
    "det_jx": lambda s: float(s.jac.det_jx),
    "cos_theta1": lambda s: float(s.jac.jq[0, 0]),
    "cos_theta2": lambda s: float(s.jac.jq[1, 1]),
    "cond": lambda s: float(condition_number(s.params, s.pose.p)),
    "velocity_min": lambda s: float(s.ellipses.velocity.radii.min()),
    "velocity_max": lambda s: float(s.ellipses.velocity.radii.max()),
    "force_ellipse_min": lambda s: float(s.ellipses.force.radii.min()),
    "force_ellipse_max": lambda s: float(s.ellipses.force.radii.max()),
    "p1_mm": lambda s: float(s.pose.p[0]) * 1e3,
    "p2_mm": lambda s: float(s.pose.p[1]) * 1e3,
    "other_p1_mm": lambda s: float(s.other[0]) * 1e3,
    "other_p2_mm": lambda s: float(s.other[1]) * 1e3,
    "other_det_jx": lambda s: float(jacobians(s.params, s.other, s.pose.d).det_jx),
    "workspace_cm2": lambda s: s.area(s.params, "in_stroke"),
    "reachable_cm2": lambda s: s.area(s.params, "reachable"),
    "paper_workspace_cm2": lambda s: s.area(Params.paper(), "in_stroke"),
    "paper_reachable_cm2": lambda s: s.area(Params.paper(), "reachable"),
}
"""How each number a lesson may state (:data:`~tpm_viz.app.demos.CHECK_NAMES`) is computed from its scene."""


def check_values(demo: Demo, names: Iterable[str] | None = None, reference: Reference | None = None) -> dict:
    """The numbers ``names`` (default: the lesson's ``[checks]``) recomputed from the lesson's scene (closed form;
    ``reference`` only for ``reference_gap``)."""
    scene = _Scene(demo, reference)
    wanted = [c.name for c in demo.checks] if names is None else list(names)
    for name in wanted:
        if name not in CHECKS:
            raise InputError(f"unknown check {name!r}; known: {', '.join(CHECKS)}")
    return {name: CHECKS[name](scene) for name in wanted}


def tolerance(check: Check) -> float:
    """The accepted absolute difference: the check's ``tol``, else 0.5 % of the stated value or 0.005."""
    return check.tol if check.tol is not None else max(0.005 * abs(check.value), 0.005)


def verify(demo: Demo, reference: Reference | None = None) -> list[str]:
    """One line per stated number that the scene does not bear out (``reference_gap`` is skipped without
    ``reference``); empty when the lesson is right."""
    checks = [c for c in demo.checks if reference is not None or c.name != "reference_gap"]
    values = check_values(demo, [c.name for c in checks], reference)
    return [
        f"{demo.source or demo.key}: checks.{c.name} states {c.value:g}, the scene gives {values[c.name]:.6g} "
        f"(tolerance {tolerance(c):g})"
        for c in checks
        if not abs(values[c.name] - c.value) <= tolerance(c)
    ]


def demo_by_key(key: str, lessons: Iterable[Demo] = DEMOS) -> Demo:
    """The lesson with this key."""
    lessons = tuple(lessons)
    for demo in lessons:
        if demo.key == key:
            return demo
    raise InputError(f"unknown demo {key!r}; known: {', '.join(d.key for d in lessons)}")


def _stated(demo: Demo) -> str:
    """A lesson of a lecturer's own: its stated numbers, as recomputed."""
    checks = [c for c in demo.checks if c.name != "reference_gap"]
    values = check_values(demo, [c.name for c in checks])
    return "; ".join(f"{CHECK_NAMES[c.name].split(' [')[0]}: {values[c.name]:.4g}" for c in checks)


def effect(demo: Demo) -> Phrase | str:
    """One line of numbers that shows the lesson's effect (closed form; see the module docstring), written as the
    panel and the Player write them: actuator forces per actuator (``τ_i`` [N], ``|τ_i|``), never as a norm."""
    s = _Scene(demo, None)
    key, mm = demo.key, 1e3
    if key == "direct" and demo.motion is not None:
        start, end = s.run.tau[0], s.run.tau[-1]
        return Phrase(
            "τ = ({a1}, {a2}) N at the start, ({b1}, {b2}) N at the end: the larger |τ_i| grows ×{ratio} for the same "
            "|p̈|; det J_x falls from {det0} to {det1}",
            a1=fixed(start[0]),
            a2=fixed(start[1]),
            b1=fixed(end[0]),
            b2=fixed(end[1]),
            ratio=fixed(CHECKS["force_ratio"](s)),
            det0=fixed(CHECKS["det_jx_start"](s), ".2f"),
            det1=fixed(CHECKS["det_jx_end"](s), ".2f"),
        )
    if key == "workspace":
        paper = Params.paper()
        return Phrase(
            "in-stroke workspace {w0} → {w1} cm²; reachable square {r0} → {r1} cm² (l_a {l0} → {l1} mm)",
            w0=fixed(s.area(paper, "in_stroke"), ".0f"),
            w1=fixed(s.area(s.params, "in_stroke"), ".0f"),
            r0=fixed(s.area(paper, "reachable"), ".0f"),
            r1=fixed(s.area(s.params, "reachable"), ".0f"),
            l0=fixed(paper.l_a * mm, ".0f"),
            l1=fixed(s.params.l_a * mm, ".0f"),
        )
    if key == "speed" and len(demo.compare) == 2:
        (t1, t2), p1, p2 = demo.compare, s.peak_at(0), s.peak_at(1)
        return Phrase(
            "peak |τ_i| {p1} N at T = {t1} s, {p2} N at T = {t2} s: ratio {ratio} = (T2/T1)² = {law}",
            p1=fixed(p1),
            t1=fixed(t1, "g"),
            p2=fixed(p2),
            t2=fixed(t2, "g"),
            ratio=fixed(p1 / p2, ".3f"),
            law=fixed((t2 / t1) ** 2, ".3f"),
        )
    if key == "agreement" and demo.motion is not None:
        return Phrase(
            "closed-form peak |τ_i| {peak} N; the Pinocchio curves are drawn dotted on top", peak=fixed(s.run.peak)
        )
    if key == "modes" and demo.d is not None:
        p, q = s.pose.p * mm, s.other * mm
        return Phrase(
            "d = ({d1}, {d2}) mm: P = ({p1}, {p2}) mm with det J_x = {det}, P′ = ({q1}, {q2}) mm with "
            "det J_x = {other}",
            d1=fixed(demo.d[0] * mm, ".0f"),
            d2=fixed(demo.d[1] * mm, ".0f"),
            p1=fixed(p[0]),
            p2=fixed(p[1]),
            det=fixed(CHECKS["det_jx"](s), "+.2f"),
            q1=fixed(q[0]),
            q2=fixed(q[1]),
            other=fixed(CHECKS["other_det_jx"](s), "+.2f"),
        )
    if key == "inverse" and demo.motion is None:
        v, f = s.ellipses.velocity.radii, s.ellipses.force.radii
        return Phrase(
            "cos θ1 = {cos}, cond J = {cond}; velocity ellipse {v0} × {v1}, force ellipse {f0} × {f1} (per unit "
            "actuator speed / force)",
            cos=fixed(CHECKS["cos_theta1"](s), ".3f"),
            cond=fixed(CHECKS["cond"](s)),
            v0=fixed(v.min(), ".2f"),
            v1=fixed(v.max(), ".2f"),
            f0=fixed(f.min(), ".2f"),
            f1=fixed(f.max(), ".2f"),
        )
    return _stated(demo)
