"""Closed-loop control lab: a sampled controller drives the Pinocchio closed-loop model.

Plant: the closed-loop multibody model of :mod:`tpm_viz.multibody.model`, in its 2 independent platform
coordinates (:class:`~tpm_viz.multibody.forward.PlatformPlant`, the same dynamics as the KKT forward
dynamics of the replay, ~15 µs per evaluation), integrated with the classical Runge-Kutta scheme (RK4)
like :mod:`tpm_viz.multibody.replay`. A payload [kg] rides on the platform (the plant's ``m_p`` grows);
the controller does not know it.

Controller: one of the laws of :mod:`tpm_viz.paper.control` on the paper's closed form with its *own*
parameters (relative mass errors of ``m_a``, ``m_b``, ``m_p``), sampled at ``rate`` [Hz] with a
zero-order hold: at ``t_k = k / rate`` it reads the platform state ``(p, ṗ)`` plus seeded Gaussian
noise, computes ``τ_k`` and clips it to ``±force_limit`` [N]; the plant integrates with ``τ_k`` constant
until ``t_{k+1}`` (RK4 sub-steps of at most :data:`MAX_PLANT_STEP`). The hold makes the error of an exact
model proportional to the sample period (the force lags by half a period); with ``feedforward_at="mid"`` the
reference's acceleration (``ctc``) or closed-form force (``pdff``) is taken at ``t_k + 1/(2 rate)``, the middle
of the hold, which removes most of that lag (``tests/multibody/test_control_midpoint.py``). Since ``τ`` is
constant on each hold interval, the actuator work over it is exactly ``τ_k · (d(t_{k+1}) - d(t_k))`` (the tests
use this for the energy balance). The plant starts at ``p_ref(0) + offset`` with ``ṗ = ṗ_ref(0)``.

This module does not import Pinocchio itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import SupportsFloat

import numpy as np

from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.multibody.forward import PlatformPlant
from tpm_viz.multibody.model import model_for
from tpm_viz.paper.control import ControlLaw, ControllerKind, Gains, model_with_errors, reference_state
from tpm_viz.paper.tracking import failed_at, held_rk4
from tpm_viz.paper.trajectories import Trajectory, paper_duration, positive_seconds

__all__ = ["COLUMNS", "DEFAULT_RATE", "MAX_PLANT_STEP", "MAX_SAMPLES", "ControlRun", "ControlSetup", "simulate"]

DEFAULT_RATE = 1000.0
"""Default controller sample rate [Hz]."""
MAX_PLANT_STEP = 1e-3
"""Largest RK4 step of the plant [s]; a hold interval is split into equal sub-steps below it."""
MAX_SAMPLES = 2_000_000
"""Upper bound on the number of controller samples of one run."""
COLUMNS = ["t", "p1_ref", "p2_ref", "p1", "p2", "e1", "e2", "tau1", "tau2", "tau_ff1", "tau_ff2"]
"""CSV columns of :meth:`ControlRun.columns` (SI: s, m, N)."""


def _number(value: str | SupportsFloat, name: str, low: float = 0.0) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(value) or value < low:
        raise InputError(f"{name} must be a finite number >= {low:g}, got {value:g}")
    return value


@dataclass(frozen=True)
class ControlSetup:
    """Everything about one experiment except the mechanism and the reference (SI units)."""

    controller: ControllerKind = ControllerKind.CTC
    gains: Gains = field(default_factory=Gains)
    rate: float = DEFAULT_RATE  # controller sample rate [Hz]
    payload: float = 0.0  # mass on the platform unknown to the controller [kg]
    mass_error: tuple[float, float, float] = (0.0, 0.0, 0.0)  # relative errors of m_a, m_b, m_p in the controller
    force_limit: float | None = None  # actuator saturation |τ_i| <= limit [N]; None: no limit
    noise: float = 0.0  # standard deviation of the measured platform position, per axis [m]
    velocity_noise: float = 0.0  # standard deviation of the measured platform velocity, per axis [m/s]
    offset: tuple[float, float] = (0.0, 0.0)  # initial platform position minus the reference's [m]
    seed: int = 0  # seed of the measurement noise
    feedforward_at: str = "sample"  # "sample": the reference's p̈ (and τ_ff) at t_k; "mid": at t_k + 1/(2 rate)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "controller", ControllerKind.parse(self.controller))
        if not isinstance(self.gains, Gains):
            raise InputError("gains must be a tpm_viz.paper.control.Gains")
        rate = _number(self.rate, "rate [Hz]")
        if rate <= 0:
            raise InputError(f"rate [Hz] must be positive, got {rate:g}")
        set_(self, "rate", rate)
        set_(self, "payload", _number(self.payload, "payload [kg]"))
        if len(self.mass_error) != 3:
            raise InputError("mass_error needs three relative errors (m_a, m_b, m_p)")
        set_(self, "mass_error", tuple(_number(e, "relative mass error", -0.999) for e in self.mass_error))
        if self.force_limit is not None:
            limit = _number(self.force_limit, "force limit [N]")
            if limit <= 0:
                raise InputError(f"force limit [N] must be positive, got {limit:g}")
            set_(self, "force_limit", limit)
        if self.feedforward_at not in ("sample", "mid"):
            raise InputError(f"feedforward_at must be 'sample' or 'mid', got {self.feedforward_at!r}")
        set_(self, "noise", _number(self.noise, "position noise [m]"))
        set_(self, "velocity_noise", _number(self.velocity_noise, "velocity noise [m/s]"))
        if len(self.offset) != 2:
            raise InputError("offset needs two components (x, y) [m]")
        set_(self, "offset", tuple(_number(x, "initial offset [m]", -math.inf) for x in self.offset))
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer):
            raise InputError(f"seed must be an integer, got {self.seed!r}")


@dataclass(frozen=True)
class ControlRun:
    """One closed-loop run, sampled at the controller's times (``n`` samples, SI units)."""

    name: str  # the reference ("line", "circle" or the trajectory's name)
    setup: ControlSetup
    plant_params: Params  # the simulated mechanism (payload included)
    model_params: Params  # the controller's model (mass errors included)
    t: np.ndarray  # (n,) sample times [s]
    p_ref: np.ndarray  # (n, 2) reference platform position [m]
    dp_ref: np.ndarray  # (n, 2) reference platform velocity [m/s]
    p: np.ndarray  # (n, 2) true platform position at t_k [m]
    dp: np.ndarray  # (n, 2) true platform velocity at t_k [m/s]
    tau: np.ndarray  # (n, 2) applied actuator forces, held on [t_k, t_k+1) (after saturation) [N]
    tau_ff: np.ndarray  # (n, 2) the error-independent part of the command (paper.control) [N]
    saturated: np.ndarray  # (n,) bool: some actuator force was clipped at t_k

    @property
    def error(self) -> np.ndarray:
        """Tracking error ``e = p_ref - p`` [m], ``(n, 2)``."""
        return self.p_ref - self.p

    @property
    def error_norm(self) -> np.ndarray:
        """``|e|`` [m], ``(n,)``."""
        return np.linalg.norm(self.error, axis=1)

    @property
    def rms_error(self) -> float:
        """Root mean square of ``|e|`` over the samples [m]."""
        return float(np.sqrt(np.mean(self.error_norm**2)))

    @property
    def max_error(self) -> float:
        """Largest ``|e|`` [m]."""
        return float(np.max(self.error_norm))

    @property
    def peak_force(self) -> float:
        """Largest applied ``|τ_i|`` [N]."""
        return float(np.max(np.abs(self.tau)))

    @property
    def time_in_saturation(self) -> float:
        """Time [s] during which some actuator force was clipped (held intervals, the last sample excluded)."""
        return float(np.count_nonzero(self.saturated[:-1]) / self.setup.rate)

    def columns(self) -> dict[str, np.ndarray]:
        """The run as CSV columns :data:`COLUMNS`."""
        e = self.error
        arrays = (self.t, *self.p_ref.T, *self.p.T, *e.T, *self.tau.T, *self.tau_ff.T)
        return dict(zip(COLUMNS, arrays, strict=True))

    def summary(self) -> str:
        """One line: RMS and max error, peak force, time in saturation."""
        s = self.setup
        horizon = self.t[-1] - self.t[0]
        share = 100.0 * self.time_in_saturation / horizon if horizon > 0 else 0.0
        return (
            f"{s.controller.value} on {self.name}, {horizon:g} s at {s.rate:g} Hz: "
            f"RMS error {self.rms_error * 1e3:.4g} mm, "
            f"max error {self.max_error * 1e3:.4g} mm, peak force {self.peak_force:.1f} N, "
            f"saturated {self.time_in_saturation * 1e3:.1f} ms ({share:.1f} %)"
        )


