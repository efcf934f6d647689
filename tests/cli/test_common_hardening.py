"""The command line as a trusted Unix tool (issue 12): atomic outputs never the input, capped streaming input,
one-line errors of bounded length with exit 2, ``serve`` that fails fast; real-world CSVs accepted (issue 13).

Network: only 127.0.0.1 and 192.0.2.1 (TEST-NET, never bindable here) are used, and nothing connects anywhere.
"""

from __future__ import annotations

import csv
import errno
import io
import os
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

from tests.support import cli
from tpm_viz.cli import main
from tpm_viz.cli.common import write_output
from tpm_viz.cli.serve import check_bind
from tpm_viz.core.csvio import MAX_BYTES, MAX_ROWS
from tpm_viz.core.errors import InputError

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

POSES = "p1,p2\n0.05,-0.02\n0,0\n"


@pytest.fixture
def run(capsys):
    """``tpm-viz ARGS`` in this process: ``run(*args, stdin=...)`` -> status, stdout, stderr."""
    return lambda *args, stdin=None: cli.run(capsys, *args, stdin=stdin)


def one_line_error(res: cli.Ran | subprocess.CompletedProcess, text: str = "", limit: int = 320) -> None:
    assert res.returncode == 2, res.stderr
    assert text in res.stderr, res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr and len(res.stderr) <= limit


def rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


# --- outputs: never the input, atomic ---------------------------------------------------------------------------


def test_output_that_is_the_input_is_refused_by_any_path(tmp_path, run):
    src = tmp_path / "poses.csv"
    src.write_text(POSES)
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.csv").symlink_to(src)
    for out in (src, tmp_path / "sub" / ".." / "poses.csv", tmp_path / "link.csv"):
        one_line_error(run("kinematics", "--input", str(src), "--output", str(out)), "is the input file")
        assert src.read_text() == POSES
    with open(src, encoding="utf-8") as fh:  # --input - reading the output file through stdin
        saved, sys.stdin = sys.stdin, fh
        try:
            res = run("kinematics", "--input", "-", "--output", str(src))
        finally:
            sys.stdin = saved
    assert res.returncode == 2 and "is the input file" in res.stderr and src.read_text() == POSES


def test_a_failure_while_writing_leaves_the_old_file_and_no_temporary(tmp_path):
    out = tmp_path / "out.csv"
    out.write_text("precious\n")
    out.chmod(0o640)

    class Exploding:
        def __len__(self):
            return 200_000

        def __getitem__(self, item):
            if item.start:  # the second chunk of rows: the temporary file is half written
                raise MemoryError("simulated failure while writing")
            return np.zeros(item.stop - item.start)

    with pytest.raises(MemoryError):
        write_output(str(out), {"a": np.zeros(200_000), "b": Exploding()})
    assert out.read_text() == "precious\n" and os.listdir(tmp_path) == ["out.csv"]
    write_output(str(out), {"a": np.array([1.5, np.nan]), "n": np.array([1, 2])})
    assert out.read_text() == "a,n\n1.5,1\n,2\n" and (out.stat().st_mode & 0o777) == 0o640
    assert os.listdir(tmp_path) == ["out.csv"]


def test_disk_full_is_one_line_naming_the_output(tmp_path, monkeypatch, capsys):
    src = tmp_path / "poses.csv"
    src.write_text(POSES)
    out = tmp_path / "out.csv"

    def full(fd):  # what a full disk answers (/dev/full is a device: refused, tests/cli/test_common_device_nodes.py)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    assert main(["kinematics", "--input", str(src), "--output", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"No space left on device: {out}" in err, err
    assert os.listdir(tmp_path) == ["poses.csv"]


@pytest.mark.end_to_end
def test_a_closed_pipe_stops_quietly():
    """The installed command in a child process whose reader goes away: status 141, nothing on stderr."""
    proc = subprocess.Popen(
        [*cli.installed(), "trajectory", "--kind", "circle", "--samples", "100000"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        assert proc.stdout.readline().startswith(b"t,p1,p2")
        proc.stdout.close()
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 141 and err == b""


# --- inputs: streaming with stated caps, forgiving decoding --------------------------------------------------------


def test_a_file_over_the_size_cap_is_refused_at_once(tmp_path, run):
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate(MAX_BYTES + 1)  # sparse: no disk space used
    start = time.monotonic()
    one_line_error(run("kinematics", "--input", str(big)), "limited to 256 MiB")
    assert time.monotonic() - start < 10


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_dev_zero_is_refused_at_once(run):
    one_line_error(run("kinematics", "--input", "/dev/zero"), "a system file, not a data file")


def test_rows_beyond_the_cap_are_refused_while_streaming(run):
    data = b"p1,p2\n" + b"0,0\n" * (MAX_ROWS + 10)
    start = time.monotonic()
    one_line_error(run("kinematics", "--input", "-", stdin=data), f"more than {MAX_ROWS} data rows")
    assert time.monotonic() - start < 40


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "latin-1", "utf-8-sig"])
def test_other_encodings_are_read(tmp_path, encoding, run):
    src = tmp_path / "poses.csv"
    src.write_bytes("p1 [\u00b5m];p2 [mm]\r\n50000;-20\r\n".encode(encoding))
    res = run("kinematics", "--input", str(src))
    assert res.returncode == 0, res.stderr
    r = rows(res.stdout)[0]
    assert (float(r["p1"]), float(r["p2"])) == pytest.approx((0.05, -0.02))


