"""The fair job queue (``tpm_viz.classroom.jobs``) on its own: latest wins per tab and kind, light tabs before
flooders, bounds, a tab leaving, a failing job reported to its tab. Deterministic: a job blocks on an event while
the test queues the rest (nothing runs meanwhile), then the order of the runs is read; the clock of the demand is
the test's own. No sleeps, no timing."""

from __future__ import annotations

import math
import threading

import pytest

from tpm_viz.classroom.jobs import BURST, FLOODER, TAU, Demand, FairJobs
from tpm_viz.core.errors import BusyError, InputError

WAIT = 30.0  # s: only a bound against a hung test, never reached when it passes


class Clock:
    """A hand-moved clock [s]."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class Recorder:
    """Jobs that record their runs in order; :meth:`block` holds the pool's thread until released."""

    def __init__(self, jobs: FairJobs) -> None:
        self.jobs = jobs
        self.runs: list[str] = []
        self.done: dict[str, tuple[object, Exception | None]] = {}
        self.dropped: list[str] = []
        self.lock = threading.Lock()
        self.release = threading.Event()
        self.started = threading.Event()

    def job(self, name: str):
        def fn() -> str:
            with self.lock:
                self.runs.append(name)
            return name.upper()

        return fn

    def submit(self, tab, kind, name: str, fn=None) -> bool:
        def done(result, error) -> None:
            with self.lock:
                self.done[name] = (result, error)

        def dropped() -> None:
            with self.lock:
                self.dropped.append(name)

        return self.jobs.submit(tab, kind, fn or self.job(name), done, dropped)

    def block(self, tab="blocker") -> None:
        """A job that holds the (only) thread until :attr:`release` is set."""

        def fn() -> None:
            self.started.set()
            assert self.release.wait(WAIT)

        self.jobs.submit(tab, "block", fn)
        assert self.started.wait(WAIT)

    def finish(self) -> None:
        self.release.set()
        assert self.jobs.wait_idle(WAIT)


@pytest.fixture
def clock():
    return Clock()


@pytest.fixture
def rec(clock):
    return Recorder(FairJobs(threads=1, per_tab=4, total=12, clock=clock))


def test_a_newer_job_of_the_same_tab_and_kind_replaces_the_pending_one(rec):
    rec.block()
    for value in range(5):
        rec.submit("tab", "plan", f"plan{value}")
    rec.submit("tab", "map", "map")  # another kind of the same tab: not replaced
    rec.submit("other", "plan", "other-plan")  # the same kind of another tab: not replaced
    assert rec.jobs.pending() == 3
    rec.finish()
    assert sorted(rec.runs) == ["map", "other-plan", "plan4"]
    assert rec.done["plan4"] == ("PLAN4", None)
    assert sorted(rec.dropped) == ["plan0", "plan1", "plan2", "plan3"]  # told, never run, no result
    assert not set(rec.done) & set(rec.dropped)


def test_a_tab_that_asks_now_and_then_goes_before_a_flooders_tenth_request(rec, clock):
    rec.block()
    for k in range(9):  # nine requests of a flooder, 0.1 s apart, each a new kind (none replaced)
        clock.now += 0.1
        if k < 4:
            rec.submit("flooder", f"k{k}", f"flood{k}")
        else:
            rec.submit("flooder", "k3", f"flood{k}")  # the per-tab bound (4 kinds): latest wins in the last one
    clock.now += 0.1
    rec.submit("student", "run", "student")
    clock.now += 0.1
    rec.submit("flooder", "k3", "flood9")  # the tenth
    rec.finish()
    assert rec.runs[0] == "student", rec.runs
    assert rec.runs[1:] == ["flood0", "flood1", "flood2", "flood9"]


def test_flooders_take_turns_by_waiting_time_after_every_lighter_tab(rec, clock):
    rec.block()
    for rnd in range(6):  # three flooders asking every 0.2 s: all at the flooding cap
        for tab in ("a", "b", "c"):
            clock.now += 0.05
            rec.submit(tab, "control", f"{tab}{rnd}")
    assert min(rec.jobs.demand.of(t) for t in "abc") > FLOODER
    clock.now += 0.05
    rec.submit("light", "map", "light")
    rec.finish()
    # the light tab first; the flooders in the order they started waiting (a, b, c), each its latest request
    assert rec.runs == ["light", "a5", "b5", "c5"]


def test_demand_decays_with_its_time_constant_and_one_action_counts_once(clock):
    demand = Demand(clock=clock)
    demand.add("t")
    clock.now += 2 * BURST
    demand.add("t")
    for _ in range(3):  # one action: a parameter change re-plans, redraws the map and reruns the trajectory
        clock.now += BURST / 4
        demand.add("t")
    clock.now += TAU
    since_second = TAU + 3 * BURST / 4  # the burst's later requests neither count nor move its time
    assert demand.of("t") == pytest.approx((1.0 + math.exp(-2 * BURST / TAU)) * math.exp(-since_second / TAU))
    clock.now += 100 * TAU
    assert demand.of("t") < 1e-12


def test_pending_jobs_are_bounded_per_tab_and_in_all(rec):
    rec.block()
    accepted = [rec.submit("greedy", f"kind{k}", f"greedy{k}") for k in range(6)]
    assert accepted == [True] * 4 + [False] * 2  # per_tab = 4
    assert rec.submit("greedy", "kind0", "greedy0-again")  # replacing never grows the queue: accepted
    accepted = [rec.submit(f"tab{t}", "run", f"tab{t}") for t in range(10)]
    assert accepted == [True] * 8 + [False] * 2  # total = 12
    assert rec.jobs.pending() == 12
    rec.finish()
    assert len(rec.runs) == 12
    for name in ("greedy4", "greedy5", "tab8", "tab9"):
        result, error = rec.done[name]
        assert result is None and isinstance(error, BusyError), name
        assert name not in rec.runs


