"""What every ``tpm-viz`` subcommand shares: the one-line-error parser, ``--set NAME=VALUE``, number checks,
and the output file: never the input (:func:`check_output`), never a device, FIFO or folder (:func:`check_outputs`,
before any work; the writer checks again), written atomically (:func:`write_output`).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Mapping
from typing import overload

import numpy as np

from tpm_viz.core.csvio import write_columns
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import output_target
from tpm_viz.core.numbers import parse_number
from tpm_viz.core.params import PARAM_INFO, Params

__all__ = [
    "MAX_COUNT",
    "MAX_MESSAGE",
    "MAX_SECONDS",
    "MIN_SECONDS",
    "Parser",
    "check_output",
    "check_outputs",
    "common_parent",
    "one_line",
    "params_from_args",
    "port_number",
    "positive",
    "positive_float",
    "within",
    "write_output",
]

MAX_MESSAGE = 300
"""Longest error message printed [characters] (a huge cell or argument is cut, never echoed whole)."""
MIN_SECONDS, MAX_SECONDS = 1e-9, 1e6
"""Bounds of every duration and time step on the command line [s]."""
MAX_COUNT = 100_000
"""Most samples, random states and the like a count option may ask for (each costs a model evaluation or more)."""


def one_line(message: str) -> str:
    """``message`` on one line, cut to :data:`MAX_MESSAGE` characters."""
    text = " ".join(str(message).split())
    return text if len(text) <= MAX_MESSAGE else text[: MAX_MESSAGE - 3] + "..."


class Parser(argparse.ArgumentParser):
    """An argparse parser whose usage errors are one line and exit status 2."""

    def error(self, message: str):  # pragma: no cover - exercised through main()
        raise InputError(one_line(f"{self.prog}: {message}"))


def common_parent() -> argparse.ArgumentParser:
    """The options every model subcommand takes: ``--set NAME=VALUE`` (SI units, repeatable)."""
    known = ", ".join(k for k in PARAM_INFO if k not in ("stroke", "pivot_spacing"))
    common = Parser(add_help=False)
    common.add_argument(
        "--set",
        action="append",
        metavar="NAME=VALUE",
        help=f"override a parameter in SI units (repeatable); names: {', '.join(PARAM_INFO)} (paper: {known})",
    )
    return common


def params_from_args(args: argparse.Namespace) -> Params:
    """The parameter set from ``--set NAME=VALUE`` options (SI units) over the paper's defaults."""
    overrides: dict[str, str] = {}
    for item in getattr(args, "set", None) or []:
        name, sep, value = item.partition("=")
        if not sep:
            raise InputError(f"--set expects NAME=VALUE, got {item!r}")
        name = name.strip()
        info = PARAM_INFO.get(name)
        overrides[name] = str(parse_number(value, name, info.get("unit", ""))) if info else value.strip()
    return Params.paper().with_overrides(overrides)


@overload
def positive(value: float, name: str) -> float: ...
@overload
def positive(value: None, name: str) -> None: ...
@overload
def positive(value: float | None, name: str) -> float | None: ...
def positive(value: float | None, name: str) -> float | None:
    """``value`` if None or positive and finite; else :class:`~tpm_viz.core.errors.InputError` naming ``name``."""
    if value is not None and (not math.isfinite(value) or value <= 0):
        raise InputError(f"{name} must be a positive, finite number, got {value:g}")
    return value


def within(value: float, name: str, low: float, high: float, unit: str = "") -> float:
    """``value`` if it is a finite number from ``low`` to ``high``; else a one-line
    :class:`~tpm_viz.core.errors.InputError` naming ``name`` and the range (a 309-digit value is never printed
    whole)."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    try:
        ok = ok and math.isfinite(value) and low <= value <= high
        shown = f"{value:g}"
    except (OverflowError, TypeError, ValueError):  # an int beyond float range
        ok, shown = False, str(value)[:12] + "..."
    if not ok:
        raise InputError(f"{name} must be from {low:g} to {high:g}{unit}, got {shown}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a number of seconds from :data:`MIN_SECONDS` to :data:`MAX_SECONDS` (numbers as typed:
    ``2e-1``, ``0,2``; :func:`tpm_viz.core.numbers.parse_number`)."""
    try:
        value = parse_number(text, "value", "s")
    except InputError as exc:
        raise argparse.ArgumentTypeError(f"expected a number of seconds: {exc}") from None
    if not MIN_SECONDS <= value <= MAX_SECONDS:
        raise argparse.ArgumentTypeError(
            f"expected a positive number of seconds from {MIN_SECONDS:g} to {MAX_SECONDS:g}, got {value:g}"
        )
    return value


def port_number(text: str) -> int:
    """argparse type: a TCP port from 0 to 65535 (0: any free port)."""
    try:
        value = int(text.strip())
    except ValueError:
        raise argparse.ArgumentTypeError("expected a whole number from 0 to 65535") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port from 0 to 65535, got {value}")
    return value


def _same_file(a: os.stat_result, b: os.stat_result) -> bool:
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def check_output(output: str | None, input_path: str | None) -> None:
    """Refuse an ``--output`` that is the ``--input`` file (the same file by any path or link, or the file that
    stdin reads when ``--input -``)."""
    if output in (None, "-") or input_path is None:
        return
    try:
        out = os.stat(output)
        if input_path == "-":
            src = os.fstat(sys.stdin.fileno())
            if not os.path.isfile(output) or not _same_file(out, src):
                return
        else:
            src = os.stat(input_path)
    except (OSError, ValueError):  # output does not exist yet (or no stdin): cannot be the input
        return
    if _same_file(out, src):
        raise InputError(f"--output {output!r} is the input file; write to another file (the input is kept)")


OUTPUT_OPTIONS = ("output", "sidecar", "scorm")
"""The options that name a file a subcommand writes (``figures --output-dir`` and ``export --format c`` name a
folder: their files go through the same writer)."""


def check_outputs(args: argparse.Namespace) -> None:
    """Refuse at once, before any work, an output option (:data:`OUTPUT_OPTIONS`) naming something that exists and is
    not a regular file, a kernel pseudo-file or a path in a missing folder
    (:func:`tpm_viz.core.files.output_target`; the writer checks again when it writes)."""
    for name in OUTPUT_OPTIONS:
        value = getattr(args, name, None)
        folder = getattr(args, "output_is_folder", False) or getattr(args, "format", None) == "c"
        if value in (None, "-") or (name == "output" and folder):
            continue  # stdout, or a folder the command writes into (export --format c, lti keygen)
        output_target(value)


def write_output(path: str | None, columns: Mapping[str, np.ndarray]) -> None:
    """:func:`tpm_viz.core.csvio.write_columns` (atomic replacement of ``path``), and a quiet exit with status 141
    when the reader of stdout goes away (``tpm-viz ... | head``), as other Unix tools do."""
    if path not in (None, "-"):
        write_columns(path, columns)
        return
    try:
        write_columns(None, columns)
        sys.stdout.flush()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise SystemExit(141) from None
