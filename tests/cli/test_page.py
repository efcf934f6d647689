"""``tpm-viz page`` on the command line (issue 39): a bad lesson number or option exits 2 with one line before any
work; a lecturer's lesson is found by its file's number and every text it brings is escaped; ``--set`` changes the
calculator's mechanism; both files are written by the CLI's one writer. The page in a browser:
tests/ui/test_takehome.py.
"""

from __future__ import annotations

import html
import io
import json
import re
import zipfile
from pathlib import Path

import pytest

from tpm_viz.app.lesson_files import assets_dir
from tpm_viz.cli import main

EVIL = "<script>alert('x')</script> & </script><!-- \"q\""


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out, out.err


def data_of(page: str) -> dict:
    found = re.search(r'<script type="application/json" id="tpm-page-data">(.*?)</script>', page, re.S)
    return json.loads(found.group(1))


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--lesson", "99", "--output", "x.html"], "--lesson 99: no lesson has that number; lessons: 1, 2, 3, 4, 5, 6"),
        (["--lesson", "two", "--output", "x.html"], "invalid int value"),
        (["--lesson", "1"], "give --output FILE.html, --scorm FILE.zip or both"),
        (["--lesson", "1", "--output", "x.html", "--seed", "-1"], "the seed must be a whole number"),
        (["--lesson", "1", "--output", "x.html", "--seed", "9007199254740992"], "the seed must be a whole number"),
        (["--lesson", "1", "--output", "x.html", "--lang", "fr"], "invalid choice: 'fr'"),
        (["--lesson", "1", "--output", "x.html", "--set", "l_a=abc"], "l_a"),
        (["--lesson", "1", "--output", "x.html", "--set", "colour=1"], "unknown parameter 'colour'"),
        (["--lesson", "1", "--output", "x.html", "--set", "l_a"], "--set expects NAME=VALUE"),
        (["--lesson", "1", "--output", "x.html", "--lessons", "/nonexistent-folder"], "/nonexistent-folder"),
    ],
)
def test_a_bad_lesson_number_or_option_exits_2_with_one_line_and_writes_nothing(capsys, tmp_path, argv, words):
    argv = [str(tmp_path / a) if a.endswith(".html") else a for a in argv]
    status, out, err = run(capsys, "page", *argv)
    assert status == 2 and out == ""
    assert err.startswith("tpm-viz: error: ") and err.count("\n") == 1 and words in err, err
    assert list(tmp_path.iterdir()) == []


def test_a_mechanism_that_cannot_follow_the_lesson_is_refused_in_one_line(capsys, tmp_path):
    status, _, err = run(capsys, "page", "--lesson", "1", "--output", str(tmp_path / "x.html"), "--set", "l_a=0.15")
    assert status == 2 and err.count("\n") == 1 and "tpm-viz: error: " in err
    assert list(tmp_path.iterdir()) == []


def test_a_folder_that_does_not_exist_is_refused_by_the_writer(capsys, tmp_path):
    status, _, err = run(capsys, "page", "--lesson", "2", "--output", str(tmp_path / "no" / "x.html"))
    assert status == 2 and err.count("\n") == 1 and "does not exist" in err


def test_a_lecturers_lesson_is_found_by_its_number_and_every_text_is_escaped(capsys, tmp_path):
    source = (assets_dir() / "lessons" / "02-workspace.toml").read_text()
    source = source.replace('title = "2. Shorter links, smaller workspace"', f"title = {json.dumps('7. ' + EVIL)}")
    source = source.replace('en = """\nThe links are shortened', f'en = """\n{EVIL} The links are shortened', 1)
    source = source.replace('en = """\nThe links are l_a', f'en = """\n{EVIL} The links are l_a', 1)
    folder = tmp_path / "lessons"
    folder.mkdir()
    (folder / "07-mine.toml").write_text(source)
    page_path, package = tmp_path / "mine.html", tmp_path / "mine.zip"
    argv = ["page", "--lessons", str(folder), "--lesson", "7", "--output", str(page_path), "--scorm", str(package)]
    status, out, err = run(capsys, *argv, "--set", "m_p=3.5", "--seed", "5")
    assert status == 0, err
    page = page_path.read_text()
    assert out.splitlines() == [
        f"{page_path}: {len(page.encode())} bytes",
        f"{package}: {package.stat().st_size} bytes",
    ]
    assert EVIL not in page
    assert page.count(html.escape(EVIL)) >= 3  # the title (twice: <title>, <h1>), the text and the prompt
    outside = re.sub(r'srcdoc="[^"]*"', "", page)
    outside = re.sub(r"<script>.*?</script>|<script [^>]*>.*?</script>", "", outside, flags=re.S)
    assert "<!--" not in outside and "alert(" not in outside.replace(html.escape("alert('x')"), "")
    data = data_of(page)
    assert data["params"]["m_p"] == 3.5 and data["params"]["l_a"] == 0.2  # --set over the lesson's own
    assert data["seed"] == 5 and data["exercises"][0]["seed"] == 5 and EVIL in data["exercises"][0]["prompt"]
    archive = zipfile.ZipFile(io.BytesIO(package.read_bytes()))
    assert archive.read("index.html").decode() == page
    assert Path(page_path).stat().st_size <= 5_000_000
