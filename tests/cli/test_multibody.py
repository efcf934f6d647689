"""``tpm-viz replay | crosscheck | figures``: register() on a plain parser, then the command in this process; one test
runs the installed entry point end to end (statuses 0, 1 and 2)."""

from __future__ import annotations

import argparse
import csv
import io
import struct

import numpy as np
import pytest

import tpm_viz as tv
from tests.support import cli
from tests.support.cli import parser_for
from tpm_viz.cli import multibody as cli_multibody

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = tv.Params.paper()


@pytest.fixture
def run(capsys):
    """``tpm-viz ARGS`` in this process -> status, stdout, stderr."""
    return lambda *args: cli.run(capsys, *args)


def table(text: str) -> dict[str, np.ndarray]:
    rows = list(csv.DictReader(io.StringIO(text)))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def plain_parser() -> argparse.ArgumentParser:
    return parser_for(cli_multibody)


def test_register_works_on_a_plain_argparse_parser(tmp_path):
    parser = plain_parser()
    out = tmp_path / "replay.csv"
    args = parser.parse_args(["replay", "--trajectory", "line", "--duration", "0.1", "--output", str(out)])
    assert args.func(args) == 0
    cols = table(out.read_text())
    assert list(cols) == cli_multibody.REPLAY_COLUMNS
    assert cols["t"][-1] == pytest.approx(0.1)
    assert np.max(np.hypot(cols["p1_sim"] - cols["p1_ref"], cols["p2_sim"] - cols["p2_ref"])) < 1e-7
    heavy = parser.parse_args(["replay", "--trajectory", "line", "--duration", "0.1", "--set", "m_p=4.42"])
    heavy.output = str(tmp_path / "heavy.csv")
    assert heavy.func(heavy) == 0
    tau_heavy = table((tmp_path / "heavy.csv").read_text())["tau1"]
    assert np.max(np.abs(tau_heavy)) > 1.3 * np.max(np.abs(cols["tau1"]))  # --set reached the model
    for name in ("crosscheck", "figures"):
        argv = [name, "--output-dir", str(tmp_path)] if name == "figures" else [name]
        assert callable(parser.parse_args(argv).func)


def test_replay_prints_csv_that_tracks_the_closed_form(run):
    res = run("replay", "--trajectory", "circle", "--duration", "0.25")
    assert res.returncode == 0, res.stderr
    cols = table(res.stdout)
    assert list(cols) == cli_multibody.REPLAY_COLUMNS
    assert len(cols["t"]) == 251  # dt = min(1 ms, T / 200)
    assert np.max(np.hypot(cols["p1_sim"] - cols["p1_ref"], cols["p2_sim"] - cols["p2_ref"])) < 1e-7
    assert np.max(cols["constraint_violation"]) < 1e-9
    inner = slice(1, -1)  # the cubic law's acceleration is one-sided at t = 0 and T
    p, dp, ddp = tv.circle_state(cols["t"][inner], 0.25)
    tau = np.stack([cols["tau1"][inner], cols["tau2"][inner]], -1)
    assert np.max(np.abs(tau - tv.inverse_dynamics(P, p, dp, ddp))) < 1e-9


def test_crosscheck_passes_with_the_paper_tolerances_and_fails_with_impossible_ones(run):
    ok = run("crosscheck", "--random", "50")
    assert ok.returncode == 0, ok.stderr + ok.stdout
    assert "line T=0.2 s" in ok.stdout and "circle T=0.5 s" in ok.stdout and "random, seed 0" in ok.stdout
    assert ok.stdout.strip().endswith("result: PASS")
    bad = run(
        "crosscheck", "--random", "3", "--duration-line", "0.05", "--duration-circle", "0.05", "--rel-tol", "1e-20"
    )
    assert bad.returncode == 1
    assert "FAIL" in bad.stdout and bad.stdout.strip().endswith("result: FAIL")


def test_figures_writes_two_small_pngs(tmp_path, run):
    res = run("figures", "--output-dir", str(tmp_path / "figs"), "--duration-line", "0.3", "--samples", "101")
    assert res.returncode == 0, res.stderr
    for name in ("fig4_line.png", "fig5_circle.png"):
        data = (tmp_path / "figs" / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        width, height = struct.unpack(">II", data[16:24])
        assert (width, height) == (700, 600)
        assert 10_000 < len(data) < 200_000
        assert name in res.stdout


@pytest.mark.parametrize(
    "argv",
    [
        ["replay", "--trajectory", "square"],
        ["replay", "--trajectory", "line", "--duration", "-1"],
        ["replay", "--trajectory", "line", "--duration", "abc"],
        ["replay", "--trajectory", "line", "--duration", "nan"],
        ["replay", "--trajectory", "line", "--dt", "0"],
        ["replay"],
        ["replay", "--trajectory", "line", "--set", "l_a=abc"],
        ["replay", "--trajectory", "line", "--set", "l_a=0.09"],
        ["crosscheck", "--random", "0"],
        ["crosscheck", "--rel-tol", "-1"],
        ["figures"],
        ["figures", "--output-dir", "/dev/null/x"],
    ],
)
def test_bad_input_exits_2_with_one_line(argv, run):
    res = run(*argv)
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count("\n") == 1 and res.stderr.startswith("tpm-viz: error:")
    assert "Traceback" not in res.stderr and res.stdout == ""


@pytest.mark.end_to_end
def test_the_installed_command_exits_0_1_or_2(tmp_path):
    """The console script in a child process: a replay (0), a cross-check that fails (1), a usage error (2)."""
    ok = cli.run_installed("replay", "--trajectory", "line", "--duration", "0.05", "--output", str(tmp_path / "r.csv"))
    assert ok.returncode == 0 and ok.stderr == "", ok.stderr
    assert list(table((tmp_path / "r.csv").read_text())) == cli_multibody.REPLAY_COLUMNS
    bad = cli.run_installed(
        "crosscheck", "--random", "1", "--duration-line", "0.05", "--duration-circle", "0.05", "--rel-tol", "1e-20"
    )
    assert bad.returncode == 1 and bad.stdout.strip().endswith("result: FAIL")
    usage = cli.run_installed("replay")
    assert usage.returncode == 2 and usage.stdout == "" and usage.stderr.count("\n") == 1
