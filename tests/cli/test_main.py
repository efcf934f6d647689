"""The tpm-viz command line (``kinematics``, ``dynamics``, ``trajectory``) in this process, including every kind of bad
input; one test runs the installed entry point end to end."""

from __future__ import annotations

import csv
import importlib.metadata
import io

import numpy as np
import pytest

from tests.support import cli
from tests.support.reference import ik_quadratic, minimal_coordinate_forces
from tpm_viz import Params

P = Params.paper()


@pytest.fixture
def run(capsys):
    """``tpm-viz ARGS`` in this process: ``run(*args, stdin=...)`` -> status, stdout, stderr."""
    return lambda *args, stdin=None: cli.run(capsys, *args, stdin=stdin)


def rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def test_kinematics_keeps_unreachable_rows_flagged(tmp_path, run):
    src = tmp_path / "poses.csv"
    src.write_text("p1,p2\n0.05,-0.02\n0.3,0\n-0.135,0\n")
    out = tmp_path / "out.csv"
    res = run("kinematics", "--input", str(src), "--output", str(out))
    assert res.returncode == 0, res.stderr
    r = rows(out.read_text())
    assert [x["reachable"] for x in r] == ["1", "0", "1"]
    assert [x["status"] for x in r] == ["regular", "unreachable", "out_of_stroke"]
    assert [float(r[0]["d1"]), float(r[0]["d2"])] == pytest.approx(ik_quadratic(P, [0.05, -0.02]), abs=1e-15)
    assert float(r[0]["theta1"]) == pytest.approx(np.arcsin(-0.02 / 0.26), abs=1e-15)
    assert r[1]["d1"] == ""  # no value for an unreachable pose, never NaN


def test_dynamics_matches_the_minimal_coordinate_reference_and_set_overrides(tmp_path, run):
    src = tmp_path / "states.csv"
    src.write_text("p1,p2,dp1,dp2,ddp1,ddp2\n0.04,0.03,0.5,-0.7,8,3\n")
    res = run("dynamics", "--input", str(src), "--set", "m_p=3.0", "--set", "l_a=0.3", "--fext", "5,-2")
    assert res.returncode == 0, res.stderr
    r = rows(res.stdout)[0]
    params = P.replace(m_p=3.0, l_a=0.3)
    ref = minimal_coordinate_forces(params, [0.04, 0.03], [0.5, -0.7], [8, 3], f_ext=(5, -2))
    assert [float(r["tau1"]), float(r["tau2"])] == pytest.approx(ref, rel=1e-6)


def test_trajectory_samples_the_cubic_line(tmp_path, run):
    res = run("trajectory", "--kind", "line", "--duration", "0.4", "--samples", "5")
    assert res.returncode == 0, res.stderr
    r = rows(res.stdout)
    t = np.array([float(x["t"]) for x in r])
    s = 3 * (t / 0.4) ** 2 - 2 * (t / 0.4) ** 3  # conventions.md time law
    assert t == pytest.approx([0, 0.1, 0.2, 0.3, 0.4])
    assert [float(x["p1"]) for x in r] == pytest.approx(-0.1 + 0.2 * s, abs=1e-15)
    # the cubic law starts at rest with s'' = 6/T²: p̈(0) = 6/T² (p_end - p_start), force jumps at t = 0
    assert [float(r[0]["ddp1"]), float(r[0]["ddp2"])] == pytest.approx([6 / 0.16 * 0.2, 6 / 0.16 * 0.1])
    assert [float(r[-1]["ddp1"]), float(r[-1]["ddp2"])] == pytest.approx([-6 / 0.16 * 0.2, -6 / 0.16 * 0.1])
    assert float(r[0]["dp1"]) == 0.0 and float(r[0]["dd1"]) == 0.0 and abs(float(r[0]["tau1"])) > 1.0
    assert {"d1", "dd1", "ddd1", "tau1", "tau2", "theta1", "det_jx", "cond"} <= set(r[0])


