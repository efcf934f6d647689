"""``tpm-viz clip | report`` for people (issue 40.7): a typo is refused at once, before the heavy imports; a report
says where it wrote; a trajectory that is neither a choice nor a file names the choices."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tpm_viz.cli import main

HEAVY = ("matplotlib", "av", "PIL", "pinocchio")


def _refused_before_heavy_imports(*argv: str) -> tuple[int, list[str], str]:
    """Run ``tpm-viz ARGV`` in a fresh interpreter: its status, the heavy modules it imported, its stderr."""
    code = (
        "import sys\nfrom tpm_viz.cli import main\nstatus = main(sys.argv[1:])\n"
        f"print(status, *[m for m in {HEAVY!r} if m in sys.modules])"
    )
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=120)
    words = done.stdout.split()
    return int(words[0]), words[1:], done.stderr


@pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["clip", "--trajectory", "line", "--output", "x.avi"], "--output must end in .gif or .mp4"),
        (["clip", "--trajectory", "line", "--output", "x.gif", "--fps", "0"], "frame rate"),
        (["clip", "--trajectory", "line", "--output", "x.gif", "--size", "10x10"], "size must be from"),
        (["clip", "--trajectory", "spiral", "--output", "x.gif"], "give line, circle or a CSV file"),
        (["report", "--trajectory", "line", "--output", "x.pdf"], "--output must end in .html"),
        (["report", "--trajectory", "line", "--output", "x.html", "--date", "May 5"], "--date must be YYYY-MM-DD"),
    ],
)
def test_a_bad_option_is_one_line_before_matplotlib_pyav_or_pinocchio_load(argv, what, tmp_path):
    argv = [a if not a.startswith("x.") else str(tmp_path / a) for a in argv]
    status, heavy, err = _refused_before_heavy_imports(*argv)
    assert status == 2 and heavy == [], (status, heavy, err)
    assert err.count("\n") == 1 and err.startswith("tpm-viz: error:") and what in err, err
    assert list(tmp_path.iterdir()) == []


def test_a_trajectory_that_is_neither_a_choice_nor_a_file_names_the_choices(tmp_path, capsys):
    assert main(["report", "--trajectory", "spiral", "--output", str(tmp_path / "r.html")]) == 2
    err = capsys.readouterr().err
    assert "'spiral'" in err and "line, circle or a CSV file" in err and "No such file" not in err


def test_a_report_says_where_it_wrote_and_what(tmp_path, capsys):
    out = tmp_path / "r.html"
    assert main(["report", "--trajectory", "circle", "--samples", "41", "--output", str(out)]) == 0
    err = capsys.readouterr().err
    assert out.is_file() and out.stat().st_size > 10_000
    size_kib = round(out.stat().st_size / 1024)
    assert err.count("\n") == 1 and err.startswith(f"tpm-viz report: {out}: ")
    assert "41 samples over 0.500 s" in err and f"{size_kib} KiB" in err
