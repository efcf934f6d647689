"""The command-line blocks of the README and of the command-line page (``docs/cli.md``) run as written, in order, in
an empty folder (the files they read are the files the blocks before them write): a reader who copies them gets no
"file not found". Every other ``tpm-viz`` line of the site is parsed by the command line's parser
(``test_doc_blocks.py``)."""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import pytest

from tests.support.docs import ROOT, blocks

pytestmark = pytest.mark.slow  # about twenty runs of the command line

PAGES = [ROOT / "README.md", ROOT / "docs" / "cli.md"]
"""The pages whose command-line blocks run (the README's first two blocks are the install and test commands)."""


def _blocks(page: pathlib.Path) -> list[str]:
    found = [b.text.strip() for b in blocks(page) if b.lang == "bash"]
    return [b for b in found if b.startswith("tpm-viz") or b.startswith("printf")]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_page_has_command_line_blocks(page):
    found = _blocks(page)
    assert found and all("tpm-viz" in b for b in found)
    lines = [ln for b in found for ln in b.splitlines() if ln.startswith("tpm-viz")]
    assert len(lines) >= 5


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_command_of_the_page_runs_as_written(page, tmp_path):
    bindir = pathlib.Path(sys.executable).parent
    env = {**os.environ, "PATH": f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}", "MPLBACKEND": "Agg"}
    for block in _blocks(page):
        for line in block.splitlines():
            command = line.split("  #")[0].strip()
            if not command:
                continue
            run = subprocess.run(
                ["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
            )
            assert run.returncode == 0, f"{page.name}: {command!r} failed: {run.stderr.strip()[-400:]}"
