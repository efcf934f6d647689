"""The README is the front door, not the manual: at most 12 KB, with the two commands of a fresh machine (CI runs
exactly the documented test command), the screenshot, links into the docs site that lead somewhere, and the citation.
"""

from __future__ import annotations

import pathlib
import re

from tests.support.docs import ROOT, blocks

README = ROOT / "README.md"
MAX_BYTES = 12 * 1024


def _bash_blocks(page: pathlib.Path) -> list[str]:
    return [b.text.strip() for b in blocks(page) if b.lang == "bash"]


def test_the_readme_is_at_most_12_kb():
    size = len(README.read_bytes())
    assert size <= MAX_BYTES, f"README.md is {size} bytes: move the manual's parts to docs/ (at most {MAX_BYTES})"


def test_ci_runs_the_readme_test_command():
    start, test = _bash_blocks(README)[:2]
    assert "python app.py" in start and "pip install" in start
    assert "pytest" in test and "\n" not in test
    ci_lines = [ln.strip() for ln in (ROOT / ".ci" / "run").read_text().splitlines()]
    assert test in ci_lines


def test_the_contributors_page_repeats_the_two_commands_exactly():
    assert _bash_blocks(ROOT / "docs" / "contributing.md")[:2] == _bash_blocks(README)[:2]


def test_the_readme_shows_the_screenshot_and_its_links_lead_to_files():
    text = README.read_text()
    assert "](docs/screenshot.png)" in text
    targets = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    local = [t for t in targets if not re.match(r"[a-z]+://", t)]
    assert len(local) >= 20
    missing = [t for t in local if not (ROOT / t).exists()]
    assert not missing, f"README links to files that are not there: {missing}"
    for reader in ("Lecturers", "Researchers", "Contributors"):
        assert f"**{reader}**" in text
