"""One server per store (issue 35, item 4): two ``tpm-viz serve`` on one store both saved, and the lecture was
whichever saved last. Now the second is refused in one line naming the first one's port and ``--session``; the
lock is the kernel's (``flock`` on ``<store>.lock``), so a ``kill -9`` leaves nothing stale; a lock that cannot be
made (read-only folder, full disk) does not stop the start, as before.

Servers run as child processes on 127.0.0.1 (``--port 0``), each stopped by its own pid."""

from __future__ import annotations

import errno
import io
import json
import os
import signal
import subprocess
import sys
from contextlib import redirect_stderr
from pathlib import Path

import pytest

import tpm_viz.classroom.storelock as storelock
from tpm_viz.classroom.identity import Keys
from tpm_viz.classroom.lecture import LectureStore
from tpm_viz.classroom.storelock import StoreBusyError, StoreLock, lock_path
from tpm_viz.core.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
START_SECONDS = 120.0
"""Longest a server may take to print its URL or its refusal on a loaded machine (it imports viser and Pinocchio)."""


# -- the lock itself --------------------------------------------------------------------------------------------------
def test_a_second_lock_on_one_store_is_refused_naming_the_holders_port(tmp_path):
    store = tmp_path / "classroom.sqlite3"
    first, notice = StoreLock.take(store)
    assert first is not None and notice is None
    with pytest.raises(StoreBusyError) as starting:  # the holder has not written its port yet
        StoreLock.take(store)
    assert f"process {os.getpid()}, still starting" in str(starting.value)
    first.serving(43117)
    with pytest.raises(StoreBusyError) as busy:
        StoreLock.take(store)
    text = str(busy.value)
    assert "\n" not in text and "port 43117" in text and "--session FILE" in text and str(store) in text
    first.release()
    again, notice = StoreLock.take(store)  # released: the next one takes it at once
    assert again is not None and notice is None
    again.release()
    assert lock_path(store).is_file()  # the file stays (removing it would let two servers lock two files)


def test_two_stores_of_a_process_on_one_path_exclude_each_other(tmp_path):
    path = tmp_path / "lecture.sqlite3"
    with redirect_stderr(io.StringIO()):
        first = LectureStore(path, Keys())
        first.open()
        first.serving(40001)
        second = LectureStore(path, Keys())
        with pytest.raises(InputError, match="port 40001"):
            second.open()
        assert second.store is None  # nothing opened, read or moved aside
        first.stop()
        second.open()  # the first stopped: the store is free
        assert second.store is not None
        second.stop()


def test_fresh_never_sets_aside_a_store_another_server_holds(tmp_path):
    path = tmp_path / "lecture.sqlite3"
    with redirect_stderr(io.StringIO()):
        first = LectureStore(path, Keys())
        first.open()
        with pytest.raises(StoreBusyError):
            LectureStore(path, Keys(), fresh=True).open()
        first.stop()
    assert not [p.name for p in tmp_path.iterdir() if "before-fresh" in p.name]  # nothing set aside


@pytest.mark.parametrize("code", [errno.EROFS, errno.ENOSPC, errno.EACCES])
def test_a_lock_file_that_cannot_be_made_is_a_notice_and_the_store_still_saves(tmp_path, monkeypatch, code):
    real_open = os.open

    def refusing(path, flags, mode=0o777, *, dir_fd=None):
        if str(path).endswith(".lock"):
            raise OSError(code, os.strerror(code))
        return real_open(path, flags, mode, dir_fd=dir_fd)

    monkeypatch.setattr(storelock.os, "open", refusing)
    err = io.StringIO()
    with redirect_stderr(err):
        store = LectureStore(tmp_path / "lecture.sqlite3", Keys())
        store.open()
        assert store.store is not None  # saving works as before
        store.stop()
    lines = err.getvalue().splitlines()
    assert (
        len(lines) == 1 and lines[0].startswith("warning: cannot make the lock file") and os.strerror(code) in lines[0]
    )


def test_a_lock_path_that_is_a_fifo_is_not_opened_for_ever_and_left_as_it_is(tmp_path):
    store = tmp_path / "lecture.sqlite3"
    os.mkfifo(lock_path(store))
    lock, notice = StoreLock.take(store)
    assert lock is None and "not a regular file" in notice
    assert lock_path(store).is_fifo()


def test_a_full_disk_only_shortens_the_refusal(tmp_path):
    """The holder cannot write its port (RLIMIT_FSIZE 0 in a child: every write fails as on a full disk); it still
    holds the store, and the next server is refused without a port."""
    store = tmp_path / "lecture.sqlite3"
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import resource, signal, sys; from pathlib import Path\n"
            "signal.signal(signal.SIGXFSZ, signal.SIG_IGN); resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))\n"
            "from tpm_viz.classroom.storelock import StoreLock\n"
            "lock, notice = StoreLock.take(Path(sys.argv[1])); lock.serving(8080)\n"
            "print('HELD', lock is not None, notice, flush=True); sys.stdin.read()",
            str(store),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert child.stdout.readline().strip() == "HELD True None"
        assert lock_path(store).stat().st_size == 0  # nothing could be written
        with pytest.raises(StoreBusyError, match="in use by another tpm-viz server; stop"):
            StoreLock.take(store)
    finally:
        child.stdin.close()
        child.wait(timeout=60)


# -- two servers, as a lecturer starts them ---------------------------------------------------------------------------
def _serve(store: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "tpm_viz", "serve", "--host", "127.0.0.1", "--port", "0", "--session", str(store)]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)


def _url_port(proc: subprocess.Popen) -> int:
    line = proc.stdout.readline().strip()  # the first line is the URL (or nothing: the process ended)
    assert line.startswith("tpm-viz serving at http://127.0.0.1:"), (line, proc.poll())
    return int(line.rsplit(":", 1)[1])


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=30)
    for stream in (proc.stdout, proc.stderr):
        stream.close()


@pytest.mark.slow
def test_a_second_server_on_one_store_is_refused_and_a_kill_9_leaves_nothing_stale(tmp_path):
    store = tmp_path / "classroom.sqlite3"
    first = _serve(store)
    third = None
    try:
        port = _url_port(first)
        second = _serve(store)
        out, err = second.communicate(timeout=START_SECONDS)
        assert second.returncode == 2 and out == "", (out, err)
        assert err.count("\n") == 1 and err.startswith("tpm-viz: error: the session store"), err
        assert f"port {port}" in err and "--session FILE" in err and "Traceback" not in err
        os.kill(first.pid, signal.SIGKILL)  # no clean-up runs: only the kernel releases the lock
        first.wait(timeout=60)
        third = _serve(store)
        now = _url_port(third)  # starts at once, on the same store
        assert json.loads(lock_path(store).read_text()) == {"pid": third.pid, "port": now}
    finally:
        _stop(first)
        if third is not None:
            _stop(third)
