"""The Python runtime of a serving process: its garbage collector, how often its threads take turns, and where
large blocks of memory come from.

One server process serves every tab from many threads under one interpreter lock (the GIL): the websocket loop,
viser's callback pool, the heavy-job worker (:mod:`.jobs`), the deferred builds (:mod:`.later`). Two process-wide
settings decide how long a tab waits while another thread computes; :func:`tune_for_serving` sets both, once, in
the serving process (:func:`tpm_viz.ui.app.main`; the in-process benchmarks call it to measure what is served). This
module is their one owner: nothing else in tpm-viz sets them (``tests/classroom/test_later.py`` checks).
"""

from __future__ import annotations

import ctypes
import functools
import gc
import sys
from typing import Any

__all__ = ["GC_THRESHOLDS", "MMAP_THRESHOLD", "SWITCH_INTERVAL", "fixed_mmap_threshold", "tune_for_serving"]

GC_THRESHOLDS = (10_000, 10, 100)
"""Python's collector thresholds in a serving process (Python's defaults: 700, 10, 10)."""
SWITCH_INTERVAL = 0.001
"""[s] How long a thread may keep the GIL while another waits for it (Python's default: 0.005)."""
MMAP_THRESHOLD = 128 * 1024
"""[bytes] Blocks this large or larger are mapped on their own and given back to the system when freed (glibc's
initial threshold, kept fixed: see :func:`fixed_mmap_threshold`)."""
_M_MMAP_THRESHOLD = -3  # glibc's mallopt parameter (malloc.h)


@functools.cache
def _libc() -> Any:
    try:
        return ctypes.CDLL("libc.so.6")
    except OSError:
        return None


def fixed_mmap_threshold(size: int = MMAP_THRESHOLD) -> bool:
    """Keep glibc's mmap threshold at ``size`` bytes (a no-op without glibc). -> whether it was set.

    glibc raises the threshold each time a mapped block is freed, up to 32 MiB, so after a few uploads (512 KiB
    parts, the 540 kB CSV text, its samples, a run's arrays) those blocks come from the heaps of the 32 callback
    threads, and what is freed there stays in the process: 60 tabs that uploaded and left left 127 MB free inside
    the heaps, 29 MB of it returned by ``malloc_trim`` (``mallinfo2``, ``benchmarks/bench_upload_flood.py``). With
    the threshold fixed, the free part was 16 MB and the flood's memory went back (docs/classroom.md §5)."""
    mallopt = getattr(_libc(), "mallopt", None)
    return bool(mallopt is not None and mallopt(_M_MMAP_THRESHOLD, int(size)) == 1)


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

    - :func:`fixed_mmap_threshold`: large blocks (uploads, runs) are given back to the system when freed.

    Measured by ``benchmarks/bench_reconnect.py``, ``benchmarks/bench_worker_flood.py`` and
    ``benchmarks/bench_upload_flood.py`` (docs/classroom.md §5).
    """
    fixed_mmap_threshold()
    gc.collect()
    gc.freeze()
    gc.set_threshold(*GC_THRESHOLDS)
    sys.setswitchinterval(SWITCH_INTERVAL)
