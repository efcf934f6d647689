"""``docs/takehome.md`` publishes the size of every shipped lesson's page: the table under "Page sizes" is what
``tpm-viz page --lesson N --output lesson-N.html`` (N = 1 to 6, English, seed 0) writes, regenerated here.

Checked: the lessons, their titles and frame counts exactly; the bytes within 1 % (viser compresses the recording
with zstd, whose output may differ by a few bytes with its version), and every page within the issue's
5,000,000 bytes. With ``TPM_VIZ_UPDATE_DOCS=1`` the test writes the fresh table into the doc (then commit it).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import pathlib
import re

import pytest

from tpm_viz.app.lessons import DEMOS
from tpm_viz.cli import main

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "takehome.md"
BLOCK = re.compile(r"(<!-- sizes: tpm-viz page --lesson N --output lesson-N.html[^\n]*-->\n```text\n)(.*?)(```)", re.S)
LIMIT = 5_000_000


def _table(folder: pathlib.Path) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["lesson", "title", "frames", "bytes"])
    for n in range(1, len(DEMOS) + 1):
        path = folder / f"lesson-{n}.html"
        with contextlib.redirect_stdout(io.StringIO()) as printed:
            assert main(["page", "--lesson", str(n), "--output", str(path)]) == 0
        size = path.stat().st_size
        assert printed.getvalue() == f"{path}: {size} bytes\n"
        data = json.loads(re.search(r'id="tpm-page-data">(.*?)</script>', path.read_text(), re.S).group(1))
        writer.writerow([n, DEMOS[n - 1].title.split(". ", 1)[1], len(data["frames"]["t"]), size])
    return out.getvalue()


@pytest.mark.slow
def test_the_doc_shows_the_size_of_every_lessons_page(tmp_path):
    fresh = _table(tmp_path)
    text = DOC.read_text(encoding="utf-8")
    found = BLOCK.search(text)
    assert found is not None, "docs/takehome.md has no sizes block"
    if os.environ.get("TPM_VIZ_UPDATE_DOCS") == "1":
        DOC.write_text(text[: found.start(2)] + fresh + text[found.end(2) :], encoding="utf-8")
        found = BLOCK.search(DOC.read_text(encoding="utf-8"))
        assert found is not None
    shown = list(csv.reader(io.StringIO(found.group(2))))
    now = list(csv.reader(io.StringIO(fresh)))
    assert [r[:3] for r in shown] == [r[:3] for r in now], f"refresh the table (TPM_VIZ_UPDATE_DOCS=1):\n{fresh}"
    for was, size in zip(shown[1:], now[1:], strict=True):
        assert abs(int(was[3]) - int(size[3])) <= 0.01 * int(size[3]), f"refresh the table:\n{fresh}"
        assert int(size[3]) <= LIMIT
