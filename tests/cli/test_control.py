"""``tpm-viz control``: register() on the project's one-line-error parser, handler end to end.

``control`` is not yet in ``tpm_viz.cli.build_parser``; :func:`run` mirrors ``tpm_viz.cli.main``
(TpmVizError and OSError: one line on stderr, exit status 2).
"""

from __future__ import annotations

import csv
import io
import math
import subprocess
import sys

import numpy as np
import pytest

import tpm_viz as tv
from tpm_viz.cli import control as cli_control
from tpm_viz.cli.common import Parser, common_parent
from tpm_viz.multibody.control import COLUMNS


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    parser = Parser(prog="tpm-viz")
    cli_control.register(parser.add_subparsers(dest="command", required=True, parser_class=Parser), common_parent())
    try:
        args = parser.parse_args(argv)
        status = int(args.func(args) or 0)
    except tv.TpmVizError as exc:
        print(f"tpm-viz: error: {exc}", file=sys.stderr)
        status = 2
    out = capsys.readouterr()
    return status, out.out, out.err


def table(text: str) -> dict[str, np.ndarray]:
    rows = list(csv.DictReader(io.StringIO(text)))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def test_columns_are_the_library_columns():
    assert cli_control.CONTROL_COLUMNS == COLUMNS


def test_circle_with_computed_torque_to_a_file(tmp_path, capsys):
    out = tmp_path / "run.csv"
    status, stdout, stderr = run(
        ["control", "--trajectory", "circle", "--controller", "ctc", "--output", str(out)], capsys
    )
    assert status == 0 and stdout == ""
    cols = table(out.read_text())
    assert list(cols) == COLUMNS and len(cols["t"]) == 501 and cols["t"][-1] == pytest.approx(0.5)
    assert cols["e1"] == pytest.approx(cols["p1_ref"] - cols["p1"], abs=1e-15)
    assert np.hypot(cols["p1_ref"], cols["p2_ref"]) == pytest.approx(0.1)  # the paper's circle
    assert np.max(np.hypot(cols["e1"], cols["e2"])) < 1e-3
    assert np.max(np.abs(cols["tau_ff1"])) > 100
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and "ctc on circle" in lines[0] and "RMS error" in lines[0] and "peak force" in lines[0]


def test_every_option_reaches_the_simulation(capsys):
    argv = ["control", "--trajectory", "line", "--duration", "0.1", "--controller", "pd", "--wn", "15", "--zeta", "0.8"]
    argv += ["--payload", "0.5", "--mass-error", "0.1", "--force-limit", "60", "--rate", "2000", "--noise", "1e-5"]
    argv += ["--offset", "0.001,-0.002", "--seed", "3", "--set", "m_p=3.0"]
    status, stdout, stderr = run(argv, capsys)
    assert status == 0, stderr
    cols = table(stdout)
    assert len(cols["t"]) == 201 and cols["t"][1] == pytest.approx(1 / 2000)
    assert np.max(np.abs(cols["tau1"])) <= 60 and "saturated" in stderr
    assert cols["p1"][0] - cols["p1_ref"][0] == pytest.approx(0.001) and cols["e2"][0] == pytest.approx(0.002)
    assert not np.any(cols["tau_ff1"])  # plain PD has no feedforward
    again = run(argv, capsys)[1]
    assert again == stdout  # seeded


def test_a_users_csv_trajectory(tmp_path, capsys):
    path = tmp_path / "path.csv"
    t = np.linspace(0.0, 0.2, 21)
    rows = "\n".join(f"{x},{0.05 * math.sin(8 * x)},{0.01}" for x in t)
    path.write_text("t,p1,p2\n" + rows + "\n")
    status, stdout, stderr = run(
        ["control", "--trajectory", str(path), "--controller", "pdff", "--duration", "0.25"], capsys
    )
    assert status == 0, stderr
    cols = table(stdout)
    assert cols["t"][-1] == pytest.approx(0.25) and cols["p2_ref"] == pytest.approx(0.01)
    assert cols["p1_ref"][100] == pytest.approx(0.05 * math.sin(0.8), abs=1e-4)


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--trajectory", "circle", "--controller", "pid"], "invalid choice"),
        (["--trajectory", "circle", "--controller", "ctc", "--rate", "0"], "rate"),
        (["--trajectory", "circle", "--controller", "ctc", "--offset", "1mm"], "--offset"),
        (["--trajectory", "circle", "--controller", "ctc", "--payload", "-1"], "payload"),
        (["--trajectory", "circle", "--controller", "ctc", "--force-limit", "-5"], "--force-limit"),
        (["--trajectory", "circle", "--controller", "ctc", "--wn", "0"], "natural frequency"),
        (["--trajectory", "circle", "--controller", "ctc", "--duration", "-1"], "--duration"),
        (["--trajectory", "no/such/file.csv", "--controller", "ctc"], "No such file"),
        (["--trajectory", "circle", "--controller", "ctc", "--wn", "400"], "at t ="),
        (["--controller", "ctc"], "--trajectory"),
    ],
)
def test_bad_input_exits_2_with_one_line(extra, needle, capsys):
    status, stdout, stderr = run(["control", *extra], capsys)
    assert status == 2 and stdout == ""
    assert len(stderr.strip().splitlines()) == 1 and needle in stderr


def test_bad_csv_file_exits_2(tmp_path, capsys):
    path = tmp_path / "bad.csv"
    path.write_text("t,x,y\n0,0,0\n")
    status, _, stderr = run(["control", "--trajectory", str(path), "--controller", "ctc"], capsys)
    assert status == 2 and "column" in stderr


def test_importing_the_command_line_module_does_not_load_pinocchio():
    code = "import sys, tpm_viz.cli.control; print('pinocchio' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
