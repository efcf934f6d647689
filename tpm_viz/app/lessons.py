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
from tpm_viz.app.overlays import cached_map
from tpm_viz.app.readouts import Reference
from tpm_viz.app.runs import Run, build_run
from tpm_viz.errors import InputError
from tpm_viz.paper.ellipses import manipulability_ellipses
from tpm_viz.paper.jacobians import condition_number, jacobians
from tpm_viz.paper.kinematics import forward_kinematics_both
from tpm_viz.paper.workspace import workspace_area
from tpm_viz.params import Params

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
    def pose(self):
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
    def jac(self):
        return jacobians(self.params, self.pose.p, self.pose.d)

    @cached_property
    def ellipses(self):
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
    return float(np.linalg.norm(run.tau[k]))


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


def effect(demo: Demo) -> str:
    """One line of numbers that shows the lesson's effect (closed form; see the module docstring)."""
    s = _Scene(demo, None)
    key, mm = demo.key, 1e3
    if key == "direct" and demo.motion is not None:
        start, end = _tau(s.run, 0), _tau(s.run, -1)
        return (
            f"|τ| at the start {start:.0f} N, at the end {end:.0f} N (×{end / start:.1f}) for the same |p̈|; "
            f"det J_x falls from {CHECKS['det_jx_start'](s):.2f} to {CHECKS['det_jx_end'](s):.2f}"
        )
    if key == "workspace":
        paper = Params.paper()
        return (
            f"in-stroke workspace {s.area(paper, 'in_stroke'):.0f} → {s.area(s.params, 'in_stroke'):.0f} cm²; "
            f"reachable square {s.area(paper, 'reachable'):.0f} → {s.area(s.params, 'reachable'):.0f} cm² "
            f"(l_a {paper.l_a * mm:.0f} → {s.params.l_a * mm:.0f} mm)"
        )
    if key == "speed" and len(demo.compare) == 2:
        (t1, t2), p1, p2 = demo.compare, s.peak_at(0), s.peak_at(1)
        return (
            f"peak |τ| {p1:.1f} N at T = {t1:g} s, {p2:.1f} N at T = {t2:g} s: ratio {p1 / p2:.3f} "
            f"= (T2/T1)² = {(t2 / t1) ** 2:.3f}"
        )
    if key == "agreement" and demo.motion is not None:
        return f"closed-form peak |τ| {s.run.peak:.1f} N; the Pinocchio curves are drawn dotted on top"
    if key == "modes" and demo.d is not None:
        p, q = s.pose.p * mm, s.other * mm
        return (
            f"d = ({demo.d[0] * mm:.0f}, {demo.d[1] * mm:.0f}) mm: P = ({p[0]:.1f}, {p[1]:.1f}) mm with "
            f"det J_x = {CHECKS['det_jx'](s):+.2f}, P′ = ({q[0]:.1f}, {q[1]:.1f}) mm with "
            f"det J_x = {CHECKS['other_det_jx'](s):+.2f}"
        )
    if key == "inverse" and demo.motion is None:
        v, f = s.ellipses.velocity.radii, s.ellipses.force.radii
        return (
            f"cos θ1 = {CHECKS['cos_theta1'](s):.3f}, cond J = {CHECKS['cond'](s):.1f}; velocity ellipse "
            f"{v.min():.2f} × {v.max():.2f}, force ellipse {f.min():.2f} × {f.max():.2f} (per unit actuator "
            "speed / force)"
        )
    return _stated(demo)
