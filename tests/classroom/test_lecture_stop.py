"""A stop by the system (SIGTERM) saves the session, even when it comes right after the URL line: the handler is
installed before the line is printed (it used to be installed after it, and a stop in between killed the server
without saving: 4 of 16 fresh servers)."""

from __future__ import annotations

import os
import signal

import pytest

from tests.support.protocol import ServerProcess
from tpm_viz.classroom.identity import Keys
from tpm_viz.classroom.lecture import LectureStore

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out


def test_a_stop_right_after_the_url_line_saves_the_session(tmp_path):
    for k in range(4):
        session = tmp_path / f"session-{k}.sqlite3"
        server = ServerProcess(session=session)
        os.kill(server.pid, signal.SIGTERM)
        assert server.proc.wait(timeout=30) == 0
        lecture, _ = LectureStore(session, Keys()).load()
        assert lecture is not None  # the shared mechanism, written by the stop
