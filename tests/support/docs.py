"""The pages of the docs site and the README, and their fenced code blocks, for the tests that check them.

A page is ``README.md``, a Markdown file of ``docs/`` (not the build output, not the pages generated at build time)
or an ``assets/**/README.md`` (``docs/assets.md`` includes them). A fenced block runs from a line of three or more
backticks and its language to the closing backticks; a MyST directive (a language in braces, ``{toctree}``) is not a
code block.
"""

from __future__ import annotations

import dataclasses
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
GENERATED = ("_build", "api/generated", "examples")
"""Folders of ``docs/`` that the build writes (ignored by git)."""
NOT_RUN = re.compile(r"<!--\s*not run:\s*(\S.*?)\s*-->")
"""The HTML comment, on the line just above a block, that says why a Python block is a fragment."""


@dataclasses.dataclass(frozen=True)
class Block:
    """One fenced block: its page, first line (1-based, the fence), language (``""`` if none), text, and the reason
    it is not run (``None``: it is run)."""

    page: pathlib.Path
    line: int
    lang: str
    text: str
    not_run: str | None

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def pages() -> list[pathlib.Path]:
    """Every page of the site (the hand-written ones), the README and the assets' READMEs."""
    found = [ROOT / "README.md"]
    for path in sorted(DOCS.rglob("*.md")):
        rel = path.relative_to(DOCS).as_posix()
        if not any(rel == g or rel.startswith(g + "/") for g in GENERATED):
            found.append(path)
    found += sorted((ROOT / "assets").rglob("README.md"))
    return found


def blocks(page: pathlib.Path) -> list[Block]:
    """The fenced code blocks of one page, in order."""
    lines = page.read_text().splitlines()
    found, k = [], 0
    while k < len(lines):
        opening = re.match(r"^(`{3,})(.*)$", lines[k])
        if not opening:
            k += 1
            continue
        fence, lang = opening.group(1), opening.group(2).strip()
        end = k + 1
        while end < len(lines) and not lines[end].startswith(fence):
            end += 1
        above = next((ln for ln in reversed(lines[:k]) if ln.strip()), "")
        reason = NOT_RUN.search(above)
        if not lang.startswith("{"):
            text = "\n".join(lines[k + 1 : end]) + "\n"
            found.append(Block(page, k + 1, lang, text, reason.group(1) if reason else None))
        k = end + 1
    return found


def all_blocks() -> list[Block]:
    return [b for page in pages() for b in blocks(page)]


def block_after(page: pathlib.Path, marker: str) -> Block:
    """The first fenced block after the first line of ``page`` that contains ``marker``."""
    lines = page.read_text().splitlines()
    at = next((n for n, ln in enumerate(lines, 1) if marker in ln), None)
    assert at is not None, f"{marker!r} is not in {page.relative_to(ROOT)}"
    after = [b for b in blocks(page) if b.line > at]
    assert after, f"no fenced block after {marker!r} in {page.relative_to(ROOT)}"
    return after[0]
