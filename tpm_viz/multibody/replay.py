"""Forward-dynamics replay: the paper's actuator forces drive the Pinocchio model (the ADAMS check).

The closed-form actuator forces ``τ(t)`` (eqs. 29-31, :func:`tpm_viz.inverse_dynamics`) along the
paper's line or circle (Figs. 4-5) are applied open-loop to the closed-loop multibody model
(:mod:`tpm_viz.multibody.model`), whose constrained forward dynamics is integrated with the classical
Runge-Kutta scheme (RK4) in the joint coordinates ``(q, v)``. ``τ`` is evaluated exactly at every
RK4 stage time from :func:`tpm_viz.line_state` / :func:`tpm_viz.circle_state`.

Constraint stabilisation: after every step the state is projected back on the closures
(:meth:`MultibodyModel.project`: minimum-norm Newton steps on the positions, then the velocity
projected on the admissible motions). The recorded ``constraint_violation`` is the closure gap
*before* that projection, i.e. what one RK4 step lets drift. If both models describe the same
mechanism, the simulated platform follows the reference; its error measures the agreement.

This module does not import Pinocchio itself; it only calls :mod:`tpm_viz.multibody.model`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.multibody.model import model_for
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.trajectories import circle_state, line_state, paper_duration, positive_seconds

__all__ = ["DEFAULT_DT", "MAX_STEPS", "MIN_STEPS", "ReplayResult", "replay"]

DEFAULT_DT = 1e-3
"""Largest default RK4 step [s]."""
MIN_STEPS = 200
"""The default step is ``min(DEFAULT_DT, duration / MIN_STEPS)``: short, violent motions get finer steps."""
MAX_STEPS = 200_000
"""Upper bound on the number of steps (duration / dt) of one replay."""


@dataclass(frozen=True)
class ReplayResult:
    """One replay, sampled at every step (``n = steps + 1`` samples, SI units)."""

    kind: str  # "line" or "circle"
    duration: float  # T [s]
    dt: float  # RK4 step [s]
    t: np.ndarray  # (n,) time [s]
    p_ref: np.ndarray  # (n, 2) reference platform position [m]
    p_sim: np.ndarray  # (n, 2) simulated platform position [m]
    tau: np.ndarray  # (n, 2) applied actuator forces (closed form; one-sided at t = 0 and T) [N]
    constraint_violation: np.ndarray  # (n,) largest closure gap before projection [m]
    d_sim: np.ndarray  # (n, 2) simulated actuator positions [m]
    dd_sim: np.ndarray  # (n, 2) simulated actuator velocities [m/s]
    kinetic_energy: np.ndarray  # (n,) kinetic energy of the multibody model [J]

    @property
    def tracking_error(self) -> np.ndarray:
        """``|p_sim - p_ref|`` [m], shape ``(n,)``."""
        return np.linalg.norm(self.p_sim - self.p_ref, axis=-1)

    @property
    def max_tracking_error(self) -> float:
        """Largest tracking error over the replay [m]."""
        return float(np.max(self.tracking_error))

    @property
    def max_constraint_violation(self) -> float:
        """Largest closure gap over the replay [m]."""
        return float(np.max(self.constraint_violation))


def _steps(duration: float, dt: float | None) -> int:
    dt = min(DEFAULT_DT, duration / MIN_STEPS) if dt is None else positive_seconds(dt, T("time step"))
    steps = max(1, math.ceil(duration / dt - 1e-9))
    if steps > MAX_STEPS:
        raise InputError(
            Phrase("duration / dt = {steps} steps exceeds the limit of {most}", steps=steps, most=MAX_STEPS)
        )
    return steps


def replay(
    params: Params,
    kind: str,
    duration: float | None = None,
    dt: float | None = None,
    force_params: Params | None = None,
) -> ReplayResult:
    """Drive the Pinocchio model with the paper's actuator forces along ``kind`` (``"line"``/``"circle"``).

    ``duration`` [s] defaults to :data:`tpm_viz.DEFAULT_DURATIONS`; ``dt`` [s] (default
    ``min(DEFAULT_DT, duration / MIN_STEPS)``) is rounded down so that whole RK4 steps span the
    duration. ``force_params`` (default ``params``) are the parameters the closed-form forces are
    computed with: a mismatch shows as a tracking error.
    Raises :mod:`tpm_viz.core.errors` exceptions for bad input, an unreachable path or a singular
    configuration on it.
    """
    if not isinstance(params, Params) or not isinstance(force_params, Params | None):
        raise InputError("replay needs tpm_viz.Params parameter sets")
    duration = paper_duration(kind, duration)
    steps = _steps(duration, dt)
    h = duration / steps
    state = line_state if kind == "line" else circle_state
    stage_t = np.linspace(0.0, duration, 2 * steps + 1)  # t_k and t_k + h/2
    # The cubic law's acceleration jumps at t = 0 and t = T (it is 0 outside): use the one-sided
    # values there, those of the step being integrated (else RK4 drops to first order).
    one_sided = stage_t.copy()
    one_sided[[0, -1]] = [1e-12 * duration, duration * (1 - 1e-12)]
    p_all, dp_all, ddp_all = state(one_sided, duration)
    tau_all = inverse_dynamics(force_params or params, p_all, dp_all, ddp_all)  # eqs. 29-31 at every stage
    model = model_for(params)
    sl = [model.index["slider1"], model.index["slider2"]]

    q, v, _ = model.constrained_motion(p_all[0], dp_all[0], ddp_all[0])
    n = steps + 1
    p_sim, d_sim, dd_sim = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2))
    violation, energy = np.empty(n), np.empty(n)
    violation[0] = model.constraint_violation(q)

    def record(k: int, q: np.ndarray, v: np.ndarray) -> None:
        p_sim[k], d_sim[k], dd_sim[k] = model.platform_position(q), q[sl], v[sl]
        energy[k] = model.kinetic_energy(q, v)

    record(0, q, v)
    fd = model.forward_dynamics
    for k in range(steps):
        tau0, tau_half, tau1 = tau_all[2 * k], tau_all[2 * k + 1], tau_all[2 * k + 2]
        a1 = fd(q, v, tau0)
        q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
        a2 = fd(q2, v2, tau_half)
        q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
        a3 = fd(q3, v3, tau_half)
        q4, v4 = q + h * v3, v + h * a3
        a4 = fd(q4, v4, tau1)
        q = q + h / 6.0 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
        violation[k + 1] = model.constraint_violation(q)
        q, v = model.project(q, v)
        record(k + 1, q, v)
    return ReplayResult(
        kind=kind,
        duration=duration,
        dt=h,
        t=stage_t[::2].copy(),
        p_ref=state(stage_t[::2], duration)[0],
        p_sim=p_sim,
        tau=tau_all[::2].copy(),
        constraint_violation=violation,
        d_sim=d_sim,
        dd_sim=dd_sim,
        kinetic_energy=energy,
    )