def _horizon(reference: str | Trajectory, duration: float | None, horizon: float | None) -> tuple[str, float]:
    if isinstance(reference, Trajectory):
        if duration is not None:
            raise InputError("a sampled trajectory has its own duration: give horizon for a longer run")
        name, base = reference.name, reference.duration
    else:
        name, base = str(reference), paper_duration(reference, duration)
    return name, base if horizon is None else positive_seconds(horizon, T("horizon"))


def simulate(
    params: Params,
    reference: str | Trajectory,
    setup: ControlSetup | None = None,
    duration: float | None = None,
    horizon: float | None = None,
) -> ControlRun:
    """Run the control lab (see the module docstring).

    ``reference``: ``"line"`` / ``"circle"`` (path duration ``duration`` [s], default 0.2 / 0.5 s) or a
    :class:`~tpm_viz.paper.trajectories.Trajectory`; the run lasts ``horizon`` [s] (default: the path's
    duration; the reference rests at its end afterwards). Raises :class:`~tpm_viz.core.errors.TpmVizError`
    with one line for bad input or when the platform leaves the workspace (unstable loop).
    """
    if not isinstance(params, Params):
        raise InputError(f"simulate needs a tpm_viz.Params, got {type(params).__name__}")
    setup = ControlSetup() if setup is None else setup
    if not isinstance(setup, ControlSetup):
        raise InputError(f"setup must be a ControlSetup, got {type(setup).__name__}")
    name, span = _horizon(reference, duration, horizon)
    n = max(1, math.ceil(span * setup.rate - 1e-9))
    if n > MAX_SAMPLES:
        raise InputError(Phrase("horizon x rate = {n} samples exceeds the limit of {most}", n=n, most=MAX_SAMPLES))
    t = np.arange(n + 1) / setup.rate
    start = float(reference.t[0]) if isinstance(reference, Trajectory) else 0.0  # run time 0 = the path's start
    p_ref, dp_ref, ddp_ref = reference_state(reference, t + start, duration)

    plant_params = params.replace(m_p=params.m_p + setup.payload)
    model_params = model_with_errors(params, *setup.mass_error)
    law = ControlLaw(setup.controller, model_params, setup.gains)
    rows = law.sample(t, p_ref, dp_ref, ddp_ref).rows()
    if setup.feedforward_at == "mid":  # the hold's average force is the law's at mid-interval: feed that forward
        mid = law.sample(t, *reference_state(reference, t + start + 0.5 / setup.rate, duration)).rows()
        rows = [r[:4] + m[4:6] + r[6:10] + m[10:12] for r, m in zip(rows, mid, strict=True)]
    force = law.force_function()
    acc = PlatformPlant(model_for(plant_params)).acceleration

    rng = np.random.default_rng(setup.seed)
    noise = np.zeros((n + 1, 4))
    noise[:, :2] = rng.normal(0.0, 1.0, (n + 1, 2)) * setup.noise
    noise[:, 2:] = rng.normal(0.0, 1.0, (n + 1, 2)) * setup.velocity_noise
    noise_rows = noise.tolist()
    out = np.empty((n + 1, 10))  # p (2), ṗ (2), τ (2), τ_ff (2), saturated, spare
    limit = math.inf if setup.force_limit is None else setup.force_limit
    period = 1.0 / setup.rate
    sub = max(1, math.ceil(period / MAX_PLANT_STEP - 1e-9))
    h = period / sub
    p1, p2 = (float(x) for x in p_ref[0] + np.asarray(setup.offset))
    v1, v2 = (float(x) for x in dp_ref[0])
    k = 0
    try:
        for k in range(n + 1):
            z = noise_rows[k]
            tau1, tau2, ff1, ff2 = force(rows[k], p1 + z[0], p2 + z[1], v1 + z[2], v2 + z[3])
            u1, u2 = min(max(tau1, -limit), limit), min(max(tau2, -limit), limit)
            out[k] = (p1, p2, v1, v2, u1, u2, ff1, ff2, u1 != tau1 or u2 != tau2, 0.0)
            if k == n:
                break
            p1, p2, v1, v2 = held_rk4(acc, p1, p2, v1, v2, u1, u2, h, sub)
    except (TpmVizError, ZeroDivisionError, OverflowError, ValueError) as exc:
        raise failed_at(exc, k * period) from None
    return ControlRun(
        name=name,
        setup=setup,
        plant_params=plant_params,
        model_params=model_params,
        t=t,
        p_ref=p_ref,
        dp_ref=dp_ref,
        p=out[:, 0:2].copy(),
        dp=out[:, 2:4].copy(),
        tau=out[:, 4:6].copy(),
        tau_ff=out[:, 6:8].copy(),
        saturated=out[:, 8] > 0.5,
    )
