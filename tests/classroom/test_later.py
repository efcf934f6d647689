"""The deferred jobs of a tab (tpm_viz.classroom.later): run in order once the server is quiet, never lost, a bug
logged without stopping the next job."""

from __future__ import annotations

import gc
import pathlib
import sys
import threading
import weakref

from tests.support.protocol import wait_for
from tpm_viz.classroom import guard, runtime
from tpm_viz.classroom import later as later_module
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


class _Cycle:
    """Garbage only the cyclic collector frees (as a closed tab's view: its handles' callbacks point back at it)."""

    def __init__(self) -> None:
        self.me = self


def test_tidy_frees_cyclic_garbage_at_the_next_quiet_moment_once():
    gc.disable()  # the collector's own schedule must not free it first
    try:
        later = Later(quiet=3600.0)
        later.arrived()  # a storm is on
        left = _Cycle()
        gone = weakref.ref(left)
        del left
        later.tidy()
        later.tidy()  # a second tab leaving adds no second collection
        assert later.pending() == 1  # the collection waits while tabs arrive (the next hour is theirs); whether the
        # cycle is still there is not asked: another app's tidy in this process may collect it meanwhile
        later.quiet = 0.0
        later.add(lambda: None)  # wakes the thread
        wait_for(lambda: later.pending() == 0, what="the collection")
        assert gone() is None
        again = _Cycle()
        gone = weakref.ref(again)
        del again
        later.tidy()  # the next departure is collected again (the first collection cleared the flag)
        wait_for(lambda: gone() is None, what="the second collection")
    finally:
        gc.enable()


def test_garbage_still_held_by_a_job_at_the_collection_is_collected_once_the_job_lets_go(monkeypatch, caplog):
    monkeypatch.setattr(later_module, "TIDY_AGAIN", 0.05)
    gc.disable()
    try:
        later = Later(quiet=0.0)
        left = _Cycle()
        gone = weakref.ref(left)
        held = [left]  # a job of the tab that left still runs when the server is quiet
        del left
        first = threading.Event()
        real = later._tidy
        monkeypatch.setattr(later, "_tidy", lambda: (real(), first.set()))
        alive = weakref.WeakSet([gone()])
        later.tidy(kept=lambda: len(alive))
        assert first.wait(30)
        assert gone() is not None  # the first collection could not free it
        held.clear()  # the job ends: now it is garbage, and nothing else allocates to wake the collector
        wait_for(lambda: gone() is None, what="a later collection")
        assert not [r for r in caplog.records if "still in memory" in r.getMessage()]
    finally:
        gc.enable()


def test_a_tab_kept_alive_by_mistake_is_logged_once_and_the_collections_stop(monkeypatch, caplog):
    monkeypatch.setattr(later_module, "TIDY_AGAIN", 0.01)
    monkeypatch.setattr(later_module, "TIDY_TRIES", 4)
    later = Later(quiet=0.0)
    kept_forever = _Cycle()
    alive = weakref.WeakSet([kept_forever])
    asked: list[int] = []
    later.tidy(kept=lambda: asked.append(1) or len(alive))
    wait_for(lambda: any("still in memory" in r.getMessage() for r in caplog.records), what="the log line")
    wait_for(lambda: later.pending() == 0, what="the last collection")
    count = len(asked)
    threading.Event().wait(0.2)  # twenty retry periods: nothing more is asked
    assert count == len(asked) == 4
    lines = [r for r in caplog.records if "still in memory" in r.getMessage()]
    assert len(lines) == 1 and lines[0].getMessage().endswith("later: 1 (a reference kept by mistake)")


def test_tune_for_serving_sets_the_collector_and_the_switch_interval():
    thresholds, switch = gc.get_threshold(), sys.getswitchinterval()
    try:
        runtime.tune_for_serving()
        assert gc.get_threshold() == (10_000, 10, 100)
        assert abs(sys.getswitchinterval() - 0.001) < 1e-9
        assert gc.get_freeze_count() > 10_000  # the start-up heap (numpy, ...) is out of every full collection
    finally:
        gc.unfreeze()
        gc.set_threshold(*thresholds)
        sys.setswitchinterval(switch)


def test_the_runtime_settings_have_one_owner():
    """Only ``classroom/runtime.py`` sets the GIL switch interval and the collector's thresholds (issue 36: two places
    set the interval to two values)."""
    package = pathlib.Path(runtime.__file__).resolve().parents[1]
    setters = ("setswitchinterval(", "set_threshold(", "gc.freeze(")
    owners = {
        str(path.relative_to(package))
        for path in package.rglob("*.py")
        if any(call in path.read_text(encoding="utf-8") for call in setters)
    }
    assert owners == {"classroom/runtime.py"}
