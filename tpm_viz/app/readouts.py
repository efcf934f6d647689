"""Every number the app shows for one pose, computed without a browser.

:func:`evaluate` turns a :class:`~tpm_viz.app.moves.Pose` and a :class:`Load` into a :class:`Readout`:
the kinematic quantities (eqs. 8-12), the warnings (near an inverse or the direct singularity, at a stroke end)
and the actuator forces from the paper's closed form next to an independent reference (the Pinocchio model,
passed in as a function so that this module stays pure numpy).

Loads (SI). *Static*: an external force ``f_ext`` [N] applied **to** the platform at rest; the actuators hold it
with ``τ = J^{-T} f`` where ``f = -f_ext`` is the force the platform exerts on its surroundings (eq. 13); this
is eq. (31) with zero velocity and acceleration (``tpm_viz.inverse_dynamics(..., f_ext=f_ext)``).
*Dynamic*: the platform velocity ``ṗ`` [m/s] and acceleration ``p̈`` [m/s²], no external force, eq. (31).
Every number in a :class:`Readout` is finite; what cannot be computed is ``None`` (with a reason for forces).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple, Protocol, SupportsFloat

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.app.moves import Pose
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.kinematics import forward_kinematics_both
from tpm_viz.paper.status import WARN, SingularityThresholds

__all__ = ["LOAD_MODES", "Alert", "Forces", "Load", "Readout", "Reference", "evaluate", "joined", "reason"]
__all__ += ["with_reference"]

LOAD_MODES = ("static", "dynamic")


class Reference(Protocol):
    """The reference model's inverse dynamics: ``reference(params, p, dp, ddp, f_ext=None) -> τ`` [N], working mode,
    for one state (shape (2,)) or arrays of states (shape (n, 2)), e.g. ``tpm_viz.multibody.inverse_dynamics``
    (the app layer never imports Pinocchio: the UI passes it in)."""

    def __call__(
        self, params: Params, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None = None
    ) -> np.ndarray: ...


STROKE_END_TOL = 0.5e-3
"""An actuator within this distance [m] of 0 or ``Δd`` counts as *at* its stroke end."""


def _vec2(value: Iterable[str | SupportsFloat], name: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(Phrase("{name} must be two numbers, got {got}", name=name, got=repr(value))) from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InputError(Phrase("{name} must be finite, got ({x:g}, {y:g})", name=name, x=x, y=y))
    return (x, y)


def reason(exc: BaseException) -> Phrase:
    """The words of an error as a phrase (its own phrase, or its English text), to quote in another phrase."""
    first = exc.args[0] if exc.args else None
    return first if isinstance(first, Phrase) else Phrase("{text}", text=str(exc))


def joined(lines: list[Phrase]) -> Phrase | str:
    """``lines`` as one line, separated by ``"; "`` (empty if none)."""
    if not lines:
        return ""
    out = lines[0]
    for line in lines[1:]:
        out = Phrase("{first}; {then}", first=out, then=line)
    return out


@dataclass(frozen=True)
class Load:
    """What the actuators work against (SI units); see the module docstring."""

    mode: str = "static"
    """``"static"`` (external force ``f_ext`` at rest, eq. 13) or ``"dynamic"`` (motion ``ṗ, p̈``, eq. 31)."""
    f_ext: tuple[float, float] = (0.0, 0.0)
    """External force applied **to** the platform [N] (static mode)."""
    dp: tuple[float, float] = (0.0, 0.0)
    """Platform velocity ``ṗ`` [m/s] (dynamic mode)."""
    ddp: tuple[float, float] = (0.0, 0.0)
    """Platform acceleration ``p̈`` [m/s²] (dynamic mode)."""

    def __post_init__(self) -> None:
        if self.mode not in LOAD_MODES:
            raise InputError(Phrase("load mode must be 'static' or 'dynamic', got {mode}", mode=repr(self.mode)))
        for name in ("f_ext", "dp", "ddp"):
            object.__setattr__(self, name, _vec2(getattr(self, name), name))

    def motion(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(ṗ, p̈, f_ext)`` as arrays that the dynamics functions take (zeros where the mode ignores them)."""
        zero = np.zeros(2)
        if self.mode == "static":
            return zero, zero, np.array(self.f_ext)
        return np.array(self.dp), np.array(self.ddp), zero


@dataclass(frozen=True)
class Forces:
    """Actuator forces [N]: the paper's closed form, the reference model and their difference."""

    tau: np.ndarray | None
    """Closed form, eqs. (29)-(31) (eq. 13 in static mode), shape (2,); None if it cannot be computed."""
    tau_ref: np.ndarray | None
    """Reference model (Pinocchio), shape (2,); None if unavailable (see ``note``)."""
    equation: str
    """Which equation produced ``tau``, for the label."""
    note: str | Phrase = ""
    """Why ``tau`` or ``tau_ref`` is missing (one line; rendered with ``say``), else empty."""

    @property
    def diff(self) -> np.ndarray | None:
        """``tau_ref - tau`` [N], or None."""
        if self.tau is None or self.tau_ref is None:
            return None
        return self.tau_ref - self.tau


class Alert(NamedTuple):
    """One warning line and its kind: ``"inverse"``, ``"direct"`` or ``"stroke"``."""

    kind: str
    text: Phrase
    """The line (rendered in a tab's language with ``say``; ``str()``: English)."""


