"""The control lab's sampled loop on any plant: a controller of :mod:`tpm_viz.paper.control` tracks a reference.

The same experiment as :func:`tpm_viz.multibody.control.simulate` without noise, payload or initial offset: at
``t_k = k / rate`` the law reads the platform state ``(p, ṗ)``, computes ``τ_k`` with its own (possibly wrong)
model, clips it to ``±force_limit`` and holds it until ``t_{k+1}`` (zero-order hold); the plant integrates with the
classical Runge-Kutta scheme in sub-steps of at most :data:`MAX_PLANT_STEP`. The plant starts at ``p_ref(0)`` with
``ṗ = ṗ_ref(0)``. The plant is injected: :func:`tpm_viz.paper.plant.closed_form_plant` (the closed form, eqs.
28-31; what the app's exercises grade with, no Pinocchio) or Pinocchio's
:class:`~tpm_viz.multibody.forward.PlatformPlant` (the lab's own; ``tests/paper/test_plant.py`` checks that both
give the same run to ~1e-9).

The result keeps the *commanded* forces before clipping, so that "the forces stay within the limit" means the
controller never asked for more (:attr:`Tracking.commanded_peak`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.words import Phrase
from tpm_viz.paper.control import ControlLaw, reference_state
from tpm_viz.paper.plant import Acceleration
from tpm_viz.paper.trajectories import paper_duration

__all__ = ["MAX_PLANT_STEP", "Tracking", "failed_at", "held_rk4", "track"]

MAX_PLANT_STEP = 1e-3
"""Largest RK4 step of the plant [s] (as the control lab's)."""
MAX_SAMPLES = 200_000
"""Most controller samples of one run."""


@dataclass(frozen=True)
class Tracking:
    """One closed-loop run sampled at the controller's times (``n`` samples, SI units)."""

    t: np.ndarray  # (n,) [s]
    p_ref: np.ndarray  # (n, 2) [m]
    p: np.ndarray  # (n, 2) true platform position at t_k [m]
    tau: np.ndarray  # (n, 2) applied (clipped) actuator forces [N]
    commanded: np.ndarray  # (n, 2) the law's forces before clipping [N]

    @property
    def rms_error(self) -> float:
        """Root mean square of ``|p_ref - p|`` over the samples [m] (as the lab's
        :attr:`tpm_viz.multibody.control.ControlRun.rms_error`)."""
        return float(np.sqrt(np.mean(np.sum((self.p_ref - self.p) ** 2, axis=1))))

    @property
    def commanded_peak(self) -> float:
        """Largest ``|τ_i|`` the controller asked for [N]."""
        return float(np.max(np.abs(self.commanded)))

    @property
    def saturated(self) -> bool:
        """Whether some commanded force was clipped."""
        return bool(np.any(self.commanded != self.tau))


def held_rk4(
    acc: Acceleration, p1: float, p2: float, v1: float, v2: float, u1: float, u2: float, h: float, sub: int
) -> tuple[float, float, float, float]:
    """``sub`` classic Runge-Kutta steps of ``h`` [s] of ``p̈ = acc(p, ṗ, u)`` with the actuator forces ``u`` [N]
    held (a zero-order hold over one control period). -> ``(p1, p2, ṗ1, ṗ2)`` [m, m/s]."""
    hh, h6 = 0.5 * h, h / 6.0
    for _ in range(sub):
        a11, a12 = acc(p1, p2, v1, v2, u1, u2)
        x1, x2, y1, y2 = p1 + hh * v1, p2 + hh * v2, v1 + hh * a11, v2 + hh * a12
        a21, a22 = acc(x1, x2, y1, y2, u1, u2)
        x1, x2, w1, w2 = p1 + hh * y1, p2 + hh * y2, v1 + hh * a21, v2 + hh * a22
        a31, a32 = acc(x1, x2, w1, w2, u1, u2)
        x1, x2, s1, s2 = p1 + h * w1, p2 + h * w2, v1 + h * a31, v2 + h * a32
        a41, a42 = acc(x1, x2, s1, s2, u1, u2)
        p1, p2 = p1 + h6 * (v1 + 2 * y1 + 2 * w1 + s1), p2 + h6 * (v2 + 2 * y2 + 2 * w2 + s2)
        v1, v2 = v1 + h6 * (a11 + 2 * a21 + 2 * a31 + a41), v2 + h6 * (a12 + 2 * a22 + 2 * a32 + a42)
    return p1, p2, v1, v2


def failed_at(exc: Exception, at: float) -> TpmVizError:
    """What a simulation that failed at ``at`` [s] raises: ``exc``'s own kind and words with the time, or a
    divergence (a float error: an unstable loop)."""
    if isinstance(exc, TpmVizError):
        first = exc.args[0] if exc.args and isinstance(exc.args[0], Phrase) else str(exc)
        return type(exc)(Phrase("at t = {t:.4f} s: {why}", t=at, why=first))
    return InputError(Phrase("at t = {t:.4f} s the simulation diverged (unstable loop?)", t=at))


def track(
    law: ControlLaw,
    plant: Acceleration,
    reference: str = "circle",
    duration: float | None = None,
    rate: float = 1000.0,
    force_limit: float | None = None,
) -> Tracking:
    """Run ``law`` on ``plant`` along the paper's ``reference`` (``"line"`` or ``"circle"``, path duration
    ``duration`` [s], default 0.2 / 0.5 s) for the path's duration, sampled at ``rate`` [Hz].

    Raises :class:`~tpm_viz.core.errors.TpmVizError` with the time when the loop leaves the workspace or diverges.
    """
    span = paper_duration(reference, duration)
    if not (math.isfinite(rate) and rate > 0):
        raise InputError(Phrase("rate [Hz] must be positive, got {rate}", rate=rate))
    n = max(1, math.ceil(span * rate - 1e-9))
    if n > MAX_SAMPLES:
        raise InputError(Phrase("horizon x rate = {n} samples exceeds the limit of {most}", n=n, most=MAX_SAMPLES))
    t = np.arange(n + 1) / rate
    p_ref, dp_ref, ddp_ref = reference_state(reference, t, duration)
    rows = law.sample(t, p_ref, dp_ref, ddp_ref).rows()
    force = law.force_function()
    limit = math.inf if force_limit is None else float(force_limit)
    period = 1.0 / rate
    sub = max(1, math.ceil(period / MAX_PLANT_STEP - 1e-9))
    h = period / sub
    out = np.empty((n + 1, 6))  # p (2), τ applied (2), τ commanded (2)
    p1, p2 = (float(x) for x in p_ref[0])
    v1, v2 = (float(x) for x in dp_ref[0])
    k = 0
    try:
        for k in range(n + 1):
            tau1, tau2, _, _ = force(rows[k], p1, p2, v1, v2)
            u1, u2 = min(max(tau1, -limit), limit), min(max(tau2, -limit), limit)
            out[k] = (p1, p2, u1, u2, tau1, tau2)
            if k == n:
                break
            p1, p2, v1, v2 = held_rk4(plant, p1, p2, v1, v2, u1, u2, h, sub)
    except (TpmVizError, ZeroDivisionError, OverflowError, ValueError) as exc:
        raise failed_at(exc, k * period) from None
    return Tracking(t=t, p_ref=p_ref, p=out[:, 0:2].copy(), tau=out[:, 2:4].copy(), commanded=out[:, 4:6].copy())
