"""The deferred jobs of a tab (tpm_viz.classroom.later): run in order once the server is quiet, never lost, a bug
logged without stopping the next job."""

from __future__ import annotations

import threading

from tests.support.protocol import wait_for
from tpm_viz.classroom import guard
from tpm_viz.classroom.later import Later


def test_jobs_wait_for_a_quiet_moment_then_run_in_order():
    later = Later(quiet=3600.0)  # a tab "arrived" just now and the next hour is the class's
    ran: list[int] = []
    later.arrived()
    later.add(lambda: ran.append(1))
    assert ran == [] and later.pending() == 1
    later.quiet = 0.0  # the class is in: the next add wakes the thread, which runs both, oldest first
    later.add(lambda: ran.append(2))
    wait_for(lambda: later.pending() == 0, what="the jobs")
    assert ran == [1, 2]


def test_a_failing_job_is_logged_and_the_next_one_runs(monkeypatch):
    reported: list[tuple[str, str]] = []
    monkeypatch.setattr(guard, "report", lambda exc, what, client=None: reported.append((type(exc).__name__, what)))
    monkeypatch.setattr("tpm_viz.classroom.later.report", guard.report)
    later = Later(quiet=0.0)
    done = threading.Event()
    later.add(lambda: 1 / 0)
    later.add(done.set)
    assert done.wait(30)
    wait_for(lambda: later.pending() == 0, what="the queue")
    assert reported == [("ZeroDivisionError", "a deferred job")]


def test_a_queue_past_its_limit_runs_the_oldest_job_at_once_never_drops_one():
    later = Later(quiet=3600.0, limit=2)
    later.arrived()
    ran: list[int] = []
    for k in range(3):
        later.add(lambda k=k: ran.append(k))
    assert ran == [0]  # run on the adding thread: the queue is back at its limit
    assert later.pending() == 2
    later.quiet = 0.0
    later.add(lambda: ran.append(3))
    wait_for(lambda: later.pending() == 0, what="the rest")
    assert ran == [0, 1, 2, 3]
