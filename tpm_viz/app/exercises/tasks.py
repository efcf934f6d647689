"""The computations an exercise file names: reference answers, the alternatives that mistakes match, pose checks.

A file never types a reference answer: it names a computation of these registries (``answer = "tau1"``), and the
library computes the value from the variant with the closed form (eqs. 4, 11-12, 28-31; no Pinocchio). Values are
SI (m, N, rad); the exercise's ``unit`` says what the student types.

- :data:`NUMBER_TASKS`: one number (:class:`NumberTask`);
- :data:`POSE_TASKS`: a quantity checked at the pose the student gives (:class:`PoseTask`), with one pose that
  passes (the reference a lecturer may reveal; every other passing pose scores too);
- :data:`CHOICE_TASKS`: the key of the right option (:class:`ChoiceTask`);
- the ``gains`` task (a closed-loop simulation) is in :mod:`tpm_viz.app.exercises.gains`.

:func:`pose_problem` and :func:`pose_warning` are the pose rules: a pose out of reach, outside the stroke or in the
other assembly mode (``det J_x < 0``) cannot be read as an answer (a format error); one near a singularity by the
app's warning thresholds (:data:`~tpm_viz.paper.status.WARN`: ``|cos θ_i|`` or ``cos(θ1 + θ2)`` below 0.2) is read
and scores 0.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.exercises.model import Variant
from tpm_viz.app.runs import Source, build_run
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.status import WARN

__all__ = [
    "CHOICE_TASKS",
    "NUMBER_TASKS",
    "POSE_TASKS",
    "ChoiceTask",
    "NumberTask",
    "PoseTask",
    "circle_peak",
    "pose_problem",
    "pose_warning",
    "zero_pose",
]

MARGIN = 0.05
"""How far inside the warning thresholds (on ``|cos θ_i|`` and ``cos(θ1 + θ2)``) a drawn or reference pose stays."""
STROKE_MARGIN = 0.002
"""How far inside the stroke [m] a drawn or reference pose stays."""
MASSLESS = 1e-9
"""Slider and link mass [kg] of the "platform only" mistake (the smallest :class:`~tpm_viz.Params` accepts)."""


@dataclass(frozen=True)
class NumberTask:
    """A number [SI] of ``quantity`` (a :data:`~tpm_viz.core.numbers.UNITS` quantity; None: dimensionless), from the
    inputs ``needs``; ``usable`` refuses drawn numbers it cannot use; ``shows`` are computed values a prompt may
    show (``{name}``: the value as text)."""

    quantity: str | None
    needs: tuple[str, ...]
    value: Callable[[Variant], float]
    usable: Callable[[Variant], bool] | None = None
    shows: tuple[tuple[str, Callable[[Variant], str]], ...] = ()


@dataclass(frozen=True)
class PoseTask:
    """A quantity ``symbol`` [``unit``] computed at the pose ``p`` [m] a student gives (working mode, ``ṗ = 0``),
    which must be ``target`` within the exercise's tolerance; ``reference`` finds one pose that passes (None)."""

    symbol: str
    unit: str
    needs: tuple[str, ...]
    quantity: Callable[[Variant, np.ndarray], float]
    reference: Callable[[Variant], np.ndarray | None]
    target: float = 0.0

    def usable(self, variant: Variant) -> bool:
        return self.reference(variant) is not None


@dataclass(frozen=True)
class ChoiceTask:
    """The key of the right option among ``keys``."""

    keys: tuple[str, ...]
    needs: tuple[str, ...]
    value: Callable[[Variant], str]
    usable: Callable[[Variant], bool] | None = None


# ----------------------------------------------------------------------------- pose rules
def _mm(x: float) -> str:
    return fixed(x, ".1f", 1e3)


