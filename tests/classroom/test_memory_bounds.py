"""What a tab leaves behind is bounded and freed (issue 35, item 6: memory kept after abandoned uploads).

- the fair queue's memory of who asked lately never keeps a tab or a session alive (it kept the private copies of
  256 tabs that had left, each holding its whole page);
- the store's codec remembers which uploads it has stored without keeping their samples alive;
- the uploads kept with the tabs that left are bounded in bytes: over the bound, the oldest upload of the address
  holding the most is let go (the tab keeps its record and is told), never another address's first.
"""

from __future__ import annotations

import gc
import weakref

import numpy as np

from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState
from tpm_viz.classroom import away as away_module
from tpm_viz.classroom.away import UPLOAD_NOT_KEPT, Away, upload_bytes
from tpm_viz.classroom.jobs import Demand, FairJobs
from tpm_viz.classroom.records import Records
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.classroom.store import SqliteStore
from tpm_viz.core.params import Params
from tpm_viz.paper.trajectories import Trajectory

STATE = AppState.initial(Params.paper())


class _Tab:
    """A stand-in for a tab or a session (hashable, weakly referenced)."""


def _upload(rows: int = 1000) -> Source:
    t = np.linspace(0.0, 1.0, rows)
    p = np.stack([0.01 * np.sin(t), 0.01 * np.cos(t) - 0.01], axis=1)
    zero = np.zeros_like(p)
    return Source.from_trajectory(Trajectory("up.csv", t, p, zero, zero))


def test_the_demand_memory_keeps_no_tab_alive():
    demand, tab = Demand(), _Tab()
    demand.add(tab)
    demand.add("a name")
    assert demand.of(tab) > 0 and len(demand) == 2
    gone = weakref.ref(tab)
    del tab
    gc.collect()
    assert gone() is None and len(demand) == 1  # the name stays (bounded by prune), the tab went


def test_a_finished_job_leaves_its_session_to_be_freed():
    jobs, session = FairJobs(), _Tab()
    done: list[object] = []
    jobs.submit(session, "run", lambda: 42, lambda result, error: done.append(result))
    assert jobs.wait_idle(30.0) and done == [42]
    gone = weakref.ref(session)
    del session
    gc.collect()
    assert gone() is None


def test_the_store_codec_remembers_a_digest_without_the_samples(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3")
    try:
        records = Records(store)
        source = _upload()
        saved = Saved(STATE, source)
        first = records.saved(saved)["trajectory"]["blob"]
        assert records.saved(saved)["trajectory"]["blob"] == first  # remembered: not encoded again
        gone = weakref.ref(source)
        del source, saved
        gc.collect()
        assert gone() is None
    finally:
        store.close()


def test_the_uploads_kept_with_tabs_that_left_are_bounded(monkeypatch):
    one = upload_bytes({"saved": Saved(STATE, _upload())})
    assert one == 1000 * 3 * 8
    monkeypatch.setattr(away_module, "MAX_UPLOAD_BYTES", 5 * one)
    clock = [0.0]
    away = Away(clock=lambda: clock[0])
    for k in range(4):  # a class: four students at one address, each with an upload
        clock[0] += 1
        away.park(f"c:class{k}", True, Saved(STATE, _upload()), address="10.0.0.1")
    clock[0] += 1
    away.park("c:other", True, Saved(STATE, _upload()), address="10.0.0.2")
    assert away.uploads() == 5 * one and away.let_go == 0  # at the bound: all kept
    for k in range(3):  # an attacker's address: its own oldest go once it holds the most
        clock[0] += 1
        away.park(f"c:attack{k}", True, Saved(STATE, _upload()), address="10.0.0.9")
    assert away.uploads() <= 5 * one and away.let_go == 3
    kept = away.snapshot()
    assert upload_bytes(kept["c:other"][0]) == one  # the other address's first upload is never let go
    dropped = {k for k, rs in kept.items() for r in rs if r.get(UPLOAD_NOT_KEPT)}
    # each time, the oldest upload of the address then holding the most: the class's twice, then the attacker's
    assert dropped == {"c:class0", "c:class1", "c:attack0"}
    assert all(r["saved"].source is None and r["private"] for k in dropped for r in kept[k])  # the copy itself stays
