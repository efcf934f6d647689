"""``tpm-viz plan | size``: register() on a plain parser, the CSV written, the sizing table, one-line refusals."""

from __future__ import annotations

import argparse
import csv
import io
import math
import re

import numpy as np
import pytest

import tpm_viz as tv
from tests.support import cli
from tests.support.cli import parser_for
from tpm_viz.cli import plan as cli_plan
from tpm_viz.core.errors import TpmVizError
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces

P = tv.Params.paper()


def table(text: str) -> dict[str, np.ndarray]:
    rows = list(csv.DictReader(io.StringIO(text)))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def parser() -> argparse.ArgumentParser:
    return parser_for(cli_plan)


def run(argv: list[str]) -> int:
    args = parser().parse_args(argv)
    return args.func(args)


def test_plan_line_writes_the_columns_and_reports_the_cycle_time(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert run(["plan", "--path", "line", "--force-limit", "100", "--dwell", "0.1", "--output", str(out)]) == 0
    cols = table(out.read_text())
    assert list(cols) == cli_plan.PLAN_COLUMNS
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    cycle = float(re.search(r"cycle time ([\d.]+) s", err).group(1))
    assert cycle == pytest.approx(cols["t"][-1] + 0.1, abs=1e-4)
    assert np.all(np.diff(cols["t"]) > 0) and np.median(np.diff(cols["t"])) == pytest.approx(1e-3, rel=0.01)
    p, dp, ddp = (np.stack([cols[f"{n}1"], cols[f"{n}2"]], -1) for n in ("p", "dp", "ddp"))
    tau = np.stack([cols["tau1"], cols["tau2"]], -1)
    ref = pinocchio_forces(P, p[::5], dp[::5], ddp[::5])  # the written forces agree with the independent model
    assert np.max(np.abs(ref - tau[::5])) < 1e-6
    assert np.max(np.abs(tau)) <= 100.0 * 1.01
    assert np.allclose(p[[0, -1]], [(-0.1, -0.05), (0.1, 0.05)], atol=1e-12)


def test_plan_pick_reports_picks_per_minute(tmp_path, capsys):
    out = tmp_path / "pick.csv"
    assert run(["plan", "--path", "pick", "--force-limit", "200", "--dwell", "0.25", "--output", str(out)]) == 0
    err = capsys.readouterr().err
    cycle = float(re.search(r"cycle time ([\d.]+) s", err).group(1))
    picks = float(re.search(r"([\d.]+) picks/min", err).group(1))
    assert picks == pytest.approx(60.0 / cycle, abs=0.06)
    cols = table(out.read_text())
    assert cols["t"][-1] + 0.25 == pytest.approx(cycle, abs=1e-4)
    assert cols["p1"][0] == pytest.approx(cols["p1"][-1], abs=1e-12)  # there and back


def test_plan_pick_with_a_stated_size(tmp_path, capsys):
    out = tmp_path / "pick.csv"
    argv = ["plan", "--path", "pick", "--force-limit", "100", "--pick-size", "0.03,0.1,0.012", "--output", str(out)]
    assert run(argv) == 0
    cols = table(out.read_text())
    assert np.ptp(cols["p1"]) == pytest.approx(0.1, abs=1e-9)
    assert np.ptp(cols["p2"]) == pytest.approx(0.03, abs=1e-9)
    with pytest.raises(TpmVizError, match="valid region"):  # too wide for the stroke: refused, not shrunk
        run(["plan", "--path", "pick", "--force-limit", "100", "--pick-size", "0.03,0.3,0.012"])
    with pytest.raises(TpmVizError, match="H,W,R"):
        run(["plan", "--path", "pick", "--force-limit", "100", "--pick-size", "0.03"])


def test_plan_from_a_waypoint_file_with_speed_limits(tmp_path, capsys):
    pts = tmp_path / "points.csv"
    pts.write_text("p1,p2\n-0.05,-0.05\n0.05,-0.05\n0.05,0.05\n")
    out = tmp_path / "plan.csv"
    argv = ["plan", "--path", str(pts), "--force-limit", "150", "--speed-limit", "0.5", "--output", str(out)]
    assert run([*argv, "--corner-radius", "0.02"]) == 0
    cols = table(out.read_text())
    assert np.max(np.hypot(cols["dp1"], cols["dp2"])) <= 0.5 * (1 + 1e-9)
    assert (cols["p1"][-1], cols["p2"][-1]) == pytest.approx((0.05, 0.05), abs=1e-12)


def test_size_reads_a_plan_and_prints_the_table(tmp_path, capsys):
    plan_csv, size_csv = tmp_path / "plan.csv", tmp_path / "size.csv"
    run(["plan", "--path", "circle", "--force-limit", "100", "--output", str(plan_csv)])
    capsys.readouterr()
    argv = ["size", "--input", str(plan_csv), "--dwell", "0.5", "--motor-constant", "12", "--output", str(size_csv)]
    assert run(argv) == 0
    text = capsys.readouterr().out
    for name in ("peak force", "RMS force", "peak mechanical power", "energy per cycle", "copper loss"):
        assert name in text
    rows = {r["quantity"]: r for r in csv.DictReader(io.StringIO(size_csv.read_text()))}
    assert list(next(iter(rows.values()))) == ["quantity", "unit", "actuator1", "actuator2"]
    peak = max(float(rows["peak force"]["actuator1"]), float(rows["peak force"]["actuator2"]))
    assert peak == pytest.approx(100.0, rel=0.01)
    cols = table(plan_csv.read_text())
    assert float(rows["cycle time"]["actuator1"]) == pytest.approx(cols["t"][-1] + 0.5, abs=1e-12)
    rms, km = float(rows["RMS force"]["actuator1"]), 12.0
    assert float(rows["mean copper loss"]["actuator1"]) == pytest.approx(rms**2 / km**2, rel=1e-12)


def test_size_of_positions_only_uses_the_closed_form(tmp_path, capsys):
    # a quintic rest-to-rest line (zero acceleration at both ends, as the natural spline of the reader assumes)
    t = np.linspace(0.0, 0.25, 501)
    tau_n = t / 0.25
    s = 10 * tau_n**3 - 15 * tau_n**4 + 6 * tau_n**5
    ds = (30 * tau_n**2 - 60 * tau_n**3 + 30 * tau_n**4) / 0.25
    dds = (60 * tau_n - 180 * tau_n**2 + 120 * tau_n**3) / 0.25**2
    start, delta = np.array([-0.1, -0.05]), np.array([0.2, 0.1])
    p, dp, ddp = start + s[:, None] * delta, ds[:, None] * delta, dds[:, None] * delta
    src = tmp_path / "run.csv"
    src.write_text("t,p1,p2\n" + "".join(f"{a:.17g},{x:.17g},{y:.17g}\n" for a, (x, y) in zip(t, p, strict=True)))
    assert run(["size", "--input", str(src), "--dwell", "0.25"]) == 0
    lines = {ln[:30].strip(): ln.split()[-2:] for ln in capsys.readouterr().out.splitlines()[1:]}
    ref = pinocchio_forces(P, p[::4], dp[::4], ddp[::4])
    assert np.array(lines["peak force"], float) == pytest.approx(np.max(np.abs(ref), axis=0), rel=0.01)
    rms = np.sqrt(np.mean(ref[:-1] ** 2, axis=0) * 0.25 / 0.5)  # the dwell halves the mean square
    assert np.array(lines["RMS force"], float) == pytest.approx(rms, rel=0.01)


@pytest.mark.parametrize(
    "argv, match",
    [
        (["plan", "--path", "line", "--force-limit", "0"], "force limit"),
        (["plan", "--path", "line", "--force-limit", "nan"], "force limit"),
        (["plan", "--path", "line", "--force-limit", "10", "--dwell", "-1"], "dwell"),
        (["plan", "--path", "line", "--force-limit", "10", "--grid", "3"], "grid"),
        (["plan", "--path", "line", "--force-limit", "10", "--speed-limit", "-2"], "speed limit"),
        (["plan", "--path", "line", "--force-limit", "10", "--set", "stroke=0.1"], "valid region"),
        (["plan", "--path", "no-such-file.csv", "--force-limit", "10"], "no-such-file|No such file"),
        (["size", "--input", "no-such-file.csv"], "no-such-file|No such file"),
    ],
)
def test_bad_input_is_refused_with_one_line(argv, match, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    with pytest.raises((TpmVizError, OSError), match=match) as err:
        run(argv)
    assert "\n" not in str(err.value)


def test_bad_files_are_refused_with_one_line(tmp_path):
    no_t = tmp_path / "no_t.csv"
    no_t.write_text("p1,p2\n0,0\n0.01,0\n0.02,0\n0.03,0\n")
    bad_cell = tmp_path / "bad.csv"
    bad_cell.write_text("t,p1,p2\n0,0,0\n0.1,zero,0\n")
    reverse = tmp_path / "reverse.csv"
    reverse.write_text("p1,p2\n0,0\n0.05,0\n0,0\n")
    for argv, match in (
        (["size", "--input", str(no_t)], "'t'"),
        (["size", "--input", str(bad_cell)], "zero"),
        (["plan", "--path", str(reverse), "--force-limit", "10"], "reverses"),
    ):
        with pytest.raises(TpmVizError, match=match) as err:
            run(argv)
        assert "\n" not in str(err.value)


def _registered() -> bool:
    from tpm_viz.cli import build_parser

    try:
        build_parser().parse_args(["plan", "--path", "line", "--force-limit", "1"])
    except TpmVizError:
        return False
    return True


@pytest.mark.slow
@pytest.mark.end_to_end
@pytest.mark.skipif(not _registered(), reason="tpm_viz.cli does not register plan/size yet")
def test_end_to_end_through_tpm_viz_main(tmp_path):
    """The installed ``tpm-viz`` in a child process: a plan (status 0, the table, the cycle time), a bad limit (2)."""
    ok = cli.run_installed("plan", "--path", "line", "--force-limit", "100")
    assert ok.returncode == 0, ok.stderr
    assert list(table(ok.stdout)) == cli_plan.PLAN_COLUMNS
    assert math.isfinite(float(re.search(r"cycle time ([\d.]+) s", ok.stderr).group(1)))
    bad = cli.run_installed("plan", "--path", "line", "--force-limit", "-5")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
