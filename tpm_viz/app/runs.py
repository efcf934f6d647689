"""Trajectory runs for the player: a path, checked once, with every quantity the charts and exports need.

A :class:`Source` says where the platform goes: the paper's line or circle (Figs. 4-5, cubic time law,
editable duration), a straight segment of the same law (used by the guided demonstrations), or a user's timed
positions (a CSV ``t,p1,p2`` in s, m), followed through a natural cubic spline. :func:`build_run`
samples it uniformly in time, refuses it with one line if any sample leaves the valid set of
:mod:`tpm_viz.app.moves` (reach ``|p_j| < l_a``, stroke ``0 <= d_i <= Δd``, clear of both singularities,
one assembly mode), and computes the procedure (a)-(e) at every sample: ``d, ḋ, d̈`` and the closed-form
``τ``. An optional reference model (the Pinocchio model, passed in as a function so that this module stays
pure numpy) adds its forces once per run, not once per displayed frame.

SI units throughout; :meth:`Run.columns` is the CSV export.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal, SupportsFloat

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.app.moves import ik_branch, pose_codes, why_not
from tpm_viz.app.readouts import Reference, reason
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.dynamics import inverse_dynamics_detail
from tpm_viz.paper.spline import CubicSpline
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus, SingularityThresholds
from tpm_viz.paper.trajectories import DEFAULT_DURATIONS, Trajectory, circle_state, line_state

__all__ = ["RUN_SAMPLES", "Run", "Source", "build_run", "check_path", "peak_force"]

RUN_SAMPLES = 401
"""Samples of a run, uniform in time (charts, exports, the Pinocchio forces)."""
MAX_DURATION = 100.0  # s, the paper's line and circle and the demo segments
MIN_DURATION = 0.01  # s


SourceKind = Literal["line", "circle", "segment", "csv"]
"""Where a run's path comes from: the paper's line or circle, a straight segment (lessons), a user's CSV."""