@pytest.mark.slow
def test_trajectory_from_a_users_csv_matches_the_paper_circle(tmp_path, run):
    """Timed positions of the paper's circle in, spline derivatives and forces out (vs the exact trajectory)."""
    t = np.linspace(0, 0.5, 401)
    phi = 2 * np.pi * (3 * (t / 0.5) ** 2 - 2 * (t / 0.5) ** 3)
    src = tmp_path / "path.csv"
    lines = (f"{a:.17g},{0.1 * np.cos(b):.17g},{0.1 * np.sin(b):.17g}" for a, b in zip(t, phi, strict=True))
    src.write_text("t,p1,p2\n" + "\n".join(lines))
    res = run("trajectory", "--input", str(src))
    assert res.returncode == 0, res.stderr
    r = rows(res.stdout)
    exact = rows(run("trajectory", "--kind", "circle", "--samples", "401").stdout)
    mid = slice(40, -40)  # away from the natural spline's free ends
    for col in ("dp1", "tau1", "tau2"):
        got = np.array([float(x[col]) for x in r])[mid]
        ref = np.array([float(x[col]) for x in exact])[mid]
        assert got == pytest.approx(ref, abs=2e-3 * np.abs(ref).max())
    bad = run("trajectory", "--input", str(src), "--duration", "1")
    assert bad.returncode == 2 and "--duration" in bad.stderr
    both = run("trajectory", "--input", str(src), "--kind", "line")
    assert both.returncode == 2 and "not allowed with" in both.stderr


@pytest.mark.parametrize(
    ("args", "content", "message"),
    [
        (["kinematics"], "", "is empty"),
        (["kinematics"], "p1\n0\n", "missing column 'p2'"),
        (["kinematics"], "p1,p2,p1 [mm]\n0,0,0\n", "'p1' appears twice"),  # extra columns are ignored (issue 13)
        (["kinematics"], "p1,p2\n0,zero\n", "'zero' is not a number"),
        (["kinematics"], "p1,p2\n0,nan\n", "'nan' is not finite"),
        (["dynamics"], "p1,p2,dp1,dp2,ddp1,ddp2\n0.3,0,0,0,0,0\n", "unreachable"),
        (["kinematics", "--set", "l_c=1"], "p1,p2\n0,0\n", "unknown parameter 'l_c'"),
        (["kinematics", "--set", "l_a=-0.2"], "p1,p2\n0,0\n", "l_a must be positive"),
        (["kinematics", "--set", "a=5"], "p1,p2\n0,0\n", "no reachable pose"),
        (["dynamics", "--fext", "1"], "p1,p2,dp1,dp2,ddp1,ddp2\n0,0,0,0,0,0\n", "--fext"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, args, content, message, run):
    src = tmp_path / "in.csv"
    src.write_text(content)
    res = run(*args, "--input", str(src))
    assert res.returncode == 2
    assert res.stdout == ""
    assert message in res.stderr and res.stderr.count("\n") == 1 and "Traceback" not in res.stderr


@pytest.mark.parametrize("duration", ["0", "-1", "nan", "soon"])
def test_bad_duration_exits_2(duration, run):
    res = run("trajectory", "--kind", "circle", "--duration", duration)
    assert res.returncode == 2 and "duration" in res.stderr and res.stderr.count("\n") == 1


def test_missing_file_and_stdin(run):
    res = run("kinematics", "--input", "/nonexistent/poses.csv")
    assert res.returncode == 2 and "No such file" in res.stderr and "Traceback" not in res.stderr
    res = run("kinematics", "--input", "-", stdin="p1,p2\n0,0\n")
    assert res.returncode == 0, res.stderr
    assert float(rows(res.stdout)[0]["d1"]) == pytest.approx(0.482 - 0.092 - 0.260, abs=1e-15)


@pytest.mark.end_to_end
def test_the_installed_command_reads_stdin_writes_stdout_and_exits_0_or_2(tmp_path):
    """The console script of ``[project.scripts]`` in a child process: a pipe in, CSV out, status 0; a missing file,
    status 2 with one line; a usage error, status 2."""
    (script,) = [e for e in importlib.metadata.entry_points(group="console_scripts") if e.name == "tpm-viz"]
    assert script.value == "tpm_viz.cli:main"
    res = cli.run_installed("kinematics", "--input", "-", "--output", "-", stdin="p1,p2\n0,0\n")
    assert res.returncode == 0 and res.stderr == "", res.stderr
    assert float(rows(res.stdout)[0]["d1"]) == pytest.approx(0.482 - 0.092 - 0.260, abs=1e-15)
    res = cli.run_installed("kinematics", "--input", str(tmp_path / "missing.csv"))
    assert res.returncode == 2 and res.stdout == "" and res.stderr.count("\n") == 1 and "No such file" in res.stderr
    res = cli.run_installed("kinematics", "--no-such-option")
    assert res.returncode == 2 and res.stderr.startswith("tpm-viz: error:") and res.stderr.count("\n") == 1
