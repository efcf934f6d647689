"""``tpm-viz kinematics | dynamics | trajectory``: the paper's closed form on CSV files (SI units)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from tpm_viz.cli.common import check_output, params_from_args, positive_float, write_output
from tpm_viz.core.csvio import read_columns, time_unit_note
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import parse_number, plausibility_note, shorten
from tpm_viz.core.params import Params
from tpm_viz.paper.dynamics import inverse_dynamics_detail
from tpm_viz.paper.jacobians import classify, condition_number, jacobians
from tpm_viz.paper.kinematics import inverse_kinematics, leg_angles, reachable
from tpm_viz.paper.status import STATUS_LABELS
from tpm_viz.paper.trajectories import MAX_CSV_ROWS, paper_trajectory, trajectory_from_samples

__all__ = ["DYN_IN", "register"]

DYN_IN = ["p1", "p2", "dp1", "dp2", "ddp1", "ddp2"]
"""Input columns of ``tpm-viz dynamics`` (SI)."""


def _parse_fext(text: str | None) -> np.ndarray | None:
    if text is None:
        return None
    parts = text.split(";") if ";" in text else text.split(",")  # "1,5;-2" : decimal commas with a semicolon
    if len(parts) != 2:
        raise InputError(f"--fext expects two numbers FX,FY (or FX;FY) in newtons, got {shorten(text)}")
    return np.array([parse_number(x, "--fext", "N") for x in parts])


def _kinematics_columns(params: Params, p: np.ndarray) -> dict[str, np.ndarray]:
    ok = reachable(params, p)
    safe = np.where(ok[:, None], p, 0.0)
    d = inverse_kinematics(params, safe)
    theta = leg_angles(params, safe, d)
    jac = jacobians(params, safe, d)
    cond = condition_number(params, safe, d)
    nan = np.full(len(p), np.nan)
    status = classify(params, p)
    return {
        "d1": np.where(ok, d[:, 0], nan),
        "d2": np.where(ok, d[:, 1], nan),
        "theta1": np.where(ok, theta[:, 0], nan),
        "theta2": np.where(ok, theta[:, 1], nan),
        "det_jx": np.where(ok, jac.det_jx, nan),
        "det_jq": np.where(ok, jac.det_jq, nan),
        "cond": np.where(ok, cond, nan),
        "reachable": ok.astype(int),
        "status": np.array([STATUS_LABELS[int(s)].replace(" ", "_") for s in status]),
    }


def _dynamics_columns(params: Params, p, dp, ddp, fext, model: str) -> dict[str, np.ndarray]:
    res = inverse_dynamics_detail(params, p, dp, ddp, fext)
    tau = res.tau
    if model == "pinocchio":
        from tpm_viz import multibody  # heavy layer (pinocchio), loaded only for --model pinocchio

        tau = multibody.inverse_dynamics(params, p, dp, ddp, fext)
    cols = {}
    for name, arr in (("d", res.d), ("dd", res.dd), ("ddd", res.ddd), ("tau", tau)):
        cols[name + "1"], cols[name + "2"] = arr[:, 0], arr[:, 1]
    return cols


def _check_reachable(params: Params, p: np.ndarray) -> None:
    ok = reachable(params, p)
    if not np.all(ok):
        r = int(np.argmax(~ok))
        hint = "; if the file is in millimetres, name the columns 'p1 [mm]','p2 [mm]'" if np.max(np.abs(p)) > 1 else ""
        raise InputError(
            f"row {r + 2}: platform position ({p[r, 0]:g}, {p[r, 1]:g}) m is unreachable "
            f"(|p_j| must be below l_a = {params.l_a:g} m){hint}"
        )


def _check_forces(params: Params, cols: dict[str, np.ndarray]) -> None:
    """Refuse forces that overflow; a note on stderr when they exceed 1000 times the moving mass's weight."""
    for name in ("tau1", "tau2"):
        bad = ~np.isfinite(cols[name])
        if np.any(bad):
            raise InputError(
                f"data row {int(np.argmax(bad)) + 1}: the force {name} overflows; the velocities or accelerations "
                "are far too large (SI units: m/s, m/s^2)"
            )
    peak = float(np.max(np.abs([cols["tau1"], cols["tau2"]])))
    note = plausibility_note(peak, "the largest actuator force", "N", typical=params.moving_mass * 9.81)
    if note:
        print(f"tpm-viz: {note} (velocities in m/s, accelerations in m/s^2?)", file=sys.stderr)


def _cmd_kinematics(args) -> int:
    params = params_from_args(args)
    check_output(args.output, args.input)
    table = read_columns(args.input, ["p1", "p2"])
    p = np.stack([table["p1"], table["p2"]], -1)
    cols = dict(table)
    with np.errstate(all="ignore"):
        cols.update(_kinematics_columns(params, p))
    write_output(args.output, cols)
    return 0


