"""``tpm-viz export --format mjcf|urdf --output FILE`` and ``--format c --output DIR``: the mechanism for other tools.

:func:`register` adds the subcommand to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The text comes from
:mod:`tpm_viz.exchange` (no MuJoCo or Pinocchio needed to write it). The file is written atomically
(:func:`tpm_viz.core.files.write_atomically`, the command line's one writer: a temporary file in the same directory,
then ``os.replace``, so a reader never sees half a model; a device, FIFO or folder at ``--output`` is refused and left
as it is). ``--output -``
prints to stdout. ``--format c`` writes ``tpm_2ppa.h`` and ``tpm_2ppa.c`` (:mod:`tpm_viz.exchange.c.code`) into
the directory ``--output`` (created if missing; not through a symbolic link), each file atomically, and replaces a
file there only if it is untouched since its export, or with ``--force`` (:mod:`tpm_viz.exchange.c.folder`). The
handler returns the exit status and raises :class:`~tpm_viz.core.errors.TpmVizError` for bad input (``cli.main`` prints
one line and exits with 2).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys

from tpm_viz.cli.common import params_from_args, positive
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import write_atomically

__all__ = ["FORMATS", "register", "write_atomically"]

FORMATS = ("mjcf", "urdf", "c")
"""Export formats: MJCF (MuJoCo, Pinocchio's MJCF reader), URDF and C99 source (the closed form)."""


def _write_c(params, directory: str, force: bool) -> None:
    from tpm_viz.exchange.c.code import c_files
    from tpm_viz.exchange.c.folder import write_c_folder

    write_c_folder(directory, c_files(params), force)


def _cmd_export(args) -> int:
    from tpm_viz.exchange.mjcf import DEFAULT_SETTINGS, mjcf_text
    from tpm_viz.exchange.urdf import urdf_text

    params = params_from_args(args)
    if args.format == "c":
        if args.timestep is not None:
            raise InputError("--timestep applies to --format mjcf only")
        _write_c(params, args.output, args.force)
        return 0
    if args.force:
        raise InputError("--force applies to --format c only")
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
        "--force",
        action="store_true",
        help="--format c only: replace tpm_2ppa.h/.c even if they were edited after their export (checked by the "
        "content hash in their last line; a symbolic link or a non-regular file is never replaced)",
    )
    e.add_argument(
        "--timestep",
        type=float,
        metavar="S",
        help="MJCF only: MuJoCo time step [s] (default 0.0002; the closures' solref time constant is 2x it)",
    )
    e.set_defaults(func=_cmd_export)
