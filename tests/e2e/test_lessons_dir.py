"""``tpm-viz serve --lessons DIR``: a lecturer's own lessons in the Demos tab; a broken file is one warning line."""

from __future__ import annotations

import io
import shutil
from contextlib import redirect_stderr, redirect_stdout

import pytest

from tpm_viz.app.lessons import assets_dir
from tpm_viz.cli import main as cli_main
from tpm_viz.core.errors import InputError
from tpm_viz.ui.app import main as serve


def test_a_lecturers_folder_replaces_the_packaged_lessons_and_reports_a_broken_file(tmp_path):
    shutil.copy(assets_dir() / "lessons" / "03-speed.toml", tmp_path / "a-speed.toml")
    (tmp_path / "b-broken.toml").write_text('title = "Broken"\nkey = "broken"\nunknown_key = 3\n')
    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()):
        app = serve(host="127.0.0.1", port=0, block=False, lessons=tmp_path)
    try:
        assert [d.key for d in app.services.lessons] == ["a-speed"]  # a lesson is named by its file
        assert len(app.services.problems) == 1 and app.services.problems[0].startswith(str(tmp_path / "b-broken.toml"))
        warnings = [line for line in err.getvalue().splitlines() if "lesson refused" in line]
        assert len(warnings) == 1 and "b-broken.toml:" in warnings[0]
    finally:
        app.stop()


def test_a_folder_without_any_good_lesson_is_refused_before_serving(tmp_path, capsys):
    (tmp_path / "x.toml").write_text("this is not toml =")
    with pytest.raises(InputError, match="no lesson loaded"):
        serve(host="127.0.0.1", port=0, block=False, lessons=tmp_path)
    assert (
        cli_main(["serve", "--port", "0", "--fresh", "--session", str(tmp_path / "s.json"), "--lessons", str(tmp_path)])
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no lesson loaded" in err and "x.toml" in err
