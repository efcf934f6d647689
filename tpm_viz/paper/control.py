"""Control laws on the paper's closed-form model: PD, PD + feedforward, computed torque.

The paper derives its closed-form inverse dynamics (eqs. 29-31) "for the real-time computed torque
control in the further work" (Sections 1, 3, 5). This module is that further work, on the numpy layer:
the laws are pure functions of a *controller's own* :class:`~tpm_viz.Params` (which may be wrong: see
:func:`model_with_errors`), of the reference and of the measured platform state ``(p, ṗ)``.
The closed-loop simulation (plant, sampling, noise, saturation) is :mod:`tpm_viz.multibody.control`.

Gains from a natural frequency ``ω_n`` [Hz] and a damping ratio ``ζ``: ``ω = 2π ω_n`` [rad/s],
``K_p = ω²`` [1/s²], ``K_d = 2 ζ ω`` [1/s], so that a unit mass under ``K_p e + K_d ė`` obeys
``ë + 2ζω ė + ω² e = 0``. The laws, with ``e = p_ref - p`` (task space) or ``e_d = d_ref - d``
(actuator space, ``d`` by eq. 4, ``ḋ = J ṗ`` by eq. 9):

- ``pd``: ``τ_i = m_i (K_p e_d,i + K_d ė_d,i)`` [N], one decoupled loop per actuator; ``m_i`` [kg] is the
  diagonal of the actuator-space mass matrix of the controller's model at the home pose ``p = 0``
  (:func:`axis_masses`), which turns ``ω_n`` into a stiffness.
- ``pdff``: the same plus the closed-form ``τ(p_ref, ṗ_ref, p̈_ref)`` along the reference (eqs. 29-31).
- ``ctc``: ``τ = ID(p, ṗ, p̈_ref + K_d ė + K_p e)`` with the closed form ``ID`` at the measured state:
  with an exact model and continuous update the error obeys ``ë + K_d ė + K_p e = 0`` exactly.

Each law also returns ``τ_ff`` [N], the part of ``τ`` that does not depend on the tracking error: 0 for
``pd``, ``τ`` along the reference for ``pdff``, ``ID(p, ṗ, p̈_ref)`` for ``ctc``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol, SupportsFloat, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase

# _procedure: the scalar steps (b)-(e) of eqs. (9)-(31); the public single-state inverse_dynamics adds numpy
# checks that cost ~25 µs per call, too slow for a 1 kHz loop in Python (the checks are done here in floats).
from tpm_viz.paper.dynamics import SINGULAR_TOL, _procedure, inverse_dynamics
from tpm_viz.paper.jacobians import actuator_velocity
from tpm_viz.paper.kinematics import inverse_kinematics
from tpm_viz.paper.trajectories import State, Trajectory, circle_state, line_state, paper_duration

__all__ = [
    "CTC_DIRECT_TOL",
    "ControlLaw",
    "ControllerKind",
    "Gains",
    "ReferenceSamples",
    "axis_masses",
    "model_with_errors",
    "reference_state",
    "task_space_command",
]


class ControllerKind(StrEnum):
    """The three control laws."""

    PD = "pd"
    """PD on the actuator coordinates."""
    PDFF = "pdff"
    """PD on the actuator coordinates plus the closed-form feedforward along the reference."""
    CTC = "ctc"
    """Computed torque in task space (feedback linearisation with the closed form)."""

    @classmethod
    def parse(cls, value: str) -> ControllerKind:
        """``value`` as a kind (``"pd"``, ``"pdff"``, ``"ctc"``) or a one-line :class:`InputError`."""
        try:
            return cls(value)
        except ValueError:
            raise InputError(f"controller must be one of pd, pdff, ctc; got {value!r}") from None


def _finite(value: str | SupportsFloat, name: str, low: float, strict: bool = True) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(value) or value < low or (strict and value == low):
        raise InputError(f"{name} must be a finite number {'>' if strict else '>='} {low:g}, got {value:g}")
    return value


@dataclass(frozen=True)
class Gains:
    """Feedback gains from a natural frequency ``wn`` [Hz] and a damping ratio ``zeta`` [-]."""

    wn: float = 10.0
    """Natural frequency ``ω_n`` [Hz] of the error dynamics."""
    zeta: float = 1.0
    """Damping ratio ``ζ`` [-] (1: critically damped)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "wn", _finite(self.wn, "natural frequency wn [Hz]", 0.0))
        object.__setattr__(self, "zeta", _finite(self.zeta, "damping ratio zeta", 0.0, strict=False))

    @property
    def omega(self) -> float:
        """``ω = 2π ω_n`` [rad/s]."""
        return 2.0 * math.pi * self.wn

    @property
    def kp(self) -> float:
        """``K_p = ω²`` [1/s²]."""
        return self.omega**2

    @property
    def kd(self) -> float:
        """``K_d = 2 ζ ω`` [1/s]."""
        return 2.0 * self.zeta * self.omega