def _cmd_dynamics(args) -> int:
    params = params_from_args(args)
    fext = _parse_fext(args.fext)
    check_output(args.output, args.input)
    table = read_columns(args.input, DYN_IN)
    p, dp, ddp = (np.stack([table[a], table[b]], -1) for a, b in zip(DYN_IN[::2], DYN_IN[1::2], strict=True))
    _check_reachable(params, p)
    cols = dict(table)
    with np.errstate(all="ignore"):
        cols.update(_dynamics_columns(params, p, dp, ddp, fext, args.model))
    _check_forces(params, cols)
    write_output(args.output, cols)
    return 0


def _cmd_trajectory(args) -> int:
    params = params_from_args(args)
    fext = _parse_fext(args.fext)
    if args.input is not None:
        if args.duration is not None:
            raise InputError("--duration applies to --kind, not to a trajectory read with --input")
        check_output(args.output, args.input)
        table = read_columns(args.input, ["t", "p1", "p2"], max_rows=MAX_CSV_ROWS)
        note = time_unit_note(table)
        if note:
            print(f"tpm-viz: {note}", file=sys.stderr)
        with np.errstate(all="ignore"):
            traj = trajectory_from_samples(table["t"], np.stack([table["p1"], table["p2"]], -1), args.input)
        if not (np.all(np.isfinite(traj.dp)) and np.all(np.isfinite(traj.ddp))):
            raise InputError(f"{args.input}: samples too close in time: the velocities or accelerations overflow")
    else:
        traj = paper_trajectory(args.kind, args.duration, args.samples)
    _check_reachable(params, traj.p)
    cols: dict[str, np.ndarray] = {"t": traj.t}
    for name, arr in (("p", traj.p), ("dp", traj.dp), ("ddp", traj.ddp)):
        cols[name + "1"], cols[name + "2"] = arr[:, 0], arr[:, 1]
    with np.errstate(all="ignore"):
        kin = _kinematics_columns(params, traj.p)
        cols.update({k: kin[k] for k in ("theta1", "theta2", "det_jx", "det_jq", "cond", "reachable", "status")})
        cols.update(_dynamics_columns(params, traj.p, traj.dp, traj.ddp, fext, args.model))
    _check_forces(params, cols)
    write_output(args.output, cols)
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``kinematics``, ``dynamics`` and ``trajectory`` to the ``tpm-viz`` subparsers."""
    k = sub.add_parser("kinematics", parents=[common], help="inverse kinematics, angles, singularity measures")
    k.add_argument(
        "--input", required=True, help="CSV with columns p1,p2 [m] (- for stdin; dialects and units: docs/csv.md)"
    )
    k.add_argument("--output", help="output CSV (default: stdout)")
    k.set_defaults(func=_cmd_kinematics)

    d = sub.add_parser("dynamics", parents=[common], help="actuator forces for platform states (eqs. 28-31)")
    d.add_argument(
        "--input",
        required=True,
        help="CSV with columns p1,p2,dp1,dp2,ddp1,ddp2 (SI unless the header says, e.g. 'p1 [mm]'; "
        "other columns are ignored: the output of trajectory works)",
    )
    d.add_argument("--output", help="output CSV (default: stdout)")
    d.add_argument("--model", choices=["paper", "pinocchio"], default="paper", help="dynamic model")
    d.add_argument("--fext", metavar="FX,FY", help="external force on the platform [N]")
    d.set_defaults(func=_cmd_dynamics)

    t = sub.add_parser(
        "trajectory",
        parents=[common],
        help="the paper's line or circle (Figs. 4-5), or your own timed path t,p1,p2, with forces",
    )
    source = t.add_mutually_exclusive_group(required=True)
    source.add_argument("--kind", choices=["line", "circle"], help="the paper's trajectory")
    source.add_argument(
        "--input",
        help="CSV with columns t,p1,p2 [s, m] (or 't [ms]', 'p1 [mm]'); derivatives of its natural cubic spline",
    )
    t.add_argument("--duration", type=positive_float, help="duration T [s] up to 1e6 (default: line 0.2, circle 0.5)")
    t.add_argument("--samples", type=int, default=201, help="number of samples (default 201)")
    t.add_argument("--output", help="output CSV (default: stdout)")
    t.add_argument("--model", choices=["paper", "pinocchio"], default="paper", help="dynamic model")
    t.add_argument("--fext", metavar="FX,FY", help="external force on the platform [N]")
    t.set_defaults(func=_cmd_trajectory)
