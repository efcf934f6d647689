"""Lesson folders with files that stopped, hung or leaked through the old reader (issue 23): a lesson naming
``file = "/dev/zero"``, a FIFO, ``/etc/passwd`` or ``/proc/self/environ``, a symlink out of the folder, a deeply
nested TOML, a lesson file that is itself a FIFO. Each is refused with one line that quotes nothing of the file,
the good lessons still load, and loading never hangs (the load runs in a thread with a generous bound)."""

from __future__ import annotations

import io
import os
import threading
from contextlib import redirect_stderr, redirect_stdout

import pytest

from tpm_viz.app.lesson_files import assets_dir, load_lessons
from tpm_viz.core.words import Lang
from tpm_viz.ui.app import main as serve
from tpm_viz.ui.teaching.lessons import problems_html

SECRET = "TPM-VIZ-TEST-SECRET-7f3a"
GOOD = 'title = "{title}"\n[text]\nen = "A lesson."\n[pose]\np = [0.0, 0.0]\n'
CSV_LESSON = 'title = "{title}"\n[text]\nen = "A lesson."\n[motion]\nkind = "csv"\nfile = "{file}"\n'


def _hostile_folder(tmp_path):
    folder = tmp_path / "lessons"
    folder.mkdir()
    (tmp_path / "secret.csv").write_text(f"t,p1,p2\n{SECRET}\n")
    os.mkfifo(folder / "pipe.csv")
    os.mkfifo(folder / "05-fifo.toml")
    (folder / "link.csv").symlink_to(tmp_path / "secret.csv")
    (folder / "passwd.csv").symlink_to("/etc/passwd")
    lessons = {
        "00-good.toml": GOOD.format(title="Good A"),
        "01-zero.toml": CSV_LESSON.format(title="Zero", file="/dev/zero"),
        "02-fifo-csv.toml": CSV_LESSON.format(title="Fifo", file="pipe.csv"),
        "03-passwd.toml": CSV_LESSON.format(title="Passwd", file="/etc/passwd"),
        "04-environ.toml": CSV_LESSON.format(title="Environ", file="/proc/self/environ"),
        "06-link-out.toml": CSV_LESSON.format(title="Link", file="link.csv"),
        "07-link-passwd.toml": CSV_LESSON.format(title="Link2", file="passwd.csv"),
        "08-dotdot.toml": CSV_LESSON.format(title="Dotdot", file="../secret.csv"),
        "09-deep.toml": GOOD.format(title="Deep") + "x = " + "[" * 50_000 + "]" * 50_000 + "\n",
        "10-deep-inline.toml": GOOD.format(title="Deep2") + "x = " + "{a = " * 40 + "1" + "}" * 40 + "\n",
        "11-brackets.toml": "[" * 200_000,
        "12-fine.toml": GOOD.format(title="Good B"),
    }
    for name, text in lessons.items():
        (folder / name).write_text(text)
    return folder, len(lessons) + 1 - 2  # + the FIFO lesson, - the two good ones


def _load_bounded(folder):
    out: list = []
    loader = threading.Thread(target=lambda: out.append(load_lessons(folder)), daemon=True)
    loader.start()
    loader.join(120.0)  # a FIFO would block open() forever; the bound only catches that hang, it times nothing
    assert not loader.is_alive(), "loading the lessons hung"
    return out[0]


def _assert_quotes_nothing(text: str) -> None:
    assert SECRET not in text and "root:" not in text and "/bin/" not in text and "PATH=" not in text, text


def test_hostile_lesson_files_are_refused_one_line_each_and_the_good_ones_load(tmp_path, monkeypatch):
    monkeypatch.setenv("TPM_VIZ_TEST_ENV", SECRET)
    folder, bad = _hostile_folder(tmp_path)
    lessons, problems = _load_bounded(folder)
    assert [d.title for d in lessons] == ["Good A", "Good B"]
    assert len(problems) == bad
    for problem in problems:
        assert "\n" not in problem and problem.startswith(str(folder)), problem
        _assert_quotes_nothing(problem)
    said = {p.split(":", 1)[0].rsplit("/", 1)[-1]: p for p in problems}
    for name in ("01-zero.toml", "03-passwd.toml", "04-environ.toml", "06-link-out.toml", "08-dotdot.toml"):
        assert "outside the folder" in said[name], said[name]
    assert "pipe (FIFO)" in said["02-fifo-csv.toml"] and "pipe (FIFO)" in said["05-fifo.toml"]
    for name in ("09-deep.toml", "10-deep-inline.toml", "11-brackets.toml"):
        assert "nested deeper than 8 levels" in said[name] or "TOML" in said[name], said[name]
    assert "nested deeper" in said["09-deep.toml"] and "nested deeper" in said["10-deep-inline.toml"]
    for lang in Lang:  # the Demos tab's note, as every student sees it
        _assert_quotes_nothing(problems_html(problems, lang))


def test_a_lesson_may_name_a_packaged_trajectory_by_its_path(tmp_path):
    figure = assets_dir() / "trajectories" / "figure_eight.csv"
    (tmp_path / "eight.toml").write_text(CSV_LESSON.format(title="Eight", file=figure))
    (demo,), problems = load_lessons(tmp_path)
    assert problems == () and demo.motion is not None and demo.motion.trajectory is not None


def test_the_server_starts_with_a_hostile_lessons_folder_and_shows_the_refusals(tmp_path, monkeypatch):
    monkeypatch.setenv("TPM_VIZ_TEST_ENV", SECRET)
    folder, bad = _hostile_folder(tmp_path)
    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()):
        app = serve(host="127.0.0.1", port=0, block=False, lessons=folder)
    try:
        assert [d.title for d in app.services.lessons] == ["Good A", "Good B"]
        assert len(app.services.problems) == bad
        warnings = [line for line in err.getvalue().splitlines() if "lesson refused" in line]
        assert len(warnings) == bad
        _assert_quotes_nothing(err.getvalue())
    finally:
        app.stop()


@pytest.mark.parametrize("name", ["/dev/zero", "/proc/self/environ", "/etc/passwd"])
def test_a_single_lesson_file_that_is_a_system_file_is_refused(name):
    lessons, problems = load_lessons(name)
    assert lessons == () and len(problems) == 1
    _assert_quotes_nothing(problems[0])
