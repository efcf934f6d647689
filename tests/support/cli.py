"""Calling ``tpm-viz`` in tests: a family's ``register`` on a plain argparse parser (:func:`parser_for`), the command
in this process with its output captured (:func:`run`: what the command-line tests use), and, for the few end-to-end
tests (marked ``end_to_end``, one per family), the installed entry point in a child process (:func:`run_installed`).
"""

from __future__ import annotations

import argparse
import io
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import pytest

from tpm_viz.cli import main


def parser_for(family: ModuleType) -> argparse.ArgumentParser:
    """``tpm-viz`` with only ``family``'s subcommands (``--set`` as the shared option), on a plain parser."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--set", action="append", metavar="NAME=VALUE")
    parser = argparse.ArgumentParser(prog="tpm-viz")
    family.register(parser.add_subparsers(dest="command", required=True), common)
    return parser


@dataclass(frozen=True)
class Ran:
    """What one ``tpm-viz`` call did: its exit status and what it wrote (text), as ``subprocess.run`` reports it."""

    returncode: int
    stdout: str
    stderr: str


def run(capsys: pytest.CaptureFixture[str], *argv: str, stdin: str | bytes | None = None) -> Ran:
    """``tpm-viz ARGV`` in this process (:func:`tpm_viz.cli.main`), its output captured by ``capsys``; ``stdin``: what
    ``--input -`` reads. An exit through ``SystemExit`` (a closed pipe: 141) is its status."""
    capsys.readouterr()  # what earlier calls wrote is theirs
    saved = sys.stdin
    if stdin is not None:
        data = stdin.encode() if isinstance(stdin, str) else stdin
        sys.stdin = io.TextIOWrapper(io.BufferedReader(io.BytesIO(data)), encoding="utf-8")
    try:
        status = main(list(argv))
    except SystemExit as exc:
        status = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
    finally:
        sys.stdin = saved
    out, err = capsys.readouterr()
    return Ran(status, out, err)


def installed() -> list[str]:
    """The installed ``tpm-viz`` console script (``[project.scripts]``): the one beside this Python (a virtual
    environment's), else the first on ``PATH``; the test is skipped where the package is not installed."""
    beside = Path(sys.executable).with_name("tpm-viz")
    found = str(beside) if beside.exists() else shutil.which("tpm-viz")
    if found is None:
        pytest.skip("tpm-viz is not installed (pip install -e .)")
    return [found]


def run_installed(*argv: str, stdin: str | None = None, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    """``tpm-viz ARGV`` through the installed entry point, in a child process (end to end: the console script, its
    exit status and streams); a hang fails after ``timeout`` seconds."""
    return subprocess.run(
        [*installed(), *argv],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=None if stdin is not None else subprocess.DEVNULL,
    )
