"""``tpm-viz export --format mjcf|urdf --output FILE`` and ``--format c --output DIR``: the mechanism for other tools.

:func:`register` adds the subcommand to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The text comes from
:mod:`tpm_viz.exchange` (no MuJoCo or Pinocchio needed to write it). The file is written atomically
(:func:`tpm_viz.core.files.write_atomically`, the command line's one writer: a temporary file in the same directory,
then ``os.replace``, so a reader never sees half a model; a device, FIFO or folder at ``--output`` is refused and left
as it is). ``--output -``
prints to stdout. ``--format c`` writes ``tpm_2ppa.h`` and ``tpm_2ppa.c`` (:mod:`tpm_viz.exchange.c.code`) into
the directory ``--output`` (created if missing), each file atomically. The handler returns the exit status and
raises :class:`~tpm_viz.core.errors.TpmVizError` for bad input (``cli.main`` prints one line and exits with 2).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys

from tpm_viz.cli.common import params_from_args, positive
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import write_atomically

__all__ = ["FORMATS", "register", "write_atomically"]

FORMATS = ("mjcf", "urdf", "c")
"""Export formats: MJCF (MuJoCo, Pinocchio's MJCF reader), URDF and C99 source (the closed form)."""


def _write_c(params, directory: str) -> None:
    from tpm_viz.exchange.c.code import c_files

    if directory == "-":
        raise InputError("--format c writes two files: give a directory as --output, not '-'")
    if os.path.exists(directory) and not os.path.isdir(directory):
        raise InputError(f"--output {directory!r} is a file: --format c needs a directory (created if missing)")
    try:
        os.makedirs(directory, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the directory --output {directory!r}: {exc.strerror}") from None
    for name, text in c_files(params).items():
        write_atomically(os.path.join(directory, name), text)


def _cmd_export(args) -> int:
    from tpm_viz.exchange.mjcf import DEFAULT_SETTINGS, mjcf_text
    from tpm_viz.exchange.urdf import urdf_text

    params = params_from_args(args)
    if args.format == "c":
        if args.timestep is not None:
            raise InputError("--timestep applies to --format mjcf only")
        _write_c(params, args.output)
        return 0
    if args.format == "mjcf":
        settings = DEFAULT_SETTINGS
        if args.timestep is not None:
            dt = positive(args.timestep, "--timestep")
            settings = dataclasses.replace(settings, timestep=dt, solref=(2.0 * dt, settings.solref[1]))
        text = mjcf_text(params, settings)
    else:
        if args.timestep is not None:
            raise InputError("--timestep applies to --format mjcf only")
        text = urdf_text(params)
    if args.output == "-":
        sys.stdout.write(text)
    else:
        write_atomically(args.output, text)
    return 0


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``export`` to the ``tpm-viz`` subparsers (``common_parent`` provides ``--set NAME=VALUE``)."""
    e = subparsers.add_parser(
        "export",
        parents=[common_parent],
        help="write the mechanism as an MJCF (MuJoCo, Pinocchio) or URDF model file, or its closed form as C",
        description="Write every body of the 2-PPa TPM with the paper's mass model. MJCF: loop closures as "
        "<equality><connect> with stiff solver settings and the recommended time step (read by MuJoCo and by "
        "pinocchio.buildModelsAndConstraintsFromMJCF). URDF: a tree, the parallelograms as mimic joints, the "
        "leg closure documented in an XML comment. C: tpm_2ppa.h and tpm_2ppa.c, the closed-form kinematics, "
        "dynamics and computed-torque law for a real-time controller (C99, libm only; docs/realtime.md).",
    )
    e.add_argument("--format", required=True, choices=FORMATS, help="mjcf, urdf or c")
    e.add_argument(
        "--output",
        required=True,
        metavar="FILE",
        help="output file, replaced atomically ('-': stdout); for --format c a directory (created if missing)",
    )
    e.add_argument(
        "--timestep",
        type=float,
        metavar="S",
        help="MJCF only: MuJoCo time step [s] (default 0.0002; the closures' solref time constant is 2x it)",
    )
    e.set_defaults(func=_cmd_export)
