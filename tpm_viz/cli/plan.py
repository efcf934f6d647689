"""``tpm-viz plan | size``: the fastest motion within the motors' limits, and motor sizing, on the command line.

:func:`register` adds the subcommands to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The planner (toppra, which
loads matplotlib) is imported by the handler that runs. Handlers return the exit status and raise
:class:`~tpm_viz.core.errors.TpmVizError` for bad input (``cli.main`` prints one line and exits with 2).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from tpm_viz.app import paths
from tpm_viz.app.sizing import format_sizing, size_trajectory, sizing_columns
from tpm_viz.cli.common import MAX_SECONDS, check_output, params_from_args, positive, within
from tpm_viz.core.csvio import parse_columns, read_columns, read_text, write_columns
from tpm_viz.core.errors import InputError
from tpm_viz.paper.trajectories import trajectory_from_samples

__all__ = ["MAX_WAYPOINTS", "PLAN_COLUMNS", "SIZE_INPUTS", "register"]

MAX_WAYPOINTS = 10_000
"""Most waypoints in a ``plan --path FILE`` (each is a corner the planner must time; more is a sampled curve)."""
MAX_CORNER_RADIUS = 1.0
"""Largest ``--corner-radius`` [m] (the mechanism is a few hundred millimetres across)."""

PLAN_COLUMNS = ["t", "p1", "p2", "dp1", "dp2", "ddp1", "ddp2", "tau1", "tau2"]
"""Columns of ``tpm-viz plan`` (SI units: s, m, m/s, m/s², N)."""

SIZE_INPUTS = (
    PLAN_COLUMNS[1:],
    ["p1", "p2", "tau1", "tau2"],
    ["p1", "p2", "dp1", "dp2", "ddp1", "ddp2"],
    ["p1", "p2"],
)
"""Column sets ``tpm-viz size`` accepts (each with ``t``): forces from the file when present, else from the closed
form; velocities and accelerations from the file when present, else from a natural cubic spline through ``p``."""


def _cmd_plan(args) -> int:
    dwell = within(0.0 if args.dwell is None else args.dwell, "--dwell", 0.0, MAX_SECONDS, " s")  # before any work
    rate = positive(args.rate, "--rate")
    if args.corner_radius is not None:
        within(args.corner_radius, "--corner-radius", 0.0, MAX_CORNER_RADIUS, " m")
    points = None
    if args.path not in ("line", "circle", "pick"):
        check_output(args.output, args.path)
        cols = read_columns(args.path, ["p1", "p2"], max_rows=MAX_WAYPOINTS)  # refused while reading, before any work
        points = np.stack([cols["p1"], cols["p2"]], -1)
    from tpm_viz.app import planner  # toppra, which loads matplotlib (1 s): only for this command

    params = params_from_args(args)
    limits = planner.Limits(args.force_limit, args.speed_limit, args.actuator_speed_limit)
    if points is None:
        path = paths.path_for(params, args.path, corner_radius=args.corner_radius, pick=_pick_size(args.pick_size))
    else:
        path = paths.path_for(params, "waypoints", points, corner_radius=args.corner_radius)
    solve = planner.plan_cycle if args.path == "pick" else planner.plan_path
    plan = solve(params, path, limits, args.grid)
    smp = plan.samples(rate)
    write_columns(args.output, _plan_columns(smp))
    cycle = plan.duration + dwell
    line = f"cycle time {cycle:.4f} s (motion {plan.duration:.4f} s + dwell {dwell:g} s)"
    if args.path == "pick":
        line += f", {60.0 / cycle:.1f} picks/min"
    print(line, file=sys.stderr)
    return 0


def _pick_size(text: str | None):
    """``H,W,R`` [m] as a :class:`~tpm_viz.app.paths.PickSize` (None: the default, fitted to the workspace)."""
    if text is None:
        return None
    try:
        h, w, r = (float(x) for x in text.split(","))
    except ValueError:
        raise InputError(f"--pick-size expects H,W,R in metres (e.g. 0.025,0.15,0.01), got {text!r}") from None
    return paths.PickSize(h, w, r)


def _plan_columns(smp) -> dict[str, np.ndarray]:
    cols = {"t": smp.t}
    for name, arr in (("p", smp.p), ("dp", smp.dp), ("ddp", smp.ddp), ("tau", smp.tau)):
        cols[f"{name}1"], cols[f"{name}2"] = arr[:, 0], arr[:, 1]
    return cols


def _read_motion(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """``(t, p, dp, ddp, tau)`` from a CSV holding one of :data:`SIZE_INPUTS` (``tau`` None: closed form)."""
    text = read_text(path)
    cols: dict[str, np.ndarray] = {}
    for required in SIZE_INPUTS:  # the richest set first: forces and derivatives from the file when it has them
        try:
            cols = dict(parse_columns(text, required, source=path))
            break
        except InputError as exc:
            if "missing column" not in str(exc) or required is SIZE_INPUTS[-1]:
                raise
    if "t" not in cols:
        raise InputError(f"{path}: missing column 't' (the sizing needs times [s])")
    t = cols["t"]
    p = np.stack([cols["p1"], cols["p2"]], -1)
    if "dp1" in cols:
        dp = np.stack([cols["dp1"], cols["dp2"]], -1)
        ddp = np.stack([cols["ddp1"], cols["ddp2"]], -1)
    else:
        traj = trajectory_from_samples(t, p)
        dp, ddp = traj.dp, traj.ddp
    tau = np.stack([cols["tau1"], cols["tau2"]], -1) if "tau1" in cols else None
    return t, p, dp, ddp, tau


def _cmd_size(args) -> int:
    params = params_from_args(args)
    dwell = within(0.0 if args.dwell is None else args.dwell, "--dwell", 0.0, MAX_SECONDS, " s")
    if args.motor_constant is not None:
        within(args.motor_constant, "--motor-constant", 1e-6, 1e6, " N/sqrt(W)")
    check_output(args.output, args.input)
    t, p, dp, ddp, tau = _read_motion(args.input)
    sizing = size_trajectory(params, t, p, dp, ddp, dwell, args.motor_constant, tau=tau)
    print(format_sizing(sizing))
    if args.output:
        write_columns(args.output, {k: np.asarray(v) for k, v in sizing_columns(sizing).items()})
    return 0


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``plan`` and ``size`` to the ``tpm-viz`` subparsers (``common_parent`` provides ``--set``)."""
    pl = subparsers.add_parser(
        "plan",
        parents=[common_parent],
        help="fastest motion along a path within the actuator force limit (toppra); CSV out",
        description="Time-optimal rest-to-rest timing of a path with |tau_i| <= F_max (eqs. 29-31), optionally "
        "|dp| <= v_max and |dd_i| <= v_act. CSV columns " + ",".join(PLAN_COLUMNS) + " (SI); the cycle time "
        "(and picks/min) on stderr.",
    )
    pl.add_argument(
        "--path",
        required=True,
        metavar="line|circle|pick|FILE",
        help="the paper's line or circle, a pick-and-place cycle (25-150-25 mm, 10 mm corners, shrunk to fit), "
        "or a CSV of waypoints with columns p1,p2 [m]",
    )
    pl.add_argument("--force-limit", required=True, type=float, metavar="N", help="|tau_i| <= N [N]")
    pl.add_argument("--speed-limit", type=float, metavar="M/S", help="platform speed limit |dp| [m/s]")
    pl.add_argument("--actuator-speed-limit", type=float, metavar="M/S", help="actuator speed limit |dd_i| [m/s]")
    pl.add_argument("--dwell", type=float, metavar="S", help="rest per cycle [s], added to the cycle time (0)")
    pl.add_argument("--grid", type=int, default=300, metavar="K", help="grid points along the path (300)")
    pl.add_argument(
        "--pick-size",
        metavar="H,W,R",
        help="pick-and-place rise, span and corner radius [m], centred in the valid region (default "
        "0.025,0.15,0.01, shrunk to fit)",
    )
    pl.add_argument("--corner-radius", type=float, metavar="M", help="corner radius of waypoint paths [m] (0.010)")
    pl.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="output sample rate [Hz] (1000)")
    pl.add_argument("--output", help="output CSV (default: stdout)")
    pl.set_defaults(func=_cmd_plan)

    sz = subparsers.add_parser(
        "size",
        parents=[common_parent],
        help="motor sizing of a timed motion: peak/RMS force, power, energy, speeds, copper losses",
        description="Reads a CSV with columns t,p1,p2 and optionally dp1,dp2,ddp1,ddp2 and/or tau1,tau2 (SI; "
        "e.g. the output of 'tpm-viz plan'); missing forces come from the closed form (eqs. 29-31).",
    )
    sz.add_argument("--input", required=True, metavar="FILE", help="the motion CSV ('-' for stdin)")
    sz.add_argument("--dwell", type=float, metavar="S", help="rest per cycle [s] (0): counts in RMS and means")
    sz.add_argument("--motor-constant", type=float, metavar="K", help="motor constant [N/sqrt(W)]: copper losses")
    sz.add_argument("--output", help="also write the table as CSV (quantity,unit,actuator1,actuator2)")
    sz.set_defaults(func=_cmd_size)
