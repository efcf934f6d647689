"""*Compare arrangements* without holding the fair worker: the comparison runs in a thread of its own, and every
batch of designs its search evaluates is one job of the tab in the fair worker (:data:`~.map.CHUNK`
designs), so other tabs' jobs run between two batches as they do between two chunks of a map.

The search's numbers do not depend on how its batches are run (:data:`tpm_viz.design.optimum.Evaluate`): the tab
shows what ``tpm-viz compare`` prints for the same design, task and hold.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Hashable, Sequence

import numpy as np

from tpm_viz.classroom.guard import report
from tpm_viz.classroom.worker import Worker
from tpm_viz.core.errors import BusyError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import T
from tpm_viz.design.atlas import Row
from tpm_viz.design.compare import Hold, compare
from tpm_viz.design.indices import Task
from tpm_viz.design.optimum import Evaluate, Search
from tpm_viz.ui.teaching.design.map import CHUNK

__all__ = ["SEARCH", "WAIT", "Superseded", "in_turns", "start"]

SEARCH = Search()
"""The seed and budget of the tab's search: ``tpm-viz compare``'s defaults, so the tab shows the same optima."""
WAIT = 600.0
"""Longest wait [s] of one batch for its turn before the comparison gives up (the server is swamped)."""


class Superseded(Exception):
    """The tab asked for a newer comparison or left: this one stops at its next batch."""


def _batch(worker: Worker, tab: Hashable, key: str, cost: Callable[[np.ndarray], float], batch: list) -> list[float]:
    """``[cost(x) for x in batch]`` as ``tab``'s job ``key``, waited for (:data:`WAIT` at most)."""
    box: queue.Queue[tuple[object, Exception | None]] = queue.Queue(maxsize=1)
    worker.submit(
        key,
        lambda: [cost(x) for x in batch],
        lambda result, error: box.put((result, error)),
        tab=tab,
        dropped=lambda: box.put((None, Superseded())),
    )
    try:
        result, error = box.get(timeout=WAIT)
    except queue.Empty:
        raise BusyError(T("the server is busy: press Compare arrangements again")) from None
    if error is not None:
        raise error
    assert isinstance(result, list)
    return result


def in_turns(worker: Worker, tab: Hashable, key: str, wanted: Callable[[], bool]) -> Evaluate:
    """An :data:`~tpm_viz.design.optimum.Evaluate` that runs each batch of :data:`CHUNK` designs as ``tab``'s job
    ``key`` and waits for it; raises :class:`Superseded` once ``wanted()`` is false or the job is dropped."""

    def evaluate(cost: Callable[[np.ndarray], float], points: Sequence[np.ndarray]) -> list[float]:
        out: list[float] = []
        for start in range(0, len(points), CHUNK):
            if not wanted():
                raise Superseded
            out += _batch(worker, tab, key, cost, list(points[start : start + CHUNK]))
        return out

    return evaluate


def start(
    params: Params,
    task: Task,
    hold: Hold,
    evaluate: Evaluate,
    done: Callable[[list[Row] | None, Exception | None], None],
) -> threading.Thread:
    """Run :func:`~tpm_viz.design.compare.compare` in a new thread, then ``done(rows, None)`` or ``done(None,
    error)``; nothing when it was superseded."""

    def run() -> None:
        try:
            rows = compare(params, task, hold, how=SEARCH, evaluate=evaluate)
        except Superseded:
            return
        except TpmVizError as exc:
            done(None, exc)
            return
        except Exception as exc:  # a bug: logged, and the tab told
            report(exc, "design comparison")
            done(None, exc)
            return
        done(rows, None)

    thread = threading.Thread(target=run, name="tpm-viz-compare", daemon=True)
    thread.start()
    return thread