@pytest.mark.parametrize(
    ("cell", "text"),
    [("1" * 140_000, "longer than 65536 characters"), ("1" * 60_000, "too large"), ("x" * 60_000, "too long")],
    ids=["140kB", "60k-digits", "60k-letters"],
)
def test_huge_cells_give_short_messages(tmp_path, cell, text, run):
    src = tmp_path / "poses.csv"
    src.write_text(f"p1,p2\n{cell},0\n")
    one_line_error(run("kinematics", "--input", str(src)), text)


def test_multi_line_quoted_cell_is_a_one_line_csv_error(tmp_path, run):
    src = tmp_path / "poses.csv"
    src.write_text('p1,p2\n"' + "1\n" * 70_000 + '",0\n')
    one_line_error(run("kinematics", "--input", str(src)), "not valid CSV")


# --- numbers and options ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "args",
    [
        ["trajectory", "--kind", "line", "--duration", "1e308"],
        ["replay", "--trajectory", "line", "--duration", "1e308"],
        ["replay", "--trajectory", "line", "--dt", "1e-320"],
        ["trajectory", "--kind", "line", "--samples", "9" * 100_000],
        ["kinematics", "--input", "-", "--set", "l_a=" + "9" * 100_000],
    ],
    ids=["duration", "replay-duration", "replay-dt", "samples", "set"],
)
def test_extreme_numbers_are_one_short_line(args, run):
    one_line_error(run(*args, stdin=POSES.encode()))


def test_numbers_as_typed_on_the_command_line(run):
    res = run("trajectory", "--kind", "line", "--duration", "0,4", "--samples", "5", "--fext", "1,5;-2")
    assert res.returncode == 0, res.stderr
    assert float(rows(res.stdout)[-1]["t"]) == pytest.approx(0.4)
    res = run("kinematics", "--input", "-", "--set", "l_a=2,6e-1", stdin=POSES.encode())
    assert res.returncode == 0, res.stderr


def test_extreme_forces_get_a_plausibility_note_and_overflow_is_refused(run):
    head = "p1,p2,dp1,dp2,ddp1,ddp2\n"
    res = run("dynamics", "--input", "-", stdin=(head + "0,0,0,0,5e6,0\n").encode())  # mm/s^2 typed as m/s^2
    assert res.returncode == 0 and "note:" in res.stderr and "units" in res.stderr and res.stderr.count("\n") == 1
    assert run("dynamics", "--input", "-", stdin=(head + "0,0,0,0,1,0\n").encode()).stderr == ""
    one_line_error(run("dynamics", "--input", "-", stdin=(head + "0,0,1e300,0,1e308,0\n").encode()), "overflow")


# --- real-world CSVs through the command line ----------------------------------------------------------------------


def test_dynamics_accepts_what_trajectory_writes(tmp_path, run):
    traj = tmp_path / "traj.csv"
    assert run("trajectory", "--kind", "circle", "--samples", "21", "--output", str(traj)).returncode == 0
    res = run("dynamics", "--input", str(traj))
    assert res.returncode == 0, res.stderr
    got, ref = rows(res.stdout), rows(traj.read_text())
    assert [float(r["tau1"]) for r in got] == pytest.approx([float(r["tau1"]) for r in ref], rel=1e-12)


def test_spreadsheet_trajectory_in_milliseconds_and_millimetres(tmp_path, run):
    src = tmp_path / "path.csv"
    src.write_bytes(
        b'\xef\xbb\xbfsep=;\r\n"t [ms]";"p1 (mm)";"p2 (mm)";\r\n0;0;0;\r\n100;10;5;\r\n200;20;10;\r\n300;30;15;\r\n'
    )
    res = run("trajectory", "--input", str(src))
    assert res.returncode == 0 and res.stderr == "", res.stderr
    r = rows(res.stdout)
    assert [float(x["t"]) for x in r] == pytest.approx([0, 0.1, 0.2, 0.3])
    assert float(r[-1]["p1"]) == pytest.approx(0.03)


def test_plain_t_in_milliseconds_gets_a_hint(tmp_path, run):
    src = tmp_path / "path.csv"
    src.write_text("t;p1;p2\n0;0;0\n100;0,01;0\n200;0,02;0\n300;0,03;0\n")
    res = run("trajectory", "--input", str(src))
    assert res.returncode == 0 and "t_ms" in res.stderr and res.stderr.count("\n") == 1


def test_refusal_quotes_the_header_found(tmp_path, run):
    src = tmp_path / "path.csv"
    src.write_text("time;x;y\n0;0;0\n")
    one_line_error(
        run("trajectory", "--input", str(src)), "missing column 'p1' (need t,p1,p2); found header 'time;x;y'"
    )
    src.write_text("t,p1,p2\n0,0,0\n1,100,50\n2,100,50\n3,100,50\n")
    one_line_error(run("trajectory", "--input", str(src)), "'p1 [mm]'")


# --- serve: validated port, fails within 5 s when it cannot bind --------------------------------------------------


@pytest.mark.parametrize(
    ("args", "text"),
    [
        (["--port", "99999"], "from 0 to 65535"),
        (["--port=-1"], "from 0 to 65535"),
        (["--port", "http"], "0 to 65535"),
        (["--host", "192.0.2.1", "--port", "0"], "not an address of this machine"),
    ],
)
@pytest.mark.end_to_end
def test_serve_fails_fast_with_one_line(args, text):
    """In a child process (the installed command): a bad address must be refused before anything is served."""
    start = time.monotonic()
    one_line_error(cli.run_installed("serve", *args), text)
    assert time.monotonic() - start < 5


def test_check_bind_accepts_loopback_port_zero_and_a_busy_port():
    check_bind("127.0.0.1", 0)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        check_bind("127.0.0.1", busy.getsockname()[1])  # the app moves to the next free port
    with pytest.raises(InputError, match="not an address of this machine"):
        check_bind("192.0.2.1", 0)
