"""The planner tab's pure side: a path chosen by name (or typed waypoints), its time-optimal cycle within
the force (and speed) limits, the sizing table, and the paper's cubic law scaled to the same peak force.

:func:`solve` is what the tab runs in its background worker at every slider change (~20-70 ms): the path (cached
per mechanism), :func:`~tpm_viz.app.planner.plan_cycle` (there and back; the circle: one turn with
:func:`~tpm_viz.app.planner.plan_path`), samples at 1 kHz, :func:`~tpm_viz.app.sizing.size_motion`. The cubic law
``s = L (3u² - 2u³)``, ``u = t / T`` (the paper's Figs. 4-5 time law) along the same strokes gives forces that
scale as ``1 / T²`` (no gravity, no friction), so the ``T`` with the same peak force is exact:
``T = sqrt(peak(T = 1) / peak)``.

:data:`INDUSTRY` are other robots' catalogue figures, for orientation only.
"""

from __future__ import annotations

import functools
import math
import re
import time
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.paths import GeometricPath, path_for
from tpm_viz.app.planner import Limits, Plan, PlanSamples, plan_cycle, plan_path
from tpm_viz.app.sizing import Sizing, size_motion, size_trajectory
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import parse_number, shorten
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.dynamics import inverse_dynamics

__all__ = [
    "INDUSTRY",
    "PATH_KINDS",
    "PlanResult",
    "cubic_strokes",
    "parse_waypoints",
    "solve",
]

PATH_KINDS = {"pick-and-place": "pick", "line (Fig. 4)": "line", "circle (Fig. 5)": "circle", "waypoints": "waypoints"}
"""Dropdown label -> :class:`~tpm_viz.app.paths.PathKind` value."""
INDUSTRY = (
    ("ABB IRB 360 FlexPicker (delta)", "25-305-25 mm cycle", "150 picks/min at 0.1-1 kg"),
    ("SCARA robots (typical)", "standard cycle", "0.33-0.35 s per cycle"),
)
"""Other robots' catalogue values (robot, cycle, figure), for orientation only."""
RATE = 1000.0  # Hz, samples of the plan and of the cubic law
MAX_WAYPOINTS = 50


def parse_waypoints(text: str) -> np.ndarray:
    """``"x,y; x,y; ..."`` in mm -> ``(n, 2)`` [m]; a one-line :class:`InputError` otherwise. Each coordinate is read
    with :func:`~tpm_viz.core.numbers.parse_number` (``1e2``, ``−60``; a comma separates, so no decimal comma)."""
    if not isinstance(text, str) or len(text) > 2000:
        raise InputError(Phrase("waypoints: type them as 'x,y; x,y' in mm"))
    points = []
    for k, item in enumerate(p for p in re.split(r"[;\n]", text) if p.strip()):
        parts = [v for v in re.split(r"[,\s]+", item.strip()) if v]
        try:
            if len(parts) != 2:
                raise InputError(item)
            x, y = (parse_number(v) for v in parts)  # the one parser: 1e2, the Unicode minus (commas separate)
        except InputError:
            raise InputError(
                Phrase("waypoint {k} ({text}) must be two numbers 'x,y' in mm", k=k + 1, text=shorten(item.strip()))
            ) from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(Phrase("waypoint {k} is not finite", k=k + 1))
        points.append((x * 1e-3, y * 1e-3))
    if not 2 <= len(points) <= MAX_WAYPOINTS:
        raise InputError(
            Phrase("give 2 to {most} waypoints 'x,y; x,y' in mm, got {n}", most=MAX_WAYPOINTS, n=len(points))
        )
    return np.array(points)


@functools.lru_cache(maxsize=32)
def _path(params: Params, kind: str, points: tuple[tuple[float, float], ...] | None) -> GeometricPath:
    return path_for(params, kind, None if points is None else np.array(points))


def _cubic_samples(params: Params, path: GeometricPath, duration: float, n: int = 201) -> tuple:
    """``(t, p, ṗ, p̈)`` of the cubic law ``s = L (3u² - 2u³)`` over ``duration`` [s] along ``path``."""
    u = np.linspace(0.0, 1.0, n)
    big = path.length
    s, ds, dds = big * (3 * u**2 - 2 * u**3), big * (6 * u - 6 * u**2) / duration, big * (6 - 12 * u) / duration**2
    ps, pss = path.evaluate(s, 1), path.evaluate(s, 2)
    dp = ps * ds[:, None]
    return u * duration, path.evaluate(s), dp, ps * dds[:, None] + pss * (ds**2)[:, None]


def cubic_strokes(params: Params, paths: tuple[GeometricPath, ...], peak: float) -> tuple[float, tuple]:
    """The cubic law's stroke time ``T`` [s] with peak force ``peak`` [N] along ``paths``, and its samples
    ``(t, p, ṗ, p̈)`` of all strokes back to back."""
    unit = [_cubic_samples(params, path, 1.0) for path in paths]
    peak1 = max(float(np.max(np.abs(inverse_dynamics(params, p, dp, ddp)))) for _t, p, dp, ddp in unit)
    if not (peak > 0 and math.isfinite(peak1) and peak1 > 0):
        raise InputError(Phrase("the cubic law has no force along this path"))
    duration = math.sqrt(peak1 / peak)
    parts = [_cubic_samples(params, path, duration) for path in paths]
    t = np.concatenate([part[0] + k * duration for k, part in enumerate(parts)])
    p, dp, ddp = (np.concatenate([part[j] for part in parts]) for j in (1, 2, 3))
    return duration, (t, p, dp, ddp)


@dataclass(frozen=True)
class PlanResult:
    """One solve of the planner tab."""

    kind: str
    plan: Plan
    samples: PlanSamples
    sizing: Sizing
    cubic: Sizing
    cubic_stroke: float  # [s] one stroke of the cubic law with the same peak force
    seconds: float  # wall time of the solve [s]

    @property
    def cycle_time(self) -> float:
        """Motion time of one cycle [s] (there and back; the circle: one turn)."""
        return self.sizing.cycle_time

    @property
    def per_minute(self) -> float:
        """Cycles (picks) per minute."""
        return 60.0 / self.cycle_time


@functools.lru_cache(maxsize=32)
def solve(params: Params, kind: str, force: float, speed: float | None = None, waypoints: str = "") -> PlanResult:
    """Plan the cycle of path ``kind`` (``pick``, ``line``, ``circle``, ``waypoints`` with the typed ``waypoints``
    in mm) within ``|τ_i| <= force`` [N] and ``|ṗ| <= speed`` [m/s] (None: no speed limit); size it and its cubic
    counterpart. Cached (the last 32 requests): a class arriving at once shares one plan of the default settings,
    and a slider dragged back and forth is answered at once."""
    t0 = time.perf_counter()
    points = None
    if kind == "waypoints":
        points = tuple(map(tuple, parse_waypoints(waypoints).tolist()))
    elif kind not in PATH_KINDS.values():
        raise InputError(Phrase("unknown path {kind}", kind=repr(kind)))
    path = _path(params, kind, points)
    limits = Limits(force, speed)
    plan = plan_path(params, path, limits) if kind == "circle" else plan_cycle(params, path, limits)
    samples = plan.samples(RATE)
    sizing = size_motion(samples.t, samples.tau, samples.dd, dp=samples.dp)
    stroke, (t, p, dp, ddp) = cubic_strokes(params, plan.paths, float(np.max(sizing.peak_force)))
    cubic = size_trajectory(params, t, p, dp, ddp)
    return PlanResult(kind, plan, samples, sizing, cubic, stroke, time.perf_counter() - t0)
