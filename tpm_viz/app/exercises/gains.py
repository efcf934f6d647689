"""The ``gains`` exercise: the control lab's computed-torque law, tuned by the student, judged by simulation.

The experiment is the control lab's (``tpm-viz control --controller ctc --trajectory circle --rate 1000
--mass-error E --force-limit L``; :mod:`tpm_viz.multibody.control`): the law of :mod:`tpm_viz.paper.control` with
gains from ``ω_n`` [Hz] and ``ζ`` and its own model with the variant's relative ``mass_error`` on ``m_a``, ``m_b``
and ``m_p``, sampled at :data:`RATE` with a zero-order hold, drives the mechanism along the paper's circle (Fig. 5,
``T = 0.5 s``) from rest on the path, with the actuator forces clipped to the variant's ``force_limit``. The gains
pass when the RMS tracking error stays below :data:`RMS_LIMIT` (1 mm) and the law never asks for more than the
limit (no sample saturates).

The plant is the paper's closed form (:func:`tpm_viz.paper.plant.closed_form_plant`, stepped by
:func:`tpm_viz.paper.tracking.track`), not Pinocchio: the app layer may not import it, and the two plants agree to
round-off in acceleration and within 1e-9 m over a run (``tests/paper/test_plant.py``), so the verdicts agree
except within that distance of the boundary (``tests/app/test_exercise_references.py`` runs the lab's own
Pinocchio simulation on the same variants and gains). One
verdict is 22-44 ms of pure Python (``benchmarks/bench_exercises.py``); a wrong answer takes two (the rad/s mistake).

The reference (what ``--reveal`` shows) is ``ζ = 1`` and the geometric middle of the passing ``ω_n`` among
:data:`GRID` (rounded to 1 Hz); :func:`just_outside` is the grid value just below the passing ones (too soft: the
error exceeds 1 mm).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from tpm_viz.app.exercises.model import Variant
from tpm_viz.app.readouts import reason
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.words import Phrase
from tpm_viz.paper.control import ControlLaw, ControllerKind, Gains, model_with_errors
from tpm_viz.paper.plant import closed_form_plant
from tpm_viz.paper.tracking import track

__all__ = ["GAINS_TASKS", "GRID", "RATE", "RMS_LIMIT", "GainsTask", "Verdict", "just_outside", "reference", "verdict"]

RATE = 1000.0
"""Controller sample rate [Hz] (the lab's default, the issue's 1 kHz)."""
RMS_LIMIT = 1e-3
"""Largest RMS tracking error that passes [m]."""
GRID = (2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0, 22.0, 32.0, 45.0, 64.0, 90.0, 128.0, 180.0)
"""Natural frequencies [Hz] the reference is searched among (steps of about √2)."""
REFERENCE_ZETA = 1.0
"""Damping ratio of the reference (critically damped)."""
NEEDS = ("force_limit", "mass_error")


@dataclass(frozen=True)
class Verdict:
    """One simulation's outcome: RMS error [m], the largest commanded ``|τ_i|`` [N] and the limit [N], or the
    ``failure`` (the loop went unstable: the platform left the workspace)."""

    rms: float
    peak: float
    limit: float
    failure: Phrase | None = None

    @property
    def tracks(self) -> bool:
        return self.failure is None and self.rms < RMS_LIMIT

    @property
    def within(self) -> bool:
        return self.failure is None and self.peak <= self.limit

    @property
    def ok(self) -> bool:
        return self.tracks and self.within

    def why(self) -> Phrase:
        """One line: the numbers and what to change."""
        if self.failure is not None:
            return Phrase("the loop went unstable ({why}): lower ω_n or ζ", why=self.failure)
        rms, peak, limit = f"{self.rms * 1e3:.3g}", f"{self.peak:.1f}", f"{self.limit:.0f}"
        if self.ok:
            return Phrase(
                "correct: RMS error {rms} mm, largest |τ_i| {peak} N (limit {limit} N)", rms=rms, peak=peak, limit=limit
            )
        if not self.within:
            return Phrase(
                "the law asks for |τ_i| = {peak} N, above the limit {limit} N (RMS error {rms} mm): the gains are too "
                "stiff",
                peak=peak,
                limit=limit,
                rms=rms,
            )
        return Phrase(
            "RMS error {rms} mm, above 1 mm (largest |τ_i| {peak} N): the gains are too soft for this mass error",
            rms=rms,
            peak=peak,
        )


@functools.lru_cache(maxsize=512)
def verdict(variant: Variant, wn: float, zeta: float) -> Verdict:
    """Simulate ``variant`` with the gains ``ω_n = wn`` [Hz], ``ζ = zeta`` (module docstring)."""
    err, limit = variant["mass_error"], variant["force_limit"]
    law = ControlLaw(ControllerKind.CTC, model_with_errors(variant.params, err, err, err), Gains(wn, zeta))
    try:
        run = track(law, closed_form_plant(variant.params), "circle", rate=RATE, force_limit=limit)
    except TpmVizError as exc:
        return Verdict(math.inf, math.inf, limit, reason(exc))
    return Verdict(run.rms_error, run.commanded_peak, limit)


def _passing(variant: Variant) -> list[float]:
    return [wn for wn in GRID if verdict(variant, wn, REFERENCE_ZETA).ok]


@functools.lru_cache(maxsize=256)
def reference(variant: Variant) -> tuple[float, float] | None:
    """``(ω_n [Hz], ζ)`` that pass for ``variant``: ``ζ = 1`` and the geometric middle of the passing grid values
    (rounded to 1 Hz; the middle grid value if the rounded one fails); None if no grid value passes."""
    passing = _passing(variant)
    if not passing:
        return None
    middle = float(round(math.sqrt(passing[0] * passing[-1])))
    if verdict(variant, middle, REFERENCE_ZETA).ok:
        return middle, REFERENCE_ZETA
    return passing[len(passing) // 2], REFERENCE_ZETA


def just_outside(variant: Variant) -> tuple[float, float] | None:
    """Gains just outside the passing set: the grid value below the lowest passing one, ``ζ = 1`` (None if none)."""
    passing = _passing(variant)
    below = [wn for wn in GRID if passing and wn < passing[0]]
    return (below[-1], REFERENCE_ZETA) if below else None


@dataclass(frozen=True)
class GainsTask:
    """The gains computation: ``needs`` the inputs :data:`NEEDS`."""

    needs: tuple[str, ...] = NEEDS

    def usable(self, variant: Variant) -> bool:
        return True  # the ranges of the packaged exercise all have passing gains (checked by the selftest)


GAINS_TASKS: dict[str, GainsTask] = {"track_circle": GainsTask()}
"""The gains computations, by name."""
