"""``tpm-viz replay | crosscheck | figures``: the Pinocchio model on the command line.

:func:`register` adds the subcommands to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The heavy layers
(Pinocchio, matplotlib) are imported by the handler that runs, so that the file commands start fast
(``tests/test_layering.py``). Handlers return the exit status and raise :class:`~tpm_viz.core.errors.TpmVizError` for
bad input (``cli.main`` prints one line and exits with 2). Durations and steps: 1e-9 to 1e6 s; the CSV output is
replaced atomically (:func:`tpm_viz.cli.common.write_output`).
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from tpm_viz.cli.common import MAX_COUNT, params_from_args, positive, positive_float, within, write_output
from tpm_viz.core.errors import InputError

__all__ = ["REPLAY_COLUMNS", "register"]

REPLAY_COLUMNS = ["t", "p1_ref", "p2_ref", "p1_sim", "p2_sim", "tau1", "tau2", "constraint_violation"]
"""Columns of ``tpm-viz replay`` (SI units: s, m, N)."""


def _cmd_replay(args) -> int:
    from tpm_viz.multibody.replay import replay  # heavy layer, loaded by the command that needs it

    params = params_from_args(args)
    res = replay(params, args.trajectory, positive(args.duration, "--duration"), positive(args.dt, "--dt"))
    cols = {"t": res.t}
    for name, arr in (("ref", res.p_ref), ("sim", res.p_sim)):
        cols[f"p1_{name}"], cols[f"p2_{name}"] = arr[:, 0], arr[:, 1]
    cols["tau1"], cols["tau2"] = res.tau[:, 0], res.tau[:, 1]
    cols["constraint_violation"] = res.constraint_violation
    write_output(args.output, cols)
    return 0


def _cmd_crosscheck(args) -> int:
    from tpm_viz.multibody.crosscheck import Tolerances, crosscheck, format_table  # heavy layer

    params = params_from_args(args)
    within(args.random, "--random", 1, MAX_COUNT)  # before any work (a billion states: out of memory)
    tol = Tolerances(
        rel=positive(args.rel_tol, "--rel-tol"),
        tracking=positive(args.tracking_tol, "--tracking-tol") * 1e-3,
        violation=positive(args.violation_tol, "--violation-tol"),
    )
    rows = crosscheck(
        params,
        positive(args.duration_line, "--duration-line"),
        positive(args.duration_circle, "--duration-circle"),
        n_random=args.random,
        seed=args.seed,
        dt=positive(args.dt, "--dt"),
        tol=tol,
    )
    print(format_table(rows, tol))
    return 0 if all(r.ok for r in rows) else 1


def _cmd_figures(args) -> int:
    from tpm_viz.drawing.figures import FILE_NAMES, plot_forces  # matplotlib
    from tpm_viz.multibody.crosscheck import compare_forces  # the Pinocchio model

    params = params_from_args(args)
    within(args.samples, "--samples", 2, MAX_COUNT)
    durations = {
        "line": positive(args.duration_line, "--duration-line"),
        "circle": positive(args.duration_circle, "--duration-circle"),
    }
    out = pathlib.Path(args.output_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError) as exc:
        raise InputError(f"cannot write into --output-dir {args.output_dir!r}: {exc.strerror}") from None
    paths = [
        plot_forces(compare_forces(params, kind, duration, args.samples), out / FILE_NAMES[kind])
        for kind, duration in durations.items()
    ]
    for path in paths:
        print(path, file=sys.stdout)
    return 0


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``replay``, ``crosscheck`` and ``figures`` to the ``tpm-viz`` subparsers.

    ``common_parent`` provides ``--set NAME=VALUE`` (read by :func:`tpm_viz.cli.common.params_from_args`).
    """
    r = subparsers.add_parser(
        "replay",
        parents=[common_parent],
        help="drive the Pinocchio model with the paper's actuator forces (forward dynamics, RK4)",
        description="Apply the closed-form actuator forces (eqs. 29-31) along the paper's line or circle to the "
        "Pinocchio closed-loop model and integrate; CSV columns " + ",".join(REPLAY_COLUMNS) + " (SI).",
    )
    r.add_argument("--trajectory", required=True, choices=["line", "circle"], help="the paper's Fig. 4 or Fig. 5 path")
    r.add_argument("--duration", type=positive_float, metavar="T", help="duration [s] (default: line 0.2, circle 0.5)")
    r.add_argument("--dt", type=positive_float, help="RK4 step [s] (default: 0.001 s or duration / 200 if smaller)")
    r.add_argument("--output", help="output CSV (default: stdout)")
    r.set_defaults(func=_cmd_replay)

    c = subparsers.add_parser(
        "crosscheck",
        parents=[common_parent],
        help="paper closed form vs Pinocchio: forces, replay tracking, closures (exit 1 on failure)",
    )
    c.add_argument("--duration-line", type=positive_float, metavar="T", help="line duration [s] (default 0.2)")
    c.add_argument("--duration-circle", type=positive_float, metavar="T", help="circle duration [s] (default 0.5)")
    c.add_argument("--random", type=int, default=200, metavar="N", help="number of random regular states (200)")
    c.add_argument("--seed", type=int, default=0, help="seed of the random states (0)")
    c.add_argument("--dt", type=positive_float, help="RK4 step of the replays [s] (0.001 or duration / 200)")
    c.add_argument("--rel-tol", type=float, default=1e-9, help="tolerance on |Δτ|/(1 N + |τ|) (1e-9)")
    c.add_argument("--tracking-tol", type=float, default=0.1, metavar="MM", help="replay tracking [mm] (0.1)")
    c.add_argument("--violation-tol", type=float, default=1e-6, metavar="M", help="closure gap [m] (1e-6)")
    c.set_defaults(func=_cmd_crosscheck)

    f = subparsers.add_parser(
        "figures",
        parents=[common_parent],
        help="PNG plots of the paper's Figs. 4-5: forces by both models and their difference",
    )
    f.add_argument("--output-dir", required=True, metavar="DIR", help="directory for fig4_line.png, fig5_circle.png")
    f.add_argument("--duration-line", type=positive_float, metavar="T", help="line duration [s] (default 0.2)")
    f.add_argument("--duration-circle", type=positive_float, metavar="T", help="circle duration [s] (default 0.5)")
    f.add_argument("--samples", type=int, default=201, help="samples per trajectory (201)")
    f.set_defaults(func=_cmd_figures)
