"""Motor sizing from a timed motion: peak and RMS force, mechanical power and energy, speeds, copper losses.

Input: samples of one cycle's motion, times ``t`` [s] ``(n,)`` (non-decreasing; a repeated time marks a jump,
e.g. a step in force), actuator forces ``τ`` [N] ``(n, 2)`` and actuator velocities ``ḋ`` [m/s] ``(n, 2)``;
the cycle is the motion followed by a rest of ``dwell`` [s] (zero force: horizontal plane, no gravity, no
friction, ``docs/conventions.md``). Any timed motion fits: a plan (:mod:`tpm_viz.app.planner`), the paper's cubic
line or circle, a user's CSV, a control run; :func:`size_trajectory` gets ``τ`` from the closed form (eqs. 29-31)
and ``ḋ = J ṗ`` (eq. 9).

Between samples ``τ`` and the mechanical power ``P_i = τ_i ḋ_i`` [W] are taken as linear, and integrated exactly
under that assumption (``∫τ² dt`` by Simpson's rule on a line, ``∫max(P, 0) dt`` split at the sign change):

- RMS force ``sqrt(∫ τ_i² dt / T_cycle)`` [N]; peak force ``max |τ_i|`` [N];
- peak power ``max |P_i|`` [W] (driving or braking, whichever is larger), and separately the peak driving
  power ``max P_i`` and the peak braking power ``max -P_i`` [W] (0 if never); energy per cycle
  ``E_i = ∫ max(P_i, 0) dt`` [J] (driving work, nothing recovered); braking energy ``∫ max(-P_i, 0) dt`` [J];
  mean power ``E_i / T_cycle`` [W];
- peak actuator speed ``max |ḋ_i|`` [m/s] and peak platform speed ``max |ṗ|`` [m/s];
- with a motor constant ``k_m`` [N/sqrt(W)]: copper loss ``τ_i² / k_m²`` [W], its mean over the cycle and its
  energy per cycle [J].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import SupportsFloat

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.jacobians import actuator_velocity

__all__ = ["SIZING_COLUMNS", "Sizing", "format_sizing", "size_motion", "size_trajectory", "sizing_columns"]

SIZING_COLUMNS = ["quantity", "unit", "actuator1", "actuator2"]
"""Columns of the exported sizing table (:func:`sizing_columns`)."""


@dataclass(frozen=True)
class Sizing:
    """The sizing table of one cycle; per-actuator arrays have shape ``(2,)``."""

    cycle_time: float  # [s] motion + dwell
    motion_time: float  # [s]
    dwell: float  # [s]
    peak_force: np.ndarray  # [N]
    rms_force: np.ndarray  # [N] over the cycle, dwell included
    peak_power: np.ndarray  # [W] max |τ_i ḋ_i|, driving or braking
    peak_driving_power: np.ndarray  # [W] max(τ_i ḋ_i, 0): the motor delivers it
    peak_braking_power: np.ndarray  # [W] max(-τ_i ḋ_i, 0): the motor absorbs it
    mean_power: np.ndarray  # [W] driving energy / cycle time
    energy: np.ndarray  # [J] driving work per cycle, ∫ max(τ_i ḋ_i, 0) dt
    braking_energy: np.ndarray  # [J] ∫ max(-τ_i ḋ_i, 0) dt
    peak_actuator_speed: np.ndarray  # [m/s]
    peak_platform_speed: float | None  # [m/s], None when the platform velocity is not known
    motor_constant: float | None  # [N/sqrt(W)]
    peak_copper_loss: np.ndarray | None  # [W]
    mean_copper_loss: np.ndarray | None  # [W]
    copper_energy: np.ndarray | None  # [J] per cycle

    def rows(self) -> list[tuple[str, str, float, float]]:
        """``(quantity, unit, actuator 1, actuator 2)``; cycle-wide values are repeated in both columns."""
        rows = [
            ("cycle time", "s", self.cycle_time, self.cycle_time),
            ("motion time", "s", self.motion_time, self.motion_time),
            ("dwell", "s", self.dwell, self.dwell),
            ("peak force", "N", *self.peak_force),
            ("RMS force", "N", *self.rms_force),
            ("peak mechanical power", "W", *self.peak_power),
            ("peak driving power", "W", *self.peak_driving_power),
            ("peak braking power", "W", *self.peak_braking_power),
            ("mean mechanical power", "W", *self.mean_power),
            ("energy per cycle", "J", *self.energy),
            ("braking energy per cycle", "J", *self.braking_energy),
            ("peak actuator speed", "m/s", *self.peak_actuator_speed),
        ]
        if self.peak_platform_speed is not None:
            rows.append(("peak platform speed", "m/s", self.peak_platform_speed, self.peak_platform_speed))
        if self.motor_constant is not None:
            rows += [
                ("motor constant", "N/sqrt(W)", self.motor_constant, self.motor_constant),
                ("peak copper loss", "W", *_pair(self.peak_copper_loss)),
                ("mean copper loss", "W", *_pair(self.mean_copper_loss)),
                ("copper loss energy per cycle", "J", *_pair(self.copper_energy)),
            ]
        return [(q, u, float(a), float(b)) for q, u, a, b in rows]


def _nonnegative(value: str | SupportsFloat, name: str | Phrase) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(Phrase("{name} must be a number, got {got}", name=name, got=repr(value))) from None
    if not math.isfinite(value) or value < 0:
        raise InputError(Phrase("{name} must be zero or a positive, finite number, got {got:g}", name=name, got=value))
    return value


def _positive_part_integral(h: np.ndarray, y0: np.ndarray, y1: np.ndarray) -> np.ndarray:
    """``∫ max(y, 0)`` over intervals of length ``h`` where ``y`` runs linearly from ``y0`` to ``y1``."""
    both = np.maximum(y0, 0) + np.maximum(y1, 0)
    cross = (y0 > 0) != (y1 > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        top = np.maximum(y0, y1)
        frac = np.where(cross, top / np.where(cross, np.abs(y1 - y0), 1.0), 1.0)
    return np.where(cross, 0.5 * h * top * frac, 0.5 * h * both)


def size_motion(
    t: ArrayLike,
    tau: ArrayLike,
    dd: ArrayLike,
    dwell: float = 0.0,
    motor_constant: float | None = None,
    dp: ArrayLike | None = None,
) -> Sizing:
    """The sizing table of a motion sampled at ``t`` [s] with forces ``tau`` [N] and velocities ``dd`` [m/s].

    ``dp`` [m/s] ``(n, 2)``, the platform velocity, is optional (for the peak platform speed).
    """
    t = np.asarray(t, dtype=float)
    tau = np.asarray(tau, dtype=float)
    dd = np.asarray(dd, dtype=float)
    if t.ndim != 1 or t.size < 2 or tau.shape != (t.size, 2) or dd.shape != (t.size, 2):
        raise InputError(f"need t (n,), tau (n, 2), dd (n, 2) with n >= 2; got {t.shape}, {tau.shape}, {dd.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(tau)) and np.all(np.isfinite(dd))):
        raise InputError(Phrase("the motion contains a non-finite value (NaN or inf)"))
    h = np.diff(t)
    if np.any(h < 0):
        k = int(np.argmax(h < 0))
        raise InputError(
            Phrase(
                "times must not decrease: t = {later:g} s after t = {earlier:g} s (row {row})",
                later=float(t[k + 1]),
                earlier=float(t[k]),
                row=k + 2,
            )
        )
    motion = float(t[-1] - t[0])
    if motion <= 0:
        raise InputError(Phrase("the motion must last longer than zero seconds"))
    dwell = _nonnegative(dwell, T("the dwell"))
    cycle = motion + dwell
    hh = h[:, None]
    sq = np.sum(hh * (tau[:-1] ** 2 + tau[:-1] * tau[1:] + tau[1:] ** 2) / 3.0, axis=0)  # ∫ τ² dt, exact on lines
    power = tau * dd
    energy = np.sum(_positive_part_integral(hh, power[:-1], power[1:]), axis=0)
    braking = np.sum(_positive_part_integral(hh, -power[:-1], -power[1:]), axis=0)
    peak_force = np.max(np.abs(tau), axis=0)
    platform = None
    if dp is not None:
        dp = np.asarray(dp, dtype=float)
        if dp.shape != (t.size, 2) or not np.all(np.isfinite(dp)):
            raise InputError(f"the platform velocity must be finite with shape ({t.size}, 2), got {dp.shape}")
        platform = float(np.max(np.hypot(dp[:, 0], dp[:, 1])))
    copper = (None, None, None)
    if motor_constant is not None:
        km = _nonnegative(motor_constant, T("the motor constant"))
        if km == 0:
            raise InputError(Phrase("the motor constant must be a positive number of N/sqrt(W), got 0"))
        copper = (peak_force**2 / km**2, sq / cycle / km**2, sq / km**2)
        motor_constant = km
    return Sizing(
        cycle_time=cycle,
        motion_time=motion,
        dwell=dwell,
        peak_force=peak_force,
        rms_force=np.sqrt(sq / cycle),
        peak_power=np.max(np.abs(power), axis=0),
        peak_driving_power=np.maximum(np.max(power, axis=0), 0.0),
        peak_braking_power=np.maximum(np.max(-power, axis=0), 0.0),
        mean_power=energy / cycle,
        energy=energy,
        braking_energy=braking,
        peak_actuator_speed=np.max(np.abs(dd), axis=0),
        peak_platform_speed=platform,
        motor_constant=motor_constant,
        peak_copper_loss=copper[0],
        mean_copper_loss=copper[1],
        copper_energy=copper[2],
    )


def size_trajectory(
    params: Params,
    t: ArrayLike,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    dwell: float = 0.0,
    motor_constant: float | None = None,
    tau: ArrayLike | None = None,
) -> Sizing:
    """Sizing of a platform motion ``p, ṗ, p̈`` [m, m/s, m/s²] ``(n, 2)`` at times ``t`` [s].

    ``τ`` comes from the closed form (eqs. 29-31) unless given (e.g. measured forces of a control run);
    ``ḋ = J ṗ`` (eq. 9).
    """
    p, dp = np.asarray(p, dtype=float), np.asarray(dp, dtype=float)
    tau = inverse_dynamics(params, p, dp, ddp) if tau is None else tau
    return size_motion(t, tau, actuator_velocity(params, p, dp), dwell, motor_constant, dp=dp)


def format_sizing(sizing: Sizing) -> str:
    """The table as aligned text, one quantity per line."""
    lines = [f"{'quantity':<30} {'unit':<10} {'actuator 1':>14} {'actuator 2':>14}"]
    for q, u, a, b in sizing.rows():
        lines.append(f"{q:<30} {u:<10} {a:>14.6g} {b:>14.6g}")
    return "\n".join(lines)


def sizing_columns(sizing: Sizing) -> dict[str, list]:
    """The table as columns :data:`SIZING_COLUMNS` (for :func:`tpm_viz.core.csvio.write_columns`)."""
    rows = sizing.rows()
    return {name: [r[k] for r in rows] for k, name in enumerate(SIZING_COLUMNS)}


def _pair(values: np.ndarray | None) -> tuple[float, float]:
    """Both actuators' values of a quantity that exists when a motor constant is given."""
    assert values is not None, "copper losses need a motor constant"
    return float(values[0]), float(values[1])