def model_with_errors(params: Params, m_a: float = 0.0, m_b: float = 0.0, m_p: float = 0.0) -> Params:
    """The controller's model: ``params`` with relative mass errors (``m_a (1 + m_a_error)``, ...) [-]."""
    errors = {"m_a": m_a, "m_b": m_b, "m_p": m_p}
    changes = {}
    for name, err in errors.items():
        err = _finite(err, f"relative error of {name}", -1.0)
        changes[name] = getattr(params, name) * (1.0 + err)
    return params.replace(**changes)


def axis_masses(params: Params) -> tuple[float, float]:
    """Diagonal ``m_i`` [kg] of the actuator-space mass matrix at the home pose ``p = 0``.

    At ``p = 0``, ``J = I`` (eq. 10) and ``ṗ = 0`` leaves no velocity terms, so the closed-form force
    for ``p̈ = e_i`` (eqs. 29-31) is column ``i`` of that matrix (``m_p + m_a + 4 m_b / 3`` for the paper's
    mass model).
    """
    tau = inverse_dynamics(params, np.zeros((2, 2)), np.zeros((2, 2)), np.eye(2))
    return float(tau[0, 0]), float(tau[1, 1])


# ----------------------------------------------------------------------------- references
_HERMITE = np.array(  # quintic Hermite basis: rows = [p0, h v0, h² a0, h² a1, h v1, p1], columns = s^0..s^5
    [
        [1, 0, 0, -10, 15, -6],
        [0, 1, 0, -6, 8, -3],
        [0, 0, 0.5, -1.5, 1.5, -0.5],
        [0, 0, 0, 0.5, -1, 0.5],
        [0, 0, 0, -4, 7, -3],
        [0, 0, 0, 10, -15, 6],
    ]
)


def _hermite(traj: Trajectory, t: np.ndarray) -> State:
    """``(p, ṗ, p̈)`` of ``traj`` at times ``t`` by quintic Hermite interpolation of its samples.

    Exact for any trajectory that is a polynomial of degree <= 5 between samples (so for the cubic
    spline of :func:`~tpm_viz.paper.trajectories.trajectory_from_samples`); at rest at the last sample
    after the end, at the first sample before the start.
    """
    ts = np.asarray(traj.t, dtype=float)
    k = np.clip(np.searchsorted(ts, t, side="right") - 1, 0, ts.size - 2)
    h = ts[k + 1] - ts[k]
    s = np.clip((t - ts[k]) / h, 0.0, 1.0)[:, None]
    hh = h[:, None]
    nodes = [traj.p[k], hh * traj.dp[k], hh**2 * traj.ddp[k], hh**2 * traj.ddp[k + 1], hh * traj.dp[k + 1]]
    nodes.append(traj.p[k + 1])
    coef = np.einsum("rc,rnx->ncx", _HERMITE, np.stack(nodes))  # (n, 6, 2): monomial coefficients
    powers = s ** np.arange(6)  # (n, 6): s^0..s^5
    p = np.einsum("nc,ncx->nx", powers, coef)
    dpow = np.concatenate([np.zeros((len(t), 1)), powers[:, :5] * np.arange(1, 6)], axis=1)
    ddpow = np.concatenate([np.zeros((len(t), 2)), powers[:, :4] * np.array([2, 6, 12, 20])], axis=1)
    dp = np.einsum("nc,ncx->nx", dpow, coef) / hh
    ddp = np.einsum("nc,ncx->nx", ddpow, coef) / hh**2
    outside = (t < ts[0]) | (t > ts[-1])
    dp[outside], ddp[outside] = 0.0, 0.0
    return p, dp, ddp


