"""Platform trajectories: the paper's cubic line and circle (Figs. 4-5) and users' CSV paths.

Time law (``docs/conventions.md``): the path parameter follows the cubic polynomial
``s(τ) = 3τ² - 2τ³`` with ``τ = t / T``, so velocity is zero at both ends.

- Line (Fig. 4): from (-100, -50) mm to (+100, +50) mm, default ``T = 0.2 s``.
- Circle (Fig. 5): centre (0, 0), radius 100 mm, from (+100, 0) mm, one counter-clockwise
  turn, the cubic law on the polar angle ``φ = 2π s``; default ``T = 0.5 s``.

Positions, velocities and accelerations are exact (analytic derivatives).
A user's path (timed samples ``t, p1, p2``) is differentiated through a natural cubic spline
(:mod:`tpm_viz.paper.spline`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import SupportsFloat

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.csvio import parse_columns
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.spline import CubicSpline

__all__ = [
    "DEFAULT_DURATIONS",
    "Trajectory",
    "circle_state",
    "line_state",
    "paper_duration",
    "paper_trajectory",
    "parse_trajectory_csv",
    "positive_seconds",
    "trajectory_from_samples",
]

DEFAULT_DURATIONS = {"line": 0.2, "circle": 0.5}
"""Default durations [s] of the paper's trajectories (``docs/conventions.md``)."""

LINE_START = (-0.100, -0.050)
LINE_END = (0.100, 0.050)
CIRCLE_CENTRE = (0.0, 0.0)
CIRCLE_RADIUS = 0.100
MAX_SAMPLES = 1_000_000
MAX_CSV_ROWS = 100_000
"""Most data rows in a trajectory CSV (a natural cubic spline through them)."""

State = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
"""``(p, ṗ, p̈)`` [m, m/s, m/s²] (or ``(s, ṡ, s̈)`` of the time law), each shaped like the times given."""


@dataclass(frozen=True)
class Trajectory:
    """A sampled platform trajectory: times ``t`` [s] ``(n,)``; ``p, dp, ddp`` ``(n, 2)`` in SI."""

    name: str
    t: np.ndarray
    p: np.ndarray
    dp: np.ndarray
    ddp: np.ndarray

    @property
    def duration(self) -> float:
        """Duration [s] from the first to the last sample."""
        return float(self.t[-1] - self.t[0])


def positive_seconds(value: str | SupportsFloat, what: str | Phrase = T("duration")) -> float:
    """``value`` as a positive, finite number of seconds, or a one-line :class:`InputError` naming ``what``."""
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(Phrase("{what} must be a number of seconds, got {got}", what=what, got=repr(value))) from None
    if not math.isfinite(value) or value <= 0:
        raise InputError(
            Phrase("{what} must be a positive, finite number of seconds, got {got:g}", what=what, got=value)
        )
    return value


def paper_duration(kind: str, duration: float | None = None) -> float:
    """The validated duration [s] of the paper's ``kind`` trajectory (its default when ``duration`` is None)."""
    if kind not in DEFAULT_DURATIONS:
        raise InputError(Phrase("trajectory kind must be 'line' or 'circle', got {kind}", kind=repr(kind)))
    return DEFAULT_DURATIONS[kind] if duration is None else positive_seconds(duration)


def _check_samples(samples: int) -> int:
    if isinstance(samples, bool) or int(samples) != samples or not 2 <= samples <= MAX_SAMPLES:
        raise InputError(
            Phrase("samples must be a whole number from 2 to {most}, got {got}", most=MAX_SAMPLES, got=repr(samples))
        )
    return int(samples)


def _cubic_law(t: ArrayLike, duration: float) -> State:
    """``s, ṡ, s̈`` of ``s(τ) = 3τ² - 2τ³`` at times ``t``; at rest before 0 and after ``T``.

    On the closed interval ``[0, T]`` these are the polynomial's values, so ``s̈(0) = 6/T²`` and
    ``s̈(T) = -6/T²``: the acceleration (and the actuator force) jumps at the start and the end.
    """
    raw = np.asarray(t, dtype=float) / duration
    tau = np.clip(raw, 0.0, 1.0)
    s = 3 * tau**2 - 2 * tau**3
    ds = (6 * tau - 6 * tau**2) / duration
    dds = np.where((raw >= 0) & (raw <= 1), (6 - 12 * tau) / duration**2, 0.0)
    return s, ds, dds