@dataclass(frozen=True)
class Readout:
    """The displayed quantities of one pose (SI units, angles in rad); every float is finite."""

    p: np.ndarray  # (2,) platform position [m]
    d: np.ndarray  # (2,) actuator positions [m]
    theta: np.ndarray  # (2,) leg angles θ_i [rad] (eq. 23)
    det_jx: float  # cos(θ1 + θ2), eq. (12)
    det_jq: float  # cos θ1 cos θ2, eq. (11)
    cond: float | None  # condition number of J (eq. 10), None if infinite
    mode: int  # assembly mode, sign of det J_x
    other_p: np.ndarray | None  # (2,) the other assembly mode's platform position [m], if it exists
    near_inverse: tuple[bool, bool]  # per leg: |cos θ_i| below the threshold
    near_direct: bool  # |cos(θ1 + θ2)| below the threshold
    stroke_end: tuple[int, int]  # per actuator: -1 at d_i = 0, +1 at d_i = Δd, 0 otherwise
    forces: Forces
    alerts: tuple[Alert, ...] = ()


def _finite(x: ArrayLike | None) -> bool:
    return x is not None and bool(np.all(np.isfinite(x)))


def _condition(j: np.ndarray) -> float:
    """2-norm condition number of ``J`` (eq. 10), as :func:`tpm_viz.condition_number`; ``inf`` if singular."""
    if not np.all(np.isfinite(j)):
        return math.inf
    sv = np.linalg.svd(j, compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf


def _forces(params: Params, pose: Pose, load: Load, reference: Reference | None) -> Forces:
    dp, ddp, f_ext = load.motion()
    equation = "eq. 13: τ = J⁻ᵀ(−f_ext)" if load.mode == "static" else "eq. 31"
    notes: list[Phrase] = []
    try:
        tau = inverse_dynamics(params, pose.p, dp, ddp, f_ext, d=pose.d)
    except TpmVizError as exc:
        tau, notes = None, [reason(exc)]
    if not _finite(tau):
        tau = None
    tau_ref = None
    if reference is None:
        notes.append(T("no reference model"))
    elif np.any(pose.branch(params) < 0):
        notes.append(T("the Pinocchio model covers the working mode (eq. 4) only"))
    else:
        try:
            tau_ref = np.asarray(reference(params, pose.p, dp, ddp, f_ext), dtype=float).reshape(2)
        except (TpmVizError, ArithmeticError, np.linalg.LinAlgError) as exc:
            notes.append(Phrase("reference model: {why}", why=reason(exc)))
        if not _finite(tau_ref):
            tau_ref = None
    return Forces(tau, tau_ref, equation, joined(notes))


def with_reference(readout: Readout, params: Params, pose: Pose, load: Load, reference: Reference | None) -> Readout:
    """``readout`` (of ``pose`` under ``load``, computed without a reference) with the reference forces added: the
    same numbers as :func:`evaluate` with ``reference``, without computing the kinematics again."""
    return dataclasses.replace(readout, forces=_forces(params, pose, load, reference))


def evaluate(
    params: Params,
    pose: Pose,
    load: Load = Load(),
    reference: Reference | None = None,
    thresholds: SingularityThresholds = WARN,
) -> Readout:
    """All displayed quantities at ``pose`` under ``load`` (see the module docstring)."""
    jac = jacobians(params, pose.p, pose.d)
    det_jx, det_jq = float(jac.det_jx), float(jac.det_jq)
    cos = np.array([jac.jq[0, 0], jac.jq[1, 1]])
    sin = np.array([jac.jx[0, 1], jac.jx[1, 0]])
    cond = _condition(jac.j)
    mode = pose.mode(params)
    with np.errstate(invalid="ignore", divide="ignore"):
        sol = forward_kinematics_both(params, pose.d)
    other = sol.minus if mode > 0 else sol.plus
    other_p = np.array(other, dtype=float) if bool(sol.exists) and _finite(other) else None
    near_inverse = tuple(bool(abs(c) < thresholds.inverse) for c in cos)
    near_direct = abs(det_jx) < thresholds.direct
    stroke_end = tuple(
        -1 if di <= STROKE_END_TOL else (1 if di >= params.stroke - STROKE_END_TOL else 0) for di in pose.d
    )
    alerts = []
    for i in range(2):
        if stroke_end[i]:
            end = 0.0 if stroke_end[i] < 0 else params.stroke * 1e3
            alerts.append(
                Alert(
                    "stroke",
                    Phrase(
                        "Slider {i} is against its end-stop (d{i} = {end} mm): actuator {i} can only move it back "
                        "into the stroke",
                        i=i + 1,
                        end=fixed(end, ".1f"),
                    ),
                )
            )
    if near_direct:
        alerts.append(
            Alert(
                "direct",
                Phrase(
                    "Near the direct singularity: the platform is losing its stiffness in one direction and the "
                    "actuator forces grow without bound for a load along it (cos(θ1+θ2) = {value}, eq. 12)",
                    value=fixed(det_jx, ".3f"),
                ),
            )
        )
    for i in range(2):
        if near_inverse[i]:
            alerts.append(
                Alert(
                    "inverse",
                    Phrase(
                        "Near an inverse singularity: the links of leg {i} stand almost perpendicular to rail {i}, "
                        "so slider {i} must move far for a small platform motion along them (cos θ{i} = {value}, "
                        "eq. 11)",
                        i=i + 1,
                        value=fixed(cos[i], ".3f"),
                    ),
                )
            )
    return Readout(
        p=pose.p.copy(),
        d=pose.d.copy(),
        theta=np.arctan2(sin, cos),  # eq. (23) on the pose's branch
        det_jx=det_jx,
        det_jq=det_jq,
        cond=cond if math.isfinite(cond) else None,
        mode=mode,
        other_p=other_p,
        near_inverse=near_inverse,  # type: ignore[arg-type]
        near_direct=near_direct,
        stroke_end=stroke_end,  # type: ignore[arg-type]
        forces=_forces(params, pose, load, reference),
        alerts=tuple(alerts),
    )