def _legs(params: Params, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``d`` (eq. 4), ``cos θ_i`` (eq. 23) and ``cos(θ1 + θ2)`` (eq. 12) at a reachable pose ``p`` [m]."""
    la = params.l_a
    c = np.sqrt(la**2 - p[::-1] ** 2)
    return p + params.offset - c, c / la, float((c[0] * c[1] - p[0] * p[1]) / la**2)


def pose_problem(params: Params, p: np.ndarray) -> Phrase | None:
    """Why ``p`` [m] cannot be an answer (out of reach, outside the stroke, the other assembly mode), or None."""
    x, y = _mm(p[0]), _mm(p[1])
    if not (np.all(np.isfinite(p)) and np.all(np.abs(p) < params.l_a)):
        return Phrase(
            "({x}, {y}) mm is out of reach: each |p_j| must be below l_a = {l_a} mm", x=x, y=y, l_a=_mm(params.l_a)
        )
    d, _, det = _legs(params, p)
    for i in (0, 1):
        if not -1e-12 <= d[i] <= params.stroke + 1e-12:
            return Phrase(
                "at ({x}, {y}) mm actuator {i} would be at d{i} = {d} mm, outside the stroke 0 to {stroke} mm",
                x=x,
                y=y,
                i=i + 1,
                d=_mm(d[i]),
                stroke=_mm(params.stroke),
            )
    if det <= 0.0:
        return Phrase(
            "({x}, {y}) mm is in the other assembly mode (det J_x = {det}, beyond the red arc): give a pose of the "
            "working mode",
            x=x,
            y=y,
            det=fixed(det, ".2f"),
        )
    return None


def pose_warning(params: Params, p: np.ndarray, margin: float = 0.0) -> Phrase | None:
    """Why the readable pose ``p`` [m] is too near a singularity (the app's warning thresholds raised by
    ``margin``), or None."""
    _, cos, det = _legs(params, p)
    x, y = _mm(p[0]), _mm(p[1])
    i = int(np.argmin(np.abs(cos)))
    if abs(cos[i]) < WARN.inverse + margin:
        return Phrase(
            "({x}, {y}) mm is near the inverse singularity (cos θ{i} = {cos}, below {limit}): choose a pose clear of "
            "it",
            x=x,
            y=y,
            i=i + 1,
            cos=fixed(cos[i], ".2f"),
            limit=fixed(WARN.inverse, ".1f"),
        )
    if abs(det) < WARN.direct + margin:
        return Phrase(
            "({x}, {y}) mm is near the direct singularity (det J_x = {det}, below {limit}): choose a pose clear of it",
            x=x,
            y=y,
            det=fixed(det, ".2f"),
            limit=fixed(WARN.direct, ".1f"),
        )
    return None


def _pose(v: Variant) -> np.ndarray:
    return np.array([v["p1"], v["p2"]])


def _regular(v: Variant) -> bool:
    """The drawn pose is readable and clear of both singularities with :data:`MARGIN` to spare."""
    p, params = _pose(v), v.params
    if pose_problem(params, p) is not None or pose_warning(params, p, MARGIN) is not None:
        return False
    d = _legs(params, p)[0]
    return bool(np.all(d >= STROKE_MARGIN) and np.all(d <= params.stroke - STROKE_MARGIN))


# ----------------------------------------------------------------------------- forces (eqs. 28-31, ṗ = 0)
def _tau(params: Params, p: np.ndarray, ddp: np.ndarray) -> np.ndarray:
    return inverse_dynamics(params, p, np.zeros(2), ddp)


def _ddp(v: Variant) -> np.ndarray:
    return np.array([v["ddp1"], v["ddp2"]])


def _force(i: int, platform_only: bool = False) -> Callable[[Variant], float]:
    def value(v: Variant) -> float:
        params = v.params.replace(m_a=MASSLESS, m_b=MASSLESS) if platform_only else v.params
        return float(_tau(params, _pose(v), _ddp(v))[i])

    return value


def _force_at(i: int) -> Callable[[Variant, np.ndarray], float]:
    return lambda v, p: float(_tau(v.params, p, _ddp(v))[i])


@functools.lru_cache(maxsize=256)
def zero_pose(variant: Variant, i: int) -> np.ndarray | None:
    """A pose [m] where ``τ_i = 0`` at the variant's ``p̈`` (``ṗ = 0``): on a 99 x 99 grid of the reachable square,
    the sign changes of ``τ_i`` between neighbours inside the valid set (with :data:`MARGIN` and
    :data:`STROKE_MARGIN`), the one with the widest margin, refined by bisection; None if there is none."""
    params, ddp = variant.params, _ddp(variant)
    la = params.l_a
    axis = np.linspace(-0.98 * la, 0.98 * la, 99)
    grid = np.stack(np.meshgrid(axis, axis), -1)
    c = np.sqrt(la**2 - grid[..., ::-1] ** 2)
    d = grid + params.offset - c
    det = (c[..., 0] * c[..., 1] - grid[..., 0] * grid[..., 1]) / la**2
    room = np.minimum.reduce(
        [
            np.min(c, -1) / la - WARN.inverse - MARGIN,
            det - WARN.direct - MARGIN,
            (np.min(np.minimum(d, params.stroke - d), -1) - STROKE_MARGIN) / la,
        ]
    )
    ok = room > 0
    tau = np.where(ok, _tau(params, np.where(ok[..., None], grid, 0.0), ddp)[..., i], np.nan)
    left, right = tau[:, :-1], tau[:, 1:]
    cross = ok[:, :-1] & ok[:, 1:] & (left * right <= 0.0)
    if not np.any(cross):
        return None
    scores = np.where(cross, np.minimum(room[:, :-1], room[:, 1:]), -np.inf)
    row, col = np.unravel_index(int(np.argmax(scores)), scores.shape)
    y, lo, hi = axis[row], axis[col], axis[col + 1]
    f_lo = float(_tau(params, np.array([lo, y]), ddp)[i])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        f_mid = float(_tau(params, np.array([mid, y]), ddp)[i])
        if (f_mid <= 0.0) == (f_lo <= 0.0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    exact = np.array([0.5 * (lo + hi), y])
    rounded = np.round(exact, 5)  # 0.01 mm: a pose that reads well
    tol = variant["tol"] if "tol" in dict(variant.inputs) else 0.0
    keep = abs(float(_tau(params, rounded, ddp)[i])) <= 0.25 * tol
    return rounded if keep else exact


# ----------------------------------------------------------------------------- the circle at two speeds
@functools.lru_cache(maxsize=64)
def circle_peak(params: Params, duration: float) -> float:
    """Peak ``max |τ_i|`` [N] of the paper's circle in ``duration`` [s], as the Player computes it."""
    return build_run(params, Source.paper("circle", duration)).peak


def _peak(v: Variant, which: str) -> float:
    return circle_peak(v.params, v[which])


# ----------------------------------------------------------------------------- registries
def _sq(params: Params, x: float) -> float:
    return math.sqrt(params.l_a**2 - x**2)


def _merge_d(v: Variant) -> float:
    """``d = a - b - √2 l_a``: eq. (4) at the diagonal's direct singularity ``p1 = p2 = -l_a / √2``."""
    return v.params.offset - math.sqrt(2.0) * v.params.l_a


def _merge_in_stroke(v: Variant) -> bool:
    return STROKE_MARGIN <= _merge_d(v) <= v.params.stroke - STROKE_MARGIN


NUMBER_TASKS: dict[str, NumberTask] = {
    "tau1": NumberTask("force", ("p1", "p2", "ddp1", "ddp2"), _force(0), _regular),
    "tau2": NumberTask("force", ("p1", "p2", "ddp1", "ddp2"), _force(1), _regular),
    "tau1_platform_only": NumberTask("force", ("p1", "p2", "ddp1", "ddp2"), _force(0, True), _regular),
    "diagonal_singularity": NumberTask("length", (), lambda v: -v.params.l_a / math.sqrt(2.0)),
    "diagonal_singularity_d": NumberTask("length", (), _merge_d, _merge_in_stroke),
    "l_a": NumberTask("length", (), lambda v: v.params.l_a),
    "minus_l_a": NumberTask("length", (), lambda v: -v.params.l_a),
    "d1": NumberTask("length", ("p1", "p2"), lambda v: v["p1"] + v.params.offset - _sq(v.params, v["p2"]), _regular),
    "d2": NumberTask("length", ("p1", "p2"), lambda v: v["p2"] + v.params.offset - _sq(v.params, v["p1"]), _regular),
    "d1_other_branch": NumberTask(
        "length", ("p1", "p2"), lambda v: v["p1"] + v.params.offset + _sq(v.params, v["p2"]), _regular
    ),
    "d1_no_offset": NumberTask("length", ("p1", "p2"), lambda v: v["p1"] - _sq(v.params, v["p2"]), _regular),
    "theta1": NumberTask("angle", ("p1", "p2"), lambda v: math.asin(v["p2"] / v.params.l_a), _regular),
    "theta2": NumberTask("angle", ("p1", "p2"), lambda v: math.asin(v["p1"] / v.params.l_a), _regular),
    "theta1_from_e2": NumberTask("angle", ("p1", "p2"), lambda v: math.acos(v["p2"] / v.params.l_a), _regular),
    "circle_peak_t2": NumberTask(
        "force", ("t1", "t2"), lambda v: _peak(v, "t2"), shows=(("peak1", lambda v: fixed(_peak(v, "t1"))),)
    ),
    "circle_peak_t1": NumberTask("force", ("t1", "t2"), lambda v: _peak(v, "t1")),
    "circle_peak_linear": NumberTask("force", ("t1", "t2"), lambda v: _peak(v, "t1") * v["t1"] / v["t2"]),
    "circle_peak_inverse": NumberTask("force", ("t1", "t2"), lambda v: _peak(v, "t1") * (v["t2"] / v["t1"]) ** 2),
}
"""The numbers an exercise may ask for (the reference) or a mistake may match (an alternative), by name."""

POSE_TASKS: dict[str, PoseTask] = {
    "tau1_zero": PoseTask("τ₁", "N", ("ddp1", "ddp2", "tol"), _force_at(0), lambda v: zero_pose(v, 0)),
    "tau2_zero": PoseTask("τ₂", "N", ("ddp1", "ddp2", "tol"), _force_at(1), lambda v: zero_pose(v, 1)),
}
"""The checks of a pose answer, by name."""


def _nearer_leg(v: Variant) -> str:
    """Leg ``i`` is nearer its inverse singularity when ``|cos θ_i|`` is smaller: ``sin θ_1 = p_2 / l_a``."""
    _, cos, _ = _legs(v.params, _pose(v))
    return "leg1" if abs(cos[0]) < abs(cos[1]) else "leg2"


def _distinct_legs(v: Variant) -> bool:
    p = _pose(v)
    return pose_problem(v.params, p) is None and abs(abs(p[0]) - abs(p[1])) >= 0.01


CHOICE_TASKS: dict[str, ChoiceTask] = {
    "nearer_inverse_leg": ChoiceTask(("leg1", "leg2"), ("p1", "p2"), _nearer_leg, _distinct_legs),
}
"""The choices, by name."""
