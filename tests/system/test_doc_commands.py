"""The README's command-line blocks run as written, in order, in an empty folder (the files they read are the files
the blocks before them write): a reader who copies them gets no "file not found"."""

from __future__ import annotations

import os
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow  # about twenty runs of the command line

FIRST, LAST = "## Command line", "## Beyond the paper"


def _blocks() -> list[str]:
    text = (ROOT / "README.md").read_text()
    part = text[text.index(FIRST) : text.index(LAST)]
    return [b.strip() for b in re.findall(r"```bash\n(.*?)```", part, re.DOTALL)]


def test_the_command_line_section_has_its_blocks():
    blocks = _blocks()
    assert len(blocks) >= 2 and all("tpm-viz" in b for b in blocks)


def test_every_command_of_the_command_line_section_runs_as_written(tmp_path):
    bindir = pathlib.Path(sys.executable).parent
    env = {**os.environ, "PATH": f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}", "MPLBACKEND": "Agg"}
    for block in _blocks():
        for line in block.splitlines():
            command = line.split("  #")[0].strip()
            if not command:
                continue
            run = subprocess.run(
                ["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
            )
            assert run.returncode == 0, f"{command!r} failed: {run.stderr.strip()[-400:]}"
