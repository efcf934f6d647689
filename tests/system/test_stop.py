"""A stop by the system (SIGTERM) saves the session, even when it comes right after the URL line: the handler is
installed before the line is printed (it used to be installed after it, and a stop in between killed the server
without saving: 4 of 16 fresh servers)."""

from __future__ import annotations

import json
import os
import signal

from tests.support.protocol import ServerProcess


def test_a_stop_right_after_the_url_line_saves_the_session(tmp_path):
    for k in range(4):
        session = tmp_path / f"session-{k}.json"
        server = ServerProcess(session=session)
        os.kill(server.pid, signal.SIGTERM)
        assert server.proc.wait(timeout=30) == 0
        assert "shared" in json.loads(session.read_text())  # the shared mechanism, written by the stop
