"""Saving (tpm_viz.classroom.saver) when the disk is full and when the process is killed mid-save: said once,
retried with back-off, said again on recovery; after SIGKILL every store is readable with the last acknowledged
save. Each attack runs in a child process (RLIMIT_FSIZE, SIGKILL), never in the test process."""

from __future__ import annotations

import ast
import os
import random
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.support.stores import stored_lecture
from tpm_viz.classroom.store import SqliteStore

ROOT = Path(__file__).resolve().parents[2]

_WRITER = """
import resource, sys, time
from pathlib import Path
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.app.state import AppState
from tpm_viz.classroom.records import Records
from tpm_viz.classroom.saver import Saver
from tpm_viz.classroom.store import SqliteStore
from tpm_viz.core.params import Params

path, mode = Path(sys.argv[1]), sys.argv[2]
store = SqliteStore(path)
n = [0]

def document():
    params = Params.paper(l_a=0.2 + 1e-4 * n[0])
    saved = Saved(AppState.initial(params))
    tabs = {f"c:{k:064x}": [{"private": True, "saved": saved, "left_at": time.time(), "address": "a"}]
            for k in range(200)}
    return Document(Saved(AppState.initial(params)), 0, tabs)

def say(line, problem):
    print(("PROBLEM " if problem else "OK ") + line, flush=True)

saver = Saver(Records(store), document, say, str(path))
if mode == "kill":
    while True:
        n[0] += 1
        saver.save()
        print(n[0], flush=True)  # acknowledged: save() returned
else:
    saver.tick()
    size = max(p.stat().st_size for p in path.parent.iterdir())
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (size + 4096, hard))
    delays = []
    for _ in range(6):
        n[0] += 1
        saver.tick()
        delays.append(saver.delay)
    print("DELAYS", delays, flush=True)
    resource.setrlimit(resource.RLIMIT_FSIZE, (hard, hard))
    saver.tick()
    print("FAILING", saver.failing, flush=True)
    store.close()
    print("LA", n[0], flush=True)
"""


def _writer(tmp_path: Path, mode: str) -> subprocess.Popen:
    script = tmp_path / "writer.py"
    script.write_text(textwrap.dedent(_WRITER))
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen(
        [sys.executable, str(script), str(tmp_path / "store.sqlite3"), mode],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def test_a_full_disk_is_said_once_retried_with_back_off_and_the_recovery_said_once(tmp_path):
    proc = _writer(tmp_path, "full")
    out, err = proc.communicate(timeout=120)
    lines = out.splitlines()
    problems = [line for line in lines if line.startswith("PROBLEM ")]
    assert proc.returncode == 0 and "Traceback" not in err, err
    assert len(problems) == 1 and "cannot save the session to" in problems[0] and "full" in problems[0].lower()
    assert [line for line in lines if line.startswith("OK ")] == [
        f"OK the session is saved again to {tmp_path}/store.sqlite3"
    ]
    delays = ast.literal_eval(next(line for line in lines if line.startswith("DELAYS")).split(" ", 1)[1])
    assert delays == [4.0, 8.0, 16.0, 32.0, 60.0, 60.0]  # doubling from SAVE_SECONDS, at most a minute
    assert "FAILING False" in lines
    last = int(next(line for line in lines if line.startswith("LA")).split()[1])
    shared, _ = stored_lecture(tmp_path / "store.sqlite3")
    assert shared.state.params.l_a == pytest.approx(0.2 + 1e-4 * last)  # what failed was saved once it could be


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_sigkill_during_saves_leaves_a_readable_store_with_the_last_acknowledged_save(tmp_path, seed):
    proc = _writer(tmp_path, "kill")
    stop_after = random.Random(seed).randint(3, 40)
    acked = 0
    try:
        for line in proc.stdout:
            acked = int(line)
            if acked >= stop_after:
                break
        os.kill(proc.pid, signal.SIGKILL)  # mid-way through the next save
    finally:
        proc.kill()
        proc.wait(timeout=30)
    for line in proc.stdout.read().splitlines(keepends=True):  # acknowledged before the kill, not read yet (a busy
        if line.endswith("\n") and line.strip():  # machine lets the writer run ahead of this reader)
            acked = int(line)
    assert acked >= stop_after, proc.stderr.read()
    store = SqliteStore(tmp_path / "store.sqlite3")  # opens: not damaged (quick_check), not moved aside
    assert len(store.load().copies) == 200
    store.close()
    shared, _ = stored_lecture(tmp_path / "store.sqlite3")
    n = round((shared.state.params.l_a - 0.2) / 1e-4)
    assert n in (acked, acked + 1)  # the last acknowledged save, or the one after it if it committed
