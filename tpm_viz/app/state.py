"""The app's state: everything a tab draws, as one frozen value replaced at every change (SI units).

No viser and no maths here: :class:`AppState` is the mechanism's parameters, its pose, the load on it (static or
dynamic, :class:`~tpm_viz.app.readouts.Load`), the trajectory sample it shows and the note of the last move.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TypedDict, Unpack

from tpm_viz.app.moves import Pose
from tpm_viz.app.poses import home_pose
from tpm_viz.app.readouts import Load
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase

__all__ = ["AppState", "Changes", "TrajectorySample", "run_note"]


def run_note(run: str | Phrase, t: float) -> Phrase:
    """The one line under the banner while the platform rests on a run's sample (paused, scrubbed, at its end): the
    forces shown are that run's dynamic load at ``t`` [s], not the static load of the pose."""
    return Phrase(
        "Forces: the dynamic load of {run} at t = {t} s (a move or Home shows the static load)", run=run, t=f"{t:.3f}"
    )


@dataclass(frozen=True)
class TrajectorySample:
    """Which trajectory sample drives the platform: ``kind``, duration ``T`` [s] and time ``t`` [s]."""

    kind: str = "none"
    """``"none"`` (moved by hand), or the tag of the run that placed the platform (its source kind, or a tab's own
    control or planner run)."""
    duration: float = 0.2
    t: float = 0.0


class Changes(TypedDict, total=False):
    """The fields :meth:`AppState.replace` may change (it bumps ``version`` itself)."""

    params: Params
    pose: Pose
    load: Load
    trajectory: TrajectorySample
    note: str | Phrase


@dataclass(frozen=True)
class AppState:
    """Everything a view draws (SI units). Replaced, never mutated."""

    params: Params
    pose: Pose
    load: Load = field(default_factory=Load)
    trajectory: TrajectorySample = field(default_factory=TrajectorySample)
    note: str | Phrase = ""
    """Why the last move stopped short, or what it changed (shown to every viewer of the session, each in their
    language), or empty."""
    version: int = 0

    @classmethod
    def initial(cls, params: Params | None = None) -> AppState:
        """The paper's prototype at its home pose (``p = 0``), static mode, no load."""
        params = Params.paper() if params is None else params
        return cls(params=params, pose=home_pose(params))

    def replace(self, **changes: Unpack[Changes]) -> AppState:
        """A copy with some fields changed and the version bumped."""
        return dataclasses.replace(self, version=self.version + 1, **changes)

    @property
    def run_load(self) -> bool:
        """Whether the load is a run's sample (``ṗ, p̈`` at the time a trajectory, control run or plan was left at),
        not one typed by hand."""
        return self.trajectory.kind != "none" and self.load.mode == "dynamic"

    def at_rest(self, note: str | Phrase | None = None) -> AppState:
        """The same pose at rest, off any run: a run's dynamic load goes back to the static one (keeping the typed
        ``f_ext``; eq. 31 with ``ṗ = p̈ = 0``), the sample to ``"none"``. A dynamic load typed by hand stays (it is
        the question being asked: "what forces at this velocity?"). ``note``: the new note (None: unchanged)."""
        load = Load("static", f_ext=self.load.f_ext) if self.run_load else self.load
        sample = TrajectorySample("none", self.trajectory.duration, 0.0)
        return self.replace(load=load, trajectory=sample, note=self.note if note is None else note)