@dataclass(frozen=True)
class Source:
    """Where the platform goes. ``kind`` is ``"line"``, ``"circle"``, ``"segment"`` or ``"csv"``.

    ``duration`` [s]; ``start``/``end`` [m] for a segment; ``knots`` = ``(t, p)`` samples for a CSV path.
    """

    kind: SourceKind
    duration: float
    label: str
    start: tuple[float, float] | None = None
    end: tuple[float, float] | None = None
    knots: tuple[np.ndarray, np.ndarray] | None = field(default=None, compare=False, repr=False)

    @classmethod
    def paper(cls, kind: str, duration: float | None = None) -> Source:
        """The paper's line (Fig. 4) or circle (Fig. 5); default durations from ``docs/conventions.md``."""
        if kind not in DEFAULT_DURATIONS:
            raise InputError(Phrase("trajectory must be 'line' or 'circle', got {kind}", kind=repr(kind)))
        duration = _duration(DEFAULT_DURATIONS[kind] if duration is None else duration)
        paper_kind: SourceKind = "line" if kind == "line" else "circle"
        figure = "Fig. 4" if paper_kind == "line" else "Fig. 5"
        return cls(paper_kind, duration, f"{paper_kind} ({figure}), T = {duration:g} s")

    @classmethod
    def from_trajectory(cls, traj: Trajectory, label: str | None = None) -> Source:
        """A user's timed samples (e.g. an upload read by ``tpm_viz.app.inputs.read_upload`` or
        :func:`~tpm_viz.parse_trajectory_csv`), followed through their natural cubic spline."""
        t = np.asarray(traj.t, dtype=float)
        p = np.asarray(traj.p, dtype=float)
        if t.ndim != 1 or p.shape != (t.size, 2) or t.size < 4 or not traj.duration > 0:
            raise InputError("a trajectory needs at least 4 timed samples of (p1, p2)")
        name = label if label is not None else traj.name
        return cls("csv", traj.duration, f"{name}, T = {traj.duration:g} s", knots=(t - t[0], p))

    @classmethod
    def segment(cls, start: tuple[float, float], end: tuple[float, float], duration: float, label: str = "") -> Source:
        """A straight move ``start -> end`` [m] with the paper's cubic time law."""
        start = (float(start[0]), float(start[1]))
        end = (float(end[0]), float(end[1]))
        duration = _duration(duration)
        return cls("segment", duration, label or f"segment, T = {duration:g} s", start, end)

    def motion(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(p, ṗ, p̈)`` at times ``t`` [s] (clipped to ``[0, T]``), each of shape ``t.shape + (2,)``."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        if self.kind == "line":
            return line_state(t, self.duration)
        if self.kind == "circle":
            return circle_state(t, self.duration)
        if self.kind == "segment" and self.start is not None and self.end is not None:
            return line_state(t, self.duration, self.start, self.end)
        if self.kind == "csv" and self.knots is not None:
            spline = CubicSpline(*self.knots)
            return spline(t, 0), spline(t, 1), spline(t, 2)
        raise InputError(Phrase("unknown trajectory source {kind}", kind=repr(self.kind)))


def _duration(value: str | SupportsFloat) -> float:
    try:
        duration = float(value)
    except (TypeError, ValueError):
        raise InputError(Phrase("duration must be a number of seconds, got {got}", got=repr(value))) from None
    if not (math.isfinite(duration) and MIN_DURATION <= duration <= MAX_DURATION):
        raise InputError(
            Phrase(
                "duration must be from {low:g} s to {high:g} s, got {got}",
                low=MIN_DURATION,
                high=MAX_DURATION,
                got=repr(value),
            )
        )
    return duration


def check_path(
    params: Params,
    t: np.ndarray,
    p: np.ndarray,
    what: str | Phrase = T("the trajectory"),
    limits: SingularityThresholds = MOVE_LIMITS,
) -> None:
    """Raise :class:`InputError` at the first sample of ``p`` (``(n, 2)`` [m] at times ``t``) that is not a
    valid working-mode pose in the assembly mode of the first sample."""
    d = ik_branch(params, p, (1.0, 1.0))
    c = p - d + params.offset
    det0 = c[0, 0] * c[0, 1] - p[0, 0] * p[0, 1]
    mode = 1 if not np.isfinite(det0) or det0 >= 0 else -1
    codes = pose_codes(params, p, d, mode, (1.0, 1.0), limits)
    bad = np.flatnonzero(codes != PoseStatus.REGULAR)
    if bad.size:
        k = int(bad[0])
        raise InputError(
            Phrase(
                "{what}: at t = {t} s, p = ({x}, {y}) mm: {why}",
                what=what,
                t=fixed(t[k], ".3f"),
                x=fixed(p[k, 0], ".1f", 1e3),
                y=fixed(p[k, 1], ".1f", 1e3),
                why=why_not(params, int(codes[k]), p[k], d[k]),
            )
        )


@dataclass(frozen=True)
class Run:
    """A checked trajectory and its quantities at ``n`` uniform samples (SI units, arrays ``(n,)``/``(n, 2)``)."""

    source: Source
    params: Params
    t: np.ndarray
    p: np.ndarray
    dp: np.ndarray
    ddp: np.ndarray
    d: np.ndarray  # (a) eq. (4)
    dd: np.ndarray  # (b) eq. (9)
    ddd: np.ndarray  # (c) eq. (14)
    tau: np.ndarray  # (e) eq. (31), closed form
    tau_ref: np.ndarray | None  # reference model (Pinocchio), None if unavailable
    ref_note: Phrase | None = None  # why tau_ref is missing (None when it is there)

    @property
    def duration(self) -> float:
        """``T`` [s]."""
        return self.source.duration

    @property
    def peak(self) -> float:
        """``max |τ_i|`` over the run [N] (closed form)."""
        return peak_force(self.tau)

    @property
    def max_diff(self) -> float | None:
        """``max |τ_ref - τ|`` [N], or None without a reference."""
        return None if self.tau_ref is None else float(np.max(np.abs(self.tau_ref - self.tau)))

    def state_at(self, t: float) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """``(t, p, ṗ, p̈)`` at time ``t`` [s] clipped to ``[0, T]``, exact (not interpolated)."""
        t = float(np.clip(t, 0.0, self.duration))
        p, dp, ddp = self.source.motion(np.array([t]))
        return t, p[0], dp[0], ddp[0]

    def index_at(self, t: float) -> int:
        """Index of the sample nearest ``t`` [s]."""
        return int(np.clip(np.rint(t / self.duration * (len(self.t) - 1)), 0, len(self.t) - 1))

    def columns(self) -> dict[str, np.ndarray]:
        """The run as CSV columns (SI: s, m, m/s, m/s², N); Pinocchio columns empty without a reference."""
        ref = np.full_like(self.tau, np.nan) if self.tau_ref is None else self.tau_ref
        cols = {"t": self.t}
        for name, arr in (
            ("p", self.p),
            ("dp", self.dp),
            ("ddp", self.ddp),
            ("d", self.d),
            ("dd", self.dd),
            ("ddd", self.ddd),
            ("tau", self.tau),
        ):
            cols[f"{name}1"], cols[f"{name}2"] = arr[:, 0], arr[:, 1]
        cols["tau1_pinocchio"], cols["tau2_pinocchio"] = ref[:, 0], ref[:, 1]
        return cols


def peak_force(tau: np.ndarray) -> float:
    """``max |τ|`` [N] over an array of actuator forces."""
    return float(np.max(np.abs(tau)))


def build_run(params: Params, source: Source, reference: Reference | None = None, samples: int = RUN_SAMPLES) -> Run:
    """Sample, check and evaluate ``source`` (see the module docstring); one-line :class:`InputError`."""
    t = np.linspace(0.0, source.duration, int(samples))
    p, dp, ddp = source.motion(t)
    what = Phrase("the trajectory {label}", label=source.label)
    if source.knots is not None:  # the user's own samples, then the spline between them
        check_path(params, source.knots[0], source.knots[1], what)
    check_path(params, t, p, what)
    try:
        res = inverse_dynamics_detail(params, p, dp, ddp)
    except TpmVizError as exc:
        raise InputError(Phrase("{what}: {why}", what=what, why=reason(exc))) from None
    note: Phrase | None = T("no reference model")
    tau_ref = None
    if reference is not None:
        try:
            tau_ref = np.asarray(reference(params, p, dp, ddp), dtype=float).reshape(p.shape)
            note = None
        except (TpmVizError, ArithmeticError, np.linalg.LinAlgError) as exc:
            tau_ref, note = None, Phrase("reference model: {why}", why=reason(exc))
        if tau_ref is not None and not np.all(np.isfinite(tau_ref)):
            tau_ref, note = None, Phrase("reference model: {why}", why=T("non-finite forces"))
    return Run(source, params, t, p, dp, ddp, res.d, res.dd, res.ddd, res.tau, tau_ref, note)
