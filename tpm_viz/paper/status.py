"""The one vocabulary of pose statuses and singularity thresholds (eqs. 11-12), shared by every layer.

- :class:`PoseStatus`: why a platform pose is or is not usable, least severe first (``classify`` keeps the most
  severe; an interactive move stops at the first one that is not :attr:`PoseStatus.REGULAR`).
- :class:`FkStatus`: what the forward kinematics found for given actuator positions (two circles, eq. 27).
- :class:`SingularityThresholds`: how close to a singularity counts, on ``min_i |cos θ_i|`` (eq. 11) and
  ``|cos(θ1 + θ2)|`` (eq. 12). Two instances matter: :data:`WARN` (the readouts and maps say *near*) and
  :data:`MOVE_LIMITS` (interactive moves and trajectories stop there, before the quantities vanish).
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

from tpm_viz.core.words import Phrase, T

__all__ = [
    "FK_STATUS",
    "MOVE_LIMITS",
    "STATUS_LABELS",
    "STATUS_WORDS",
    "WARN",
    "FkStatus",
    "PoseStatus",
    "SingularityThresholds",
]


class PoseStatus(IntEnum):
    """Status of a platform pose, least severe first. Arrays of statuses hold these integer values."""

    REGULAR = 0
    NEAR_INVERSE = 1
    """A leg is near (or, for a move, at the limit of) the inverse singularity ``cos θ_i = 0`` (eq. 11)."""
    NEAR_DIRECT = 2
    """Near (or at the limit of) the direct singularity ``cos(θ1 + θ2) = 0`` (eq. 12)."""
    OUT_OF_STROKE = 3
    """An actuator is outside ``0 <= d_i <= Δd``."""
    UNREACHABLE = 4
    """No assembly: ``|p_j| >= l_a`` for a leg (eq. 4), or the leg circles do not meet, or not finite."""

    @property
    def label(self) -> str:
        """Lower-case words, e.g. ``"near inverse singularity"``."""
        return _POSE_LABELS[self]


_POSE_LABELS = {
    PoseStatus.REGULAR: "regular",
    PoseStatus.NEAR_INVERSE: "near inverse singularity",
    PoseStatus.NEAR_DIRECT: "near direct singularity",
    PoseStatus.OUT_OF_STROKE: "out of stroke",
    PoseStatus.UNREACHABLE: "unreachable",
}

STATUS_LABELS = {int(s): s.label for s in PoseStatus}
"""``{code: label}`` of :class:`PoseStatus` (kept for the public API and CSV output)."""
STATUS_WORDS: dict[PoseStatus, Phrase] = {
    PoseStatus.REGULAR: T("regular"),
    PoseStatus.NEAR_INVERSE: T("near inverse singularity"),
    PoseStatus.NEAR_DIRECT: T("near direct singularity"),
    PoseStatus.OUT_OF_STROKE: T("out of stroke"),
    PoseStatus.UNREACHABLE: T("unreachable"),
}
"""The labels of :class:`PoseStatus` as phrases, for messages shown to people (``str()``: the English label)."""


class FkStatus(IntEnum):
    """What the forward kinematics found for actuator positions ``d``: the intersections of the leg circles."""

    TWO_MODES = 0
    MODES_MERGE = 1
    """Direct singularity (eq. 12, ``s_1 = -s_2``): the circles touch and the two assembly modes merge."""
    APART = 2
    """The circles are more than ``2 l_a`` apart: the mechanism cannot be assembled."""
    COINCIDE = 3
    """Direct singularity (eq. 12, ``s_1 = s_2``): the circles coincide, the platform position is undetermined."""

    @property
    def label(self) -> str:
        return _FK_LABELS[self]


_FK_LABELS = {
    FkStatus.TWO_MODES: "two assembly modes",
    FkStatus.MODES_MERGE: "direct singularity: the two assembly modes merge (eq. 12)",
    FkStatus.APART: "cannot assemble: the leg circles are more than 2 l_a apart",
    FkStatus.COINCIDE: "direct singularity: the leg circles coincide, the platform position is undetermined (eq. 12)",
}

FK_STATUS = {int(s): s.label for s in FkStatus}
"""``{code: label}`` of :class:`FkStatus` (kept for the public API)."""


class SingularityThresholds(NamedTuple):
    """How close to a singularity counts (dimensionless, on eqs. 11-12)."""

    inverse: float = 0.2
    """Threshold on ``min_i |cos θ_i|`` (inverse singularity, eq. 11)."""
    direct: float = 0.2
    """Threshold on ``|cos(θ1 + θ2)|`` (direct singularity, eq. 12)."""


WARN = SingularityThresholds()
"""Readouts, banners and maps say *near* a singularity below these."""
MOVE_LIMITS = SingularityThresholds(inverse=0.03, direct=0.03)
"""Interactive moves and trajectories stop at these (the hard edge of the valid set)."""
