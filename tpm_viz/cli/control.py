"""``tpm-viz control``: the computed-torque control lab on the command line.

:func:`register` adds the subcommand to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The simulation
(Pinocchio plant) is imported by the handler, so that ``import tpm_viz.cli`` stays free of Pinocchio.
The run goes to ``--output`` (or stdout) as CSV with columns :data:`CONTROL_COLUMNS` (SI units) and
a one-line summary goes to stderr. Bad input raises :class:`~tpm_viz.core.errors.TpmVizError` (``cli.main``
prints one line and exits with 2).
"""

from __future__ import annotations

import argparse
import math
import sys

from tpm_viz.cli.common import check_output, params_from_args, positive, within
from tpm_viz.core.csvio import read_text, write_columns
from tpm_viz.core.errors import InputError
from tpm_viz.paper.control import Gains
from tpm_viz.paper.trajectories import parse_trajectory_csv

__all__ = ["CONTROL_COLUMNS", "register"]

CONTROL_COLUMNS = ["t", "p1_ref", "p2_ref", "p1", "p2", "e1", "e2", "tau1", "tau2", "tau_ff1", "tau_ff2"]
"""Columns of ``tpm-viz control`` (SI units: s, m, N); ``e = p_ref - p``, ``tau`` as applied (saturated)."""


def _offset(text: str | None) -> tuple[float, float]:
    if text is None:
        return (0.0, 0.0)
    parts = text.split(",")
    try:
        x, y = (float(s) for s in parts)
    except ValueError:
        raise InputError(f"--offset expects X,Y in metres (e.g. 0.001,0), got {text!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InputError(f"--offset must be finite, got {text!r}")
    return x, y


def _reference(args):
    """``(reference, duration, horizon)`` for :func:`tpm_viz.multibody.control.simulate`."""
    duration = positive(args.duration, "--duration")
    if args.trajectory in ("line", "circle"):
        return args.trajectory, duration, None
    check_output(args.output, args.trajectory)
    try:
        text = read_text(args.trajectory)
    except OSError as exc:
        raise InputError(f"cannot read --trajectory {args.trajectory!r}: {exc.strerror or exc}") from None
    return parse_trajectory_csv(text, name=args.trajectory), None, duration


def _cmd_control(args) -> int:
    from tpm_viz.multibody.control import ControlSetup, simulate  # heavy layer (Pinocchio)

    params = params_from_args(args)
    reference, duration, horizon = _reference(args)
    err = 0.0 if args.mass_error is None else args.mass_error
    within(
        args.wn, "--wn (natural frequency)", 1e-3, 1e4, " Hz"
    )  # absurd values refused here, in one line, before any work
    within(args.zeta, "--zeta (damping ratio)", 0.0, 1e3)
    within(args.rate, "--rate", 1.0, 1e6, " Hz")
    within(args.noise, "--noise", 0.0, 1.0, " m")
    within(args.seed, "--seed", 0, 2**32 - 1)
    within(err, "--mass-error", -0.99, 100.0)
    within(args.payload, "--payload", 0.0, 1e4, " kg")
    setup = ControlSetup(
        controller=args.controller,
        gains=Gains(args.wn, args.zeta),
        rate=args.rate,
        payload=args.payload,
        mass_error=(err, err, err),
        force_limit=positive(args.force_limit, "--force-limit"),
        noise=args.noise,
        offset=_offset(args.offset),
        seed=args.seed,
        feedforward_at=args.feedforward_at,
    )
    run = simulate(params, reference, setup, duration=duration, horizon=horizon)
    write_columns(args.output, run.columns())
    print(f"tpm-viz control: {run.summary()}", file=sys.stderr)
    return 0


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``control`` to the ``tpm-viz`` subparsers (``common_parent`` provides ``--set NAME=VALUE``)."""
    c = subparsers.add_parser(
        "control",
        parents=[common_parent],
        help="closed-loop control lab: PD, PD + feedforward or computed torque on the Pinocchio model",
        description="A controller sampled at --rate (zero-order hold) with the paper's closed form (eqs. 29-31) "
        "and its own, possibly wrong, masses drives the Pinocchio closed-loop model along a path; CSV columns "
        + ",".join(CONTROL_COLUMNS)
        + " (SI) and a summary line on stderr.",
    )
    c.add_argument(
        "--trajectory",
        required=True,
        metavar="line|circle|FILE",
        help="the paper's Fig. 4 line, Fig. 5 circle, or a CSV file with columns t,p1,p2 (s, m)",
    )
    c.add_argument(
        "--duration",
        type=float,
        metavar="T",
        help="line/circle: path duration [s] (default 0.2 / 0.5); FILE: simulated time [s] (default: the file's)",
    )
    c.add_argument("--controller", required=True, choices=["pd", "pdff", "ctc"], help="control law")
    c.add_argument("--wn", type=float, default=10.0, metavar="HZ", help="natural frequency of the error [Hz] (10)")
    c.add_argument("--zeta", type=float, default=1.0, metavar="Z", help="damping ratio (1)")
    c.add_argument(
        "--payload", type=float, default=0.0, metavar="KG", help="mass on the platform unknown to the controller [kg]"
    )
    c.add_argument(
        "--mass-error",
        type=float,
        metavar="FRAC",
        help="relative error of m_a, m_b and m_p in the controller's model (e.g. 0.1 for +10 %%)",
    )
    c.add_argument("--force-limit", type=float, metavar="N", help="actuator force limit [N] (default: none)")
    c.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="controller sample rate [Hz] (1000)")
    c.add_argument("--noise", type=float, default=0.0, metavar="M", help="std of the measured position [m] (0)")
    c.add_argument("--seed", type=int, default=0, help="seed of the measurement noise (0)")
    c.add_argument(
        "--feedforward-at",
        choices=["sample", "mid"],
        default="sample",
        help="where in the hold interval the reference's acceleration (pdff: force) is fed forward (sample)",
    )
    c.add_argument("--offset", metavar="X,Y", help="initial platform offset from the reference [m] (0,0)")
    c.add_argument("--output", help="output CSV (default: stdout)")
    c.set_defaults(func=_cmd_control)
