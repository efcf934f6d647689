"""Paper closed form vs the Pinocchio multibody model: the comparisons behind ``tpm-viz crosscheck``
and the figures (paper Figs. 4-5, where the authors compared against ADAMS).

Three cases: the line and the circle trajectories (inverse dynamics at every sample, plus the
forward-dynamics replay of :mod:`tpm_viz.multibody.replay`), and seeded random regular states with random
velocities, accelerations and external platform forces. "Agree" is ``docs/conventions.md``'s rule:
``|Δτ| / (1 N + |τ|) <= 1e-9``, tracking within 0.1 mm and closures within 1e-6 m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.multibody.model import inverse_dynamics as pinocchio_inverse_dynamics
from tpm_viz.multibody.replay import replay
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.jacobians import classify
from tpm_viz.paper.trajectories import paper_duration, paper_trajectory

__all__ = [
    "CrosscheckRow",
    "ForceComparison",
    "Tolerances",
    "compare_forces",
    "crosscheck",
    "format_table",
    "random_regular_states",
]


def _rel(tau: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(tau - ref) / (1.0 + np.abs(ref))))


@dataclass(frozen=True)
class ForceComparison:
    """Actuator forces along one of the paper's trajectories by both models (SI units)."""

    kind: str
    duration: float  # [s]
    t: np.ndarray  # (n,) [s]
    tau_paper: np.ndarray  # (n, 2) eqs. (29)-(31) [N]
    tau_pinocchio: np.ndarray  # (n, 2) closed-loop multibody model [N]

    @property
    def max_abs_diff(self) -> float:
        """``max |τ_pinocchio - τ_paper|`` [N]."""
        return float(np.max(np.abs(self.tau_pinocchio - self.tau_paper)))

    @property
    def max_rel_diff(self) -> float:
        """``max |Δτ| / (1 N + |τ_paper|)`` (dimensionless)."""
        return _rel(self.tau_pinocchio, self.tau_paper)


def compare_forces(params: Params, kind: str, duration: float | None = None, samples: int = 201) -> ForceComparison:
    """Both models' actuator forces along ``kind`` (``"line"`` or ``"circle"``) at ``samples`` times."""
    traj = paper_trajectory(kind, duration, samples)
    tau_paper = inverse_dynamics(params, traj.p, traj.dp, traj.ddp)
    tau_pin = pinocchio_inverse_dynamics(params, traj.p, traj.dp, traj.ddp)
    return ForceComparison(kind, traj.duration, traj.t, tau_paper, tau_pin)


def random_regular_states(
    params: Params, n: int, seed: int = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(p, ṗ, p̈, f_ext)``, each ``(n, 2)``: seeded regular poses (``classify == 0``) in SI units,
    velocities ~ N(0, 1 m/s), accelerations ~ N(0, 20 m/s²), platform forces ~ N(0, 20 N)."""
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError(f"the number of random states must be a positive whole number, got {n!r}")
    rng = np.random.default_rng(seed)
    poses: list[np.ndarray] = []
    for _ in range(200):
        cand = rng.uniform(-params.l_a, params.l_a, (4 * n, 2))
        poses.extend(cand[classify(params, cand) == 0])
        if len(poses) >= n:
            break
    else:
        raise InputError("no regular pose found for these parameters (every pose is singular or out of stroke)")
    p = np.array(poses[:n])
    return p, rng.normal(0, 1.0, (n, 2)), rng.normal(0, 20.0, (n, 2)), rng.normal(0, 20.0, (n, 2))


@dataclass(frozen=True)
class Tolerances:
    """Pass/fail limits of the crosscheck (``docs/conventions.md`` and the issue)."""

    rel: float = 1e-9  # |Δτ| / (1 N + |τ|)
    tracking: float = 1e-4  # m (0.1 mm)
    violation: float = 1e-6  # m


@dataclass(frozen=True)
class CrosscheckRow:
    """One line of the crosscheck table (SI units; ``None`` where a measure does not apply)."""

    case: str
    states: int
    max_abs_dtau: float  # [N]
    max_rel_dtau: float
    tracking_error: float | None  # [m]
    violation: float | None  # [m]
    ok: bool


def crosscheck(
    params: Params,
    duration_line: float | None = None,
    duration_circle: float | None = None,
    n_random: int = 200,
    seed: int = 0,
    dt: float | None = None,
    tol: Tolerances = Tolerances(),
) -> list[CrosscheckRow]:
    """The three comparisons of the module docstring, one :class:`CrosscheckRow` each."""
    rows = []
    for kind, duration in (("line", duration_line), ("circle", duration_circle)):
        duration = paper_duration(kind, duration)
        cmp = compare_forces(params, kind, duration)
        rep = replay(params, kind, duration, dt)
        ok = (
            cmp.max_rel_diff <= tol.rel
            and rep.max_tracking_error <= tol.tracking
            and rep.max_constraint_violation <= tol.violation
        )
        rows.append(
            CrosscheckRow(
                f"{kind} T={cmp.duration:g} s",
                len(cmp.t),
                cmp.max_abs_diff,
                cmp.max_rel_diff,
                rep.max_tracking_error,
                rep.max_constraint_violation,
                ok,
            )
        )
    p, dp, ddp, f = random_regular_states(params, n_random, seed)
    tau_paper = inverse_dynamics(params, p, dp, ddp, f)
    tau_pin = pinocchio_inverse_dynamics(params, p, dp, ddp, f)
    rel = _rel(tau_pin, tau_paper)
    rows.append(
        CrosscheckRow(
            f"random, seed {seed}",
            n_random,
            float(np.max(np.abs(tau_pin - tau_paper))),
            rel,
            None,
            None,
            rel <= tol.rel,
        )
    )
    return rows


def format_table(rows: list[CrosscheckRow], tol: Tolerances = Tolerances()) -> str:
    """A plain-text table of the rows, the tolerances and PASS/FAIL (tracking in mm)."""
    head = f"{'case':<20} {'states':>6} {'max|Δτ| [N]':>12} {'max rel':>10} {'tracking [mm]':>14} {'violation [m]':>14}"
    lines = ["paper closed form (eqs. 29-31) vs Pinocchio closed-loop model", head, "-" * len(head)]
    for r in rows:
        track = "-" if r.tracking_error is None else f"{r.tracking_error * 1e3:.3e}"
        viol = "-" if r.violation is None else f"{r.violation:.3e}"
        lines.append(
            f"{r.case:<20} {r.states:>6} {r.max_abs_dtau:>12.3e} {r.max_rel_dtau:>10.2e} {track:>14} {viol:>14}"
            f"  {'ok' if r.ok else 'FAIL'}"
        )
    lines.append(f"tolerances: rel {tol.rel:g}, tracking {tol.tracking * 1e3:g} mm, violation {tol.violation:g} m")
    lines.append("result: " + ("PASS" if all(r.ok for r in rows) else "FAIL"))
    return "\n".join(lines)
