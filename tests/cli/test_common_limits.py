"""Absurd values and oversized inputs on the command line (issue 23): ``plan --dwell 1e308`` exited 0 with a
309-digit cycle time; ``plan`` with 100,000 waypoints ran 68 s and 1.24 GB before refusing; an ``export``
failure named its temporary file. Each is now one line, exit status 2, refused before the work starts (the
work functions are replaced by ones that fail the test if they are ever called)."""

from __future__ import annotations

import numpy as np
import pytest

import tpm_viz.app.paths as paths_module
import tpm_viz.app.planner as planner_module
import tpm_viz.multibody.control as control_module
import tpm_viz.multibody.crosscheck as crosscheck_module
from tpm_viz.cli import main
from tpm_viz.cli.outputs import write_bytes
from tpm_viz.cli.plan import MAX_WAYPOINTS
from tpm_viz.core.errors import InputError


def _never(*args, **kwargs):
    raise AssertionError("the work started before the input was checked")


@pytest.fixture
def no_work(monkeypatch):
    for module, name in (
        (planner_module, "plan_path"),
        (planner_module, "plan_cycle"),
        (paths_module, "path_for"),
        (control_module, "simulate"),
        (crosscheck_module, "crosscheck"),
    ):
        monkeypatch.setattr(module, name, _never)


def _refused(capsys, argv: list[str], *words: str) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("tpm-viz: error:"), err
    assert len(err) < 200, err  # never a 309-digit number
    for word in words:
        assert word in err, err
    return err


@pytest.mark.parametrize("dwell", ["1e308", "inf", "nan", "-1", "1e7"])
def test_plan_refuses_an_absurd_dwell_before_planning(no_work, capsys, dwell):
    _refused(capsys, ["plan", "--path", "line", "--force-limit", "100", "--dwell", dwell], "--dwell", "1e+06 s")


def test_plan_refuses_an_absurd_corner_radius(no_work, capsys):
    argv = ["plan", "--path", "line", "--force-limit", "100", "--corner-radius", "1e308"]
    _refused(capsys, argv, "--corner-radius")


def test_plan_refuses_100000_waypoints_while_reading_them(no_work, capsys, tmp_path):
    path = tmp_path / "many.csv"
    angle = np.linspace(0.0, 2 * np.pi, 100_000)
    rows = "\n".join(f"{0.05 * np.cos(a):.6f},{0.05 * np.sin(a):.6f}" for a in angle)
    path.write_text("p1,p2\n" + rows + "\n")
    _refused(capsys, ["plan", "--path", str(path), "--force-limit", "100"], str(path), f"{MAX_WAYPOINTS} data rows")


def test_a_waypoint_file_at_the_limit_is_read(monkeypatch, tmp_path):
    """The bound is the file's rows, not less: 10,000 waypoints reach the planner (stopped there)."""
    seen = {}

    def stop(params, kind, points=None, **kwargs):
        seen["points"] = None if points is None else len(points)
        raise AssertionError("stop here")

    monkeypatch.setattr(paths_module, "path_for", stop)
    path = tmp_path / "limit.csv"
    x = np.linspace(-0.05, 0.05, MAX_WAYPOINTS)
    path.write_text("p1,p2\n" + "\n".join(f"{v:.8f},0" for v in x) + "\n")
    with pytest.raises(AssertionError, match="stop here"):
        main(["plan", "--path", str(path), "--force-limit", "100"])
    assert seen["points"] == MAX_WAYPOINTS


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--dwell", "1e308"), ("--dwell", "-0.5"), ("--motor-constant", "1e308"), ("--motor-constant", "0")],
)
def test_size_refuses_absurd_values(capsys, tmp_path, flag, value):
    src = tmp_path / "m.csv"
    src.write_text("t,p1,p2\n0,0,0\n0.1,0.001,0\n0.2,0.002,0\n0.3,0.003,0\n")
    _refused(capsys, ["size", "--input", str(src), flag, value], flag)


@pytest.mark.parametrize(
    ("flag", "value"),
    [
        ("--rate", "1e308"),
        ("--rate", "inf"),
        ("--wn", "1e308"),
        ("--zeta", "1e308"),
        ("--noise", "1e308"),
        ("--seed", "-1"),
        ("--seed", "9" * 40),
        ("--payload", "1e308"),
    ],
)
def test_control_refuses_absurd_values_before_simulating(no_work, capsys, flag, value):
    _refused(capsys, ["control", "--trajectory", "circle", "--controller", "pd", flag, value], flag)


@pytest.mark.parametrize("count", ["1000000000", "0"])
def test_crosscheck_refuses_an_absurd_count_before_the_work(no_work, capsys, count):
    _refused(capsys, ["crosscheck", "--random", count], "--random")


def test_an_export_failure_names_the_users_path_not_the_temporary_file(capsys, tmp_path):
    target = tmp_path / "model.urdf"
    target.mkdir()  # a folder where the file should go: os.replace fails on it
    assert main(["export", "--format", "urdf", "--output", str(target)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(target) in err and ".tmp" not in err and ".tpm-viz" not in err, err
    assert [p.name for p in tmp_path.iterdir()] == ["model.urdf"]  # no temporary file left behind


def test_a_clip_or_report_write_failure_names_the_users_path(tmp_path):
    target = tmp_path / "clip.gif"
    target.mkdir()
    with pytest.raises(InputError) as failed:  # a folder is never replaced (tpm_viz.core.files.output_target)
        write_bytes(str(target), b"GIF89a")
    assert str(target) in str(failed.value) and ".tmp" not in str(failed.value)
    assert [p.name for p in tmp_path.iterdir()] == ["clip.gif"]
