"""``tpm-viz atlas --scheduler``: the same sweep on a Dask distributed cluster (a scheduler and two workers started
here on 127.0.0.1, stopped by their pids) writes the same file as the local process pool."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import pytest

ATLAS = [
    "atlas",
    "--arrangement",
    "perpendicular",
    "--vary",
    "l_a=0.15:0.35:3",
    "--vary",
    "stroke=0.2:0.4:3",
    "--task=-0.1,0.1,-0.05,0.05",
    "--grid",
    "60",
    "--no-optimum",
]


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=30)


@pytest.mark.slow
def test_the_atlas_on_a_local_dask_cluster_equals_the_local_run(tmp_path):
    info = tmp_path / "scheduler.json"
    log = (tmp_path / "dask.log").open("w")
    procs: list[subprocess.Popen] = []
    try:
        procs.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "dask",
                    "scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    "0",
                    "--no-dashboard",
                    "--scheduler-file",
                    str(info),
                ],
                stdout=log,
                stderr=subprocess.STDOUT,
            )
        )
        deadline = time.monotonic() + 120
        while not (info.exists() and info.stat().st_size > 0):
            assert procs[0].poll() is None, (tmp_path / "dask.log").read_text()
            assert time.monotonic() < deadline, "the scheduler did not start"
            time.sleep(0.05)
        address = json.loads(info.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for k in range(2):
            procs.append(
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        "dask",
                        "worker",
                        "--scheduler-file",
                        str(info),
                        "--no-nanny",
                        "--nthreads",
                        "1",
                        "--host",
                        "127.0.0.1",
                        "--no-dashboard",
                        "--local-directory",
                        str(tmp_path / f"worker{k}"),
                    ],
                    stdout=log,
                    stderr=subprocess.STDOUT,
                )
            )
        cmd = [sys.executable, "-m", "tpm_viz"]
        on_cluster = subprocess.run(
            [*cmd, *ATLAS, "--scheduler", address, "--output", str(tmp_path / "cluster.csv")],
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert on_cluster.returncode == 0, on_cluster.stderr
        local = subprocess.run(
            [*cmd, *ATLAS, "--workers", "2", "--output", str(tmp_path / "local.csv")],
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert local.returncode == 0, local.stderr
    finally:
        for proc in reversed(procs):
            _stop(proc)
        log.close()
    cluster_text = (tmp_path / "cluster.csv").read_text()
    assert cluster_text == (tmp_path / "local.csv").read_text()
    lines = cluster_text.splitlines()
    assert len(lines) == 1 + 9 + 1  # header, the grid, the prototype
    assert "9/9 designs" in on_cluster.stderr and "9/9 designs" in local.stderr
