"""Every patch has its upstream issue and the condition that retires it: each name that
:func:`~tpm_viz.viserkit.adapter.install` knows (and the two entries that are not switches: the page script and the
private reads) has a ``PATCHES.md`` entry with an "Upstream" and a "Retire when" line, and a file
``upstream/NN-<name>.md`` with the text to file (and no other entry or file exists). Each file's script shows the
problem with viser alone (no tpm-viz): the slow test runs it and expects it to fail as the file says; once it passes
on the installed viser, the patch can go.

Run by hand against a candidate viser (an interpreter that has it, and websockets, msgspec, zstandard, numpy;
playwright for entry 13)::

    python tests/viserkit/test_upstream.py /path/to/candidate/bin/python

prints, per file, ``still needed`` (the script fails as on viser 1.1.1) or ``RETIRE`` (it passes).
"""

from __future__ import annotations

import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest
import viser

from tpm_viz.viserkit.adapter import SKIPPABLE
from tpm_viz.viserkit.core import TESTED

ROOT = pathlib.Path(__file__).resolve().parents[2]
KIT = ROOT / "tpm_viz" / "viserkit"
UPSTREAM = KIT / "upstream"
PATCHES_MD = KIT / "PATCHES.md"
NOT_SWITCHES = {"page", "internals", "reconnect"}
"""``PATCHES.md`` entries that ``install`` cannot switch off: the page script (added by the handshake hook), its way
back after a network drop, and the reads of viser's private names (``core.py``)."""
SECTIONS = ("## Observed", "## Expected", "## Reproduction", "## Suggested change", "## Workaround meanwhile")
CHROMIUM = "/usr/bin/chromium"


def entries() -> dict[int, tuple[str, str]]:
    """``PATCHES.md``'s entries: number -> (name, text of the entry)."""
    text = PATCHES_MD.read_text()
    heads = list(re.finditer(r"^## (\d+)\. `(\w+)`", text, re.MULTILINE))
    ends = [h.start() for h in heads[1:]] + [len(text)]
    return {int(h.group(1)): (h.group(2), text[h.start() : end]) for h, end in zip(heads, ends, strict=True)}


def script(path: pathlib.Path) -> str:
    """The one ``python`` block of an upstream file."""
    blocks = re.findall(r"^```python\n(.*?)^```$", path.read_text(), re.MULTILINE | re.DOTALL)
    assert len(blocks) == 1, f"{path.name}: {len(blocks)} python blocks, want one"
    return blocks[0]


def run(path: pathlib.Path, python: str) -> subprocess.CompletedProcess[str]:
    """Run a file's script with ``python`` (a fresh process: viser only, no tpm-viz), in the upstream folder."""
    env = {**os.environ, "CHROMIUM": os.environ.get("CHROMIUM", CHROMIUM if os.path.exists(CHROMIUM) else "")}
    return subprocess.run(
        [python, "-c", script(path)], capture_output=True, text=True, timeout=180, cwd=UPSTREAM, env=env
    )


def test_every_patch_install_knows_has_an_entry_an_upstream_file_and_a_retire_line():
    found = entries()
    assert sorted(found) == list(range(1, len(found) + 1)), "entries numbered 1, 2, ... in order"
    names = [name for name, _ in found.values()]
    assert len(set(names)) == len(names)
    assert set(names) == set(SKIPPABLE) | {"handshakes"} | NOT_SWITCHES
    files = {f"{n:02d}-{name}.md" for n, (name, _) in found.items()}
    assert {p.name for p in UPSTREAM.iterdir()} == files, "an upstream file per entry, and nothing else"
    for n, (name, text) in found.items():
        lines = text.splitlines()
        assert any(line.startswith("- **Retire when**: ") for line in lines), f"entry {n} ({name}): no Retire when"
        upstream = [line for line in lines if line.startswith("- **Upstream**: ")]
        assert len(upstream) == 1 and f"upstream/{n:02d}-{name}.md" in upstream[0], f"entry {n} ({name})"


@pytest.mark.parametrize("path", sorted(UPSTREAM.glob("*.md")), ids=lambda p: p.stem)
def test_each_upstream_file_is_an_issue_ready_to_send(path):
    text = path.read_text()
    number, name = path.stem.split("-", 1)
    first, title = text.splitlines()[:2]
    assert first == f"<!-- tpm-viz: the `{name}` patch, PATCHES.md entry {int(number)}. The issue to file follows. -->"
    assert title.startswith("# ") and len(title) > 20
    assert re.search(rf"^- \*\*Versions\*\*: viser {re.escape(TESTED)}\.\d+", text, re.MULTILINE)
    assert viser.__version__.startswith(TESTED + ".")
    assert re.search(r"^- \*\*Upstream status\*\*: \S", text, re.MULTILINE)
    at = [text.find(s) for s in SECTIONS]
    assert -1 not in at and at == sorted(at), f"sections {SECTIONS} in this order"
    compile(script(path), path.name, "exec")
    assert "tpm_viz" not in script(path), "the script shows viser alone"


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(UPSTREAM.glob("*.md")), ids=lambda p: p.stem)
def test_each_upstream_script_still_shows_its_problem_on_the_installed_viser(path):
    """When this fails, viser fixed it: follow the entry's "Retire when" line in ``PATCHES.md``."""
    if path.stem.endswith(("-page", "-reconnect")):
        pytest.importorskip("playwright.sync_api")
        if not os.path.exists(CHROMIUM) and shutil.which("chromium") is None:
            pytest.skip("no Chromium for the page's script")
    done = run(path, sys.executable)
    last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
    assert done.returncode != 0, f"{path.name}'s script passes: the problem is gone upstream, retire the patch"
    assert last.startswith("AssertionError"), f"{path.name}'s script failed otherwise: {last}"


def main(python: str) -> int:
    """Run every upstream script with ``python`` and print what each says (see the module docstring)."""
    python = os.path.abspath(python) if os.sep in python else shutil.which(python) or python
    for path in sorted(UPSTREAM.glob("*.md")):
        done = run(path, python)
        last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
        verdict = "RETIRE" if done.returncode == 0 else "still needed" if last.startswith("AssertionError") else "error"
        print(f"{path.stem:20} {verdict:12} {last[:100]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else sys.executable))