def line_state(
    t: ArrayLike, duration: float = DEFAULT_DURATIONS["line"], start: ArrayLike = LINE_START, end: ArrayLike = LINE_END
) -> State:
    """``(p, ṗ, p̈)`` on the straight line at times ``t`` [s]; each of shape ``t.shape + (2,)``."""
    duration = positive_seconds(duration)
    s, ds, dds = _cubic_law(t, duration)
    start, delta = np.asarray(start, float), np.asarray(end, float) - np.asarray(start, float)
    return start + s[..., None] * delta, ds[..., None] * delta, dds[..., None] * delta


def circle_state(
    t: ArrayLike,
    duration: float = DEFAULT_DURATIONS["circle"],
    centre: ArrayLike = CIRCLE_CENTRE,
    radius: float = CIRCLE_RADIUS,
) -> State:
    """``(p, ṗ, p̈)`` on the circle at times ``t`` [s] (polar angle ``φ = 2π s(t/T)``)."""
    duration = positive_seconds(duration)
    s, ds, dds = _cubic_law(t, duration)
    phi, dphi, ddphi = 2 * np.pi * s, 2 * np.pi * ds, 2 * np.pi * dds
    radial = np.stack([np.cos(phi), np.sin(phi)], -1)
    tangent = np.stack([-np.sin(phi), np.cos(phi)], -1)
    p = np.asarray(centre, float) + radius * radial
    dp = radius * dphi[..., None] * tangent
    ddp = radius * ddphi[..., None] * tangent - radius * dphi[..., None] ** 2 * radial
    return p, dp, ddp


def paper_trajectory(kind: str, duration: float | None = None, samples: int = 201) -> Trajectory:
    """The paper's ``"line"`` (Fig. 4) or ``"circle"`` (Fig. 5) sampled at ``samples`` times."""
    duration = paper_duration(kind, duration)
    t = np.linspace(0.0, duration, _check_samples(samples))
    state = line_state if kind == "line" else circle_state
    p, dp, ddp = state(t, duration)
    return Trajectory(kind, t, p, dp, ddp)


def trajectory_from_samples(t: ArrayLike, p: ArrayLike, name: str = "custom") -> Trajectory:
    """A trajectory through timed samples, derivatives from the natural cubic spline.

    ``t`` [s] shape ``(n,)`` strictly increasing, ``p`` [m] shape ``(n, 2)``, ``n >= 4``.
    Times are shifted so the trajectory starts at ``t = 0``.
    """
    t = np.asarray(t, dtype=float)
    p = np.asarray(p, dtype=float)
    if t.ndim != 1 or p.shape != (t.size, 2):
        raise InputError(f"need t of shape (n,) and p of shape (n, 2), got {t.shape} and {p.shape}")
    if t.size < 4:
        raise InputError(Phrase("a trajectory needs at least 4 samples, got {n}", n=t.size))
    spline = CubicSpline(t, p)
    t0 = t - t[0]
    return Trajectory(name, t0, p.copy(), spline(t, 1), spline(t, 2))


def parse_trajectory_csv(text: str, name: str = "custom", max_rows: int = MAX_CSV_ROWS) -> Trajectory:
    """A trajectory from CSV text with columns ``t,p1,p2`` (s, m, m unless the header gives units, ``t [ms]``);
    the dialects and limits of :mod:`tpm_viz.core.csvio` (``docs/csv.md``); one-line errors."""
    cols = parse_columns(text, ["t", "p1", "p2"], source=T("the trajectory CSV"), max_rows=max_rows)
    return trajectory_from_samples(cols["t"], np.stack([cols["p1"], cols["p2"]], -1), name)
