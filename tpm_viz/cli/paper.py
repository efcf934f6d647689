"""``tpm-viz kinematics | dynamics | trajectory``: the paper's closed form on CSV files (SI units)."""

from __future__ import annotations

import argparse

import numpy as np

from tpm_viz.cli.common import params_from_args, positive_float
from tpm_viz.csvio import read_columns, read_text, write_columns
from tpm_viz.errors import InputError
from tpm_viz.paper.dynamics import inverse_dynamics_detail
from tpm_viz.paper.jacobians import STATUS_LABELS, classify, condition_number, jacobians
from tpm_viz.paper.kinematics import inverse_kinematics, leg_angles, reachable
from tpm_viz.paper.trajectories import paper_trajectory, parse_trajectory_csv
from tpm_viz.params import Params

__all__ = ["DYN_IN", "register"]

DYN_IN = ["p1", "p2", "dp1", "dp2", "ddp1", "ddp2"]
"""Input columns of ``tpm-viz dynamics`` (SI)."""


def _parse_fext(text: str | None) -> np.ndarray | None:
    if text is None:
        return None
    parts = text.split(",")
    try:
        f = np.array([float(x) for x in parts])
    except ValueError:
        raise InputError(f"--fext expects FX,FY in newtons, got {text!r}") from None
    if f.shape != (2,) or not np.all(np.isfinite(f)):
        raise InputError(f"--fext expects two finite numbers FX,FY in newtons, got {text!r}")
    return f


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
        raise InputError(
            f"row {r + 2}: platform position ({p[r, 0]:g}, {p[r, 1]:g}) m is unreachable "
            f"(|p_j| must be below l_a = {params.l_a:g} m)"
        )


def _cmd_kinematics(args) -> int:
    params = params_from_args(args)
    table = read_columns(args.input, ["p1", "p2"])
    p = np.stack([table["p1"], table["p2"]], -1)
    cols = dict(table)
    cols.update(_kinematics_columns(params, p))
    write_columns(args.output, cols)
    return 0


def _cmd_dynamics(args) -> int:
    params = params_from_args(args)
    table = read_columns(args.input, DYN_IN)
    p, dp, ddp = (np.stack([table[a], table[b]], -1) for a, b in zip(DYN_IN[::2], DYN_IN[1::2], strict=True))
    _check_reachable(params, p)
    cols = dict(table)
    cols.update(_dynamics_columns(params, p, dp, ddp, _parse_fext(args.fext), args.model))
    write_columns(args.output, cols)
    return 0


def _cmd_trajectory(args) -> int:
    params = params_from_args(args)
    if args.input is not None:
        if args.duration is not None:
            raise InputError("--duration applies to --kind, not to a trajectory read with --input")
        traj = parse_trajectory_csv(read_text(args.input), name=args.input)
    else:
        traj = paper_trajectory(args.kind, args.duration, args.samples)
    _check_reachable(params, traj.p)
    cols: dict[str, np.ndarray] = {"t": traj.t}
    for name, arr in (("p", traj.p), ("dp", traj.dp), ("ddp", traj.ddp)):
        cols[name + "1"], cols[name + "2"] = arr[:, 0], arr[:, 1]
    kin = _kinematics_columns(params, traj.p)
    cols.update({k: kin[k] for k in ("theta1", "theta2", "det_jx", "det_jq", "cond", "reachable", "status")})
    cols.update(_dynamics_columns(params, traj.p, traj.dp, traj.ddp, _parse_fext(args.fext), args.model))
    write_columns(args.output, cols)
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``kinematics``, ``dynamics`` and ``trajectory`` to the ``tpm-viz`` subparsers."""
    k = sub.add_parser("kinematics", parents=[common], help="inverse kinematics, angles, singularity measures")
    k.add_argument("--input", required=True, help="CSV with columns p1,p2 [m]")
    k.add_argument("--output", help="output CSV (default: stdout)")
    k.set_defaults(func=_cmd_kinematics)

    d = sub.add_parser("dynamics", parents=[common], help="actuator forces for platform states (eqs. 28-31)")
    d.add_argument("--input", required=True, help="CSV with columns p1,p2,dp1,dp2,ddp1,ddp2 (SI)")
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
    source.add_argument("--input", help="CSV with columns t,p1,p2 [s, m]; derivatives of its natural cubic spline")
    t.add_argument("--duration", type=positive_float, help="duration T [s] (default: line 0.2, circle 0.5)")
    t.add_argument("--samples", type=int, default=201, help="number of samples (default 201)")
    t.add_argument("--output", help="output CSV (default: stdout)")
    t.add_argument("--model", choices=["paper", "pinocchio"], default="paper", help="dynamic model")
    t.add_argument("--fext", metavar="FX,FY", help="external force on the platform [N]")
    t.set_defaults(func=_cmd_trajectory)