def test_a_tab_that_leaves_has_its_pending_jobs_dropped(rec):
    rec.block()
    rec.submit("leaver", "map", "leaver-map")
    rec.submit("leaver", "plan", "leaver-plan")
    rec.submit("stayer", "map", "stayer-map")
    rec.jobs.leave("leaver")
    assert rec.jobs.pending("leaver") == 0 and rec.jobs.pending() == 1
    rec.finish()
    assert rec.runs == ["stayer-map"]
    assert sorted(rec.dropped) == ["leaver-map", "leaver-plan"]
    assert "leaver-map" not in rec.done


def test_a_failing_job_is_told_to_its_tab_and_the_pool_carries_on(rec):
    bugs = []
    rec.jobs._report = lambda exc, what: bugs.append((exc, what))
    rec.block()

    def refuse():
        raise InputError("no such trajectory")

    rec.submit("a", "run", "bug", lambda: 1 / 0)
    rec.submit("b", "run", "refusal", refuse)
    rec.submit("c", "run", "good")
    rec.finish()
    result, error = rec.done["bug"]
    assert result is None and isinstance(error, ZeroDivisionError)
    assert [type(e) for e, _ in bugs] == [ZeroDivisionError]  # the bug is logged; the refusal is the tab's business
    assert isinstance(rec.done["refusal"][1], InputError)
    assert rec.done["good"] == ("GOOD", None)
    rec.submit("a", "run", "after")  # the pool still runs jobs
    assert rec.jobs.wait_idle(WAIT)
    assert rec.done["after"] == ("AFTER", None)


def test_a_failing_publisher_is_logged_and_the_pool_carries_on(rec):
    bugs = []
    rec.jobs._report = lambda exc, what: bugs.append(what)

    def bad_done(result, error):
        raise RuntimeError("a bug in a publisher")

    rec.jobs.submit("a", "run", lambda: 1, bad_done)
    rec.submit("b", "run", "good")
    assert rec.jobs.wait_idle(WAIT)
    assert bugs == ["publishing a background result"] and rec.done["good"] == ("GOOD", None)


def test_callbacks_never_run_inside_submit_so_callers_may_hold_their_locks(rec):
    """A caller submits under the lock its ``done`` and ``dropped`` take (a refusal, a replacement): no deadlock."""
    lock = threading.Lock()  # what the callbacks take: a call inside submit would deadlock (fail at WAIT)
    told: list[tuple[object, str]] = []

    def tell(item) -> None:
        assert lock.acquire(timeout=WAIT)
        told.append(item)
        lock.release()

    def done(k):
        return lambda result, error: tell((k, type(error).__name__))

    rec.block()
    with lock:
        for k in range(6):  # two over the per-tab bound: refused
            rec.jobs.submit("t", f"k{k}", lambda: None, done(k), lambda k=k: tell((k, "dropped")))
        rec.jobs.submit("t", "k0", lambda: None, done("k0 again"))  # replaces k0: it is dropped
        assert told == []
    rec.finish()
    expected = [(4, "BusyError"), (5, "BusyError"), (0, "dropped"), ("k0 again", "NoneType")]
    assert sorted(map(str, told)) == sorted(map(str, [*expected, (1, "NoneType"), (2, "NoneType"), (3, "NoneType")]))


def test_a_tabs_next_job_of_a_kind_waits_for_its_running_one_but_others_use_the_second_thread():
    jobs = FairJobs(threads=2)
    release, started, order = threading.Event(), threading.Event(), []

    def slow():
        started.set()
        assert release.wait(WAIT)
        order.append("first")

    jobs.submit("t", "plan", slow)
    assert started.wait(WAIT)
    jobs.submit("t", "plan", lambda: order.append("second"))  # the same slot: waits for the running one
    other = threading.Event()
    jobs.submit("u", "map", other.set)  # another tab: the second thread takes it at once
    assert other.wait(WAIT)
    assert order == []
    release.set()
    assert jobs.wait_idle(WAIT)
    assert order == ["first", "second"]


def test_threads_end_when_the_queue_is_empty(rec):
    rec.submit("a", "run", "a")
    assert rec.jobs.wait_idle(WAIT)
    alive = [t for t in threading.enumerate() if t.name.startswith("tpm-viz-jobs")]
    for thread in alive:
        thread.join(WAIT)
    assert not any(t.is_alive() for t in alive)


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="at least 1"):
        FairJobs(threads=0)


def test_the_demand_memory_is_bounded_and_forgets_faded_tabs_first(clock):
    demand = Demand(clock=clock)
    for t in range(300):
        demand.add(("old", t))
    clock.now += 20 * TAU  # faded
    for t in range(100):
        clock.now += 2 * BURST
        demand.add(("new", t))
    demand.prune(256)
    assert len(demand) == 100 and demand.of(("new", 0)) > 0.0  # the faded ones went, the recent ones stayed
    for t in range(300):  # at once: nothing faded, 400 in all
        demand.add(("fresh", t))
    demand.prune(256)
    assert len(demand) == 128  # over the bound: those that asked least went, down to half the bound
    assert all(demand.of(("new", t)) == 0.0 for t in range(100))