def reference_state(reference: str | Trajectory, t: ArrayLike, duration: float | None = None) -> State:
    """Reference ``(p, ṗ, p̈)`` [m, m/s, m/s²], each ``(n, 2)``, at times ``t`` [s] ``(n,)``.

    ``reference``: ``"line"`` or ``"circle"`` (the paper's Figs. 4-5, exact, path duration ``duration``
    [s], default 0.2 / 0.5 s) or any :class:`~tpm_viz.paper.trajectories.Trajectory` (a user's CSV, a
    planned motion), interpolated by :func:`_hermite`; ``duration`` must then be None.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    if isinstance(reference, Trajectory):
        if duration is not None:
            raise InputError("a sampled trajectory has its own duration: do not give one")
        return _hermite(reference, t)
    if isinstance(reference, str):
        duration = paper_duration(reference, duration)
        return (line_state if reference == "line" else circle_state)(t, duration)
    raise InputError(f"reference must be 'line', 'circle' or a Trajectory, got {type(reference).__name__}")


@dataclass(frozen=True)
class ReferenceSamples:
    """The reference at the controller's sample times with the model quantities that do not depend on
    the measurement (closed form with the controller's parameters); arrays ``(n, 2)``, SI."""

    t: np.ndarray  # (n,) [s]
    p: np.ndarray  # [m]
    dp: np.ndarray  # [m/s]
    ddp: np.ndarray  # [m/s²]
    d: np.ndarray  # actuator positions, eq. (4) [m]
    dd: np.ndarray  # actuator velocities, eq. (9) [m/s]
    tau: np.ndarray  # closed-form forces along the reference, eqs. (29)-(31) [N]

    def rows(self) -> list[tuple[float, ...]]:
        """Per sample ``(p1, p2, ṗ1, ṗ2, p̈1, p̈2, d1, d2, ḋ1, ḋ2, τ1, τ2)`` as floats (for the sampled loop)."""
        return [tuple(r) for r in np.concatenate([self.p, self.dp, self.ddp, self.d, self.dd, self.tau], 1).tolist()]


# ----------------------------------------------------------------------------- the laws
class Arithmetic(Protocol):
    """A number :func:`task_space_command` computes with: a float, or a symbol of the C generator."""

    def __add__(self: _N, other: _N, /) -> _N: ...

    def __sub__(self: _N, other: _N, /) -> _N: ...

    def __mul__(self: _N, other: _N, /) -> _N: ...


_N = TypeVar("_N", bound=Arithmetic)

CTC_DIRECT_TOL = 1e-9
"""The computed-torque law refuses a measured pose with ``|c_1 c_2 - p_1 p_2| < CTC_DIRECT_TOL l_a²``, i.e.
``|cos(θ1 + θ2)|`` below it (eq. 12); at the inverse singularity it refuses where the closed form does
(``SINGULAR_TOL``, eq. 11). The generated C (:mod:`tpm_viz.exchange.c.code`) reads both from here."""


def task_space_command(p_ref: _N, dp_ref: _N, ddp_ref: _N, p: _N, dp: _N, kp: _N, kd: _N) -> _N:
    """The computed-torque law's commanded acceleration on one axis [m/s²]:
    ``p̈_ref + K_d (ṗ_ref - ṗ) + K_p (p_ref - p)`` (floats, arrays, or the C generator's symbols)."""
    return ddp_ref + kd * (dp_ref - dp) + kp * (p_ref - p)


ForceFunction = Callable[[tuple[float, ...], float, float, float, float], tuple[float, float, float, float]]
"""``f(row, p1, p2, ṗ1, ṗ2) -> (τ1, τ2, τ_ff1, τ_ff2)`` [N] of :meth:`ControlLaw.force_function`."""


@dataclass(frozen=True)
class ControlLaw:
    """One controller: its ``kind``, its own model ``params`` (possibly wrong) and its ``gains``."""

    kind: ControllerKind
    params: Params
    gains: Gains = Gains()

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", ControllerKind.parse(self.kind))
        if not isinstance(self.params, Params) or not isinstance(self.gains, Gains):
            raise InputError("ControlLaw needs a tpm_viz.Params and a Gains")

    @property
    def masses(self) -> tuple[float, float]:
        """``m_i`` [kg] of the PD loops (:func:`axis_masses` of the controller's model)."""
        return axis_masses(self.params)

    def sample(self, t: ArrayLike, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike) -> ReferenceSamples:
        """The reference quantities this law needs at sample times ``t`` [s] (vectorised, closed form)."""
        p, dp, ddp = (np.asarray(x, dtype=float) for x in (p, dp, ddp))
        d = inverse_kinematics(self.params, p)
        return ReferenceSamples(
            t=np.asarray(t, dtype=float),
            p=p,
            dp=dp,
            ddp=ddp,
            d=d,
            dd=actuator_velocity(self.params, p, dp, d),
            tau=inverse_dynamics(self.params, p, dp, ddp),
        )

    def force_function(self) -> ForceFunction:
        """``f(row, p1, p2, ṗ1, ṗ2) -> (τ1, τ2, τ_ff1, τ_ff2)`` [N] for one sample (floats, no arrays).

        ``row`` is one entry of :meth:`ReferenceSamples.rows`; ``p, ṗ`` [m, m/s] the measured platform
        state. Raises :class:`~tpm_viz.core.errors.TpmVizError` if the measured pose is unreachable or singular.
        """
        prm, kp, kd = self.params, self.gains.kp, self.gains.kd
        la, k = prm.l_a, prm.a - prm.b
        m1, m2 = self.masses

        def legs(p1: float, p2: float) -> tuple[float, float]:
            if not (abs(p1) < la and abs(p2) < la):  # as inverse_dynamics refuses (eq. 4); also catches NaN
                raise UnreachablePoseError(
                    Phrase(
                        "the measured platform position ({x}, {y}) mm is outside |p_j| < l_a",
                        x=fixed(p1, ".1f", 1e3),
                        y=fixed(p2, ".1f", 1e3),
                    )
                )
            c1, c2 = math.sqrt(la * la - p2 * p2), math.sqrt(la * la - p1 * p1)
            if abs(c1 * c2) < SINGULAR_TOL * (la * la):  # as inverse_dynamics refuses (eq. 11)
                raise SingularConfigurationError(Phrase("the measured pose is at the inverse singularity (eq. 11)"))
            if abs(c1 * c2 - p1 * p2) < CTC_DIRECT_TOL * (la * la):
                raise SingularConfigurationError(Phrase("the measured pose is at the direct singularity (eq. 12)"))
            return c1, c2

        def pd(
            row: tuple[float, ...], p1: float, p2: float, dp1: float, dp2: float, ff1: float, ff2: float
        ) -> tuple[float, float, float, float]:
            c1, c2 = legs(p1, p2)
            d1, d2 = p1 + k - c1, p2 + k - c2  # eq. (4)
            dd1, dd2 = dp1 + p2 / c1 * dp2, dp2 + p1 / c2 * dp1  # eq. (9): ḋ_i = ṗ_i + tan θ_i ṗ_j
            tau1 = ff1 + m1 * (kp * (row[6] - d1) + kd * (row[8] - dd1))
            tau2 = ff2 + m2 * (kp * (row[7] - d2) + kd * (row[9] - dd2))
            return tau1, tau2, ff1, ff2

        if self.kind is ControllerKind.PD:
            return lambda row, p1, p2, dp1, dp2: pd(row, p1, p2, dp1, dp2, 0.0, 0.0)
        if self.kind is ControllerKind.PDFF:
            return lambda row, p1, p2, dp1, dp2: pd(row, p1, p2, dp1, dp2, row[10], row[11])

        def ctc(
            row: tuple[float, ...], p1: float, p2: float, dp1: float, dp2: float
        ) -> tuple[float, float, float, float]:
            c1, c2 = legs(p1, p2)
            a1 = task_space_command(row[0], row[2], row[4], p1, dp1, kp, kd)
            a2 = task_space_command(row[1], row[3], row[5], p2, dp2, kp, kd)
            tau = _procedure(prm, p1, p2, dp1, dp2, a1, a2, c1, c2, 0.0, 0.0)  # eqs. (29)-(31) at the measurement
            ff = _procedure(prm, p1, p2, dp1, dp2, row[4], row[5], c1, c2, 0.0, 0.0)
            return tau[10], tau[11], ff[10], ff[11]

        return ctc

    def force(
        self, row: tuple[float, ...], p: Sequence[float] | np.ndarray, dp: Sequence[float] | np.ndarray
    ) -> np.ndarray:
        """``(τ1, τ2, τ_ff1, τ_ff2)`` [N] for one sample (convenience wrapper of :meth:`force_function`)."""
        return np.array(self.force_function()(row, float(p[0]), float(p[1]), float(dp[0]), float(dp[1])))
