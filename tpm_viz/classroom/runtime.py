"""The Python runtime of a serving process: its garbage collector and how often its threads take turns.

One server process serves every tab from many threads under one interpreter lock (the GIL): the websocket loop,
viser's callback pool, the heavy-job worker (:mod:`.jobs`), the deferred builds (:mod:`.later`). Two process-wide
settings decide how long a tab waits while another thread computes; :func:`tune_for_serving` sets both, once, in
the serving process (:func:`tpm_viz.ui.app.main`; the in-process benchmarks call it to measure what is served). This
module is their one owner: nothing else in tpm-viz sets them (``tests/classroom/test_later.py`` checks).
"""

from __future__ import annotations

import gc
import sys

__all__ = ["GC_THRESHOLDS", "SWITCH_INTERVAL", "tune_for_serving"]

GC_THRESHOLDS = (10_000, 10, 100)
"""Python's collector thresholds in a serving process (Python's defaults: 700, 10, 10)."""
SWITCH_INTERVAL = 0.001
"""[s] How long a thread may keep the GIL while another waits for it (Python's default: 0.005)."""


def tune_for_serving() -> None:
    """Set up the runtime of a server that has just started (process-wide).

    - The start-up heap (numpy, trimesh, Pinocchio, viser) is frozen: no full collection scans it again (with 30 tabs
      one takes ~7 ms instead of ~90 ms).
    - :data:`GC_THRESHOLDS`: a young collection every 10,000 allocations, not 700, and a full collection after 100
      middle ones, not 10. With Python's defaults a reconnect storm of 100 tabs ran three full collections of
      0.1-0.2 s each, plus one of 0.3-0.7 s for the garbage of the tabs that had left. Cyclic garbage still goes:
      young collections free most of it, and the garbage of tabs that left is collected when the server is quiet
      (:meth:`~.later.Later.tidy`).
    - :data:`SWITCH_INTERVAL`: a drag is handed from the websocket loop to a callback thread, the hub and back, each
      step waiting for the GIL; while the worker simulates the control lab for ten other tabs, each wait was up to
      5 ms (a drag took 70 ms, median), now up to 1 ms.

    Measured by ``benchmarks/bench_reconnect.py`` and ``benchmarks/bench_worker_flood.py`` (docs/classroom.md §5).
    """
    gc.collect()
    gc.freeze()
    gc.set_threshold(*GC_THRESHOLDS)
    sys.setswitchinterval(SWITCH_INTERVAL)
