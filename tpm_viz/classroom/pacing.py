"""How often the students' own copies may be redrawn while they are dragged, so that a busy server stays responsive.

The server runs on one core's worth of Python (the GIL). A drag commit of an own copy costs a few milliseconds (the
inverse kinematics, both dynamic models, the tab's scene and panel), so thirty students dragging their own copies at
the browser's 20 Hz ask for more than the whole core, and everything, the presenter's broadcast included, queues up.

A :class:`Pacer` keeps the time spent on those commits near a budget: a fraction of the wall time, since the commits
hold the hub's lock one after the other however the GIL is shared (a commit that waits for the GIL makes the others
wait too: what queues is wall time, not CPU time). It measures that time over windows of :attr:`Pacer.window`
seconds and sets the shortest interval between two commits of one own copy: zero while the budget is kept; when it
is exceeded, the interval grows with the overload (``load / budget``) and shrinks again when the load falls. A
commit always takes the latest position of the gizmo (latest value wins), so a longer interval makes a dragged copy
move in fewer, larger steps, not later: the position drawn is the newest one the tab sent, at most one
browser event old when it is drawn (``benchmarks/bench_load.py --mode hall``).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

__all__ = [
    "BUSY_NUMBERS_INTERVAL",
    "WATCH_INTERVAL",
    "WATCH_TABS",
    "Pacer",
    "watch_interval",
    "watch_phase",
    "watch_slot",
]

LIVE_NUMBERS_INTERVAL = 0.25
"""Shortest time [s] between two refreshes of a panel's dashboard, ``p`` and ``d`` on the intermediate frames of a
drag or a playback (the scene itself moves at every frame; the frame where the motion stops is always shown), and
the age up to which a dashboard shows the numbers of an earlier frame of the drag. Each new set of numbers evaluates
both models (closed form and Pinocchio), so that the two numbers shown side by side always belong to the same
state."""
BUSY_NUMBERS_INTERVAL = 1.0
"""While own copies are paced, a dragged copy's numbers (its panel: both dynamic models, the typed boxes) are
refreshed at most once per this many seconds [s] mid-drag; its mechanism moves at every commit and the numbers are
always refreshed when the drag ends. The panel was half of such a commit (1.7 of 3.7 ms of CPU, ``bench_load.py
--mode hall``), and a number that changes four times a second cannot be read during a drag anyway."""


WATCH_INTERVAL = 0.05
"""While another tab drags (or a trajectory plays), a watching tab's own part of a frame (gizmo, panel, teaching
layer) is drawn at most once per this many seconds [s] (20 Hz); the mechanism itself is drawn at every commit, once
for all tabs, and the last frame of a drag is always drawn."""
WATCH_TABS = 30
"""Beyond this many tabs on one session, :data:`WATCH_INTERVAL` grows with the square of their number (60 tabs:
5 Hz each, 150 watchers: 0.8 Hz each), so that the per-tab parts of a lecture hall (gizmo, panel: one message
batch per tab) cost less than those of 30 tabs (``benchmarks/bench_load.py --mode hall``)."""
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def watch_interval(tabs: int) -> float:
    """How often [s] each of ``tabs`` tabs watching one session draws its own part of an intermediate frame."""
    return WATCH_INTERVAL * max(1.0, (tabs / WATCH_TABS) ** 2)


def watch_phase(index: int) -> float:
    """The phase in [0, 1) of the tab numbered ``index``: consecutive numbers are spread evenly over the interval
    (the golden-ratio sequence), so that any number of tabs that joined one after the other draw in turn."""
    return (index * _GOLDEN) % 1.0


def watch_slot(now: float, tabs: int, phase: float) -> int:
    """The slot of a watching tab with ``phase`` at ``now`` (``time.monotonic()``): it draws an intermediate frame
    when its slot changes, once per :func:`watch_interval`. The slots of different phases change at different
    commits: before, every watcher drew at the same commit once per interval, a burst of 120 panels that held the
    hub and then the senders (the lecture hall's p95)."""
    return math.floor(now / watch_interval(tabs) + phase)


@dataclass
class Pacer:
    """The interval between two drag commits of one own copy [s], from the time those commits took."""

    budget: float = 0.1
    """Fraction of the wall time the commits of own copies may take (the rest: the presenter, sending, reading).
    Measured with 150 tabs, 30 of them dragging own copies (``bench_load.py --mode hall``, 2 cores), p95 of the
    watchers / median tab's p95 of the own copies: with commits of ~3 ms, 0.4 gave 205-230 / 335-380 ms, 0.2 gave
    134 / 242 ms and 0.1 gave 158 / 289 ms. With the cheaper commits of :data:`BUSY_NUMBERS_INTERVAL` and coalesced
    wake-ups (~2 ms), 0.1 gave 134-146 / 272-334 ms against 148-193 / 291-382 ms for 0.2 (runs alternated; the
    server then spends ~85 % of a core whatever the budget: the reading and sending of 150 tabs set it). With the
    lean senders (:mod:`tpm_viz.viserkit.windows`) and a 0.5 ms GIL switch interval, 0.1 gives 40 / 61-67 ms (the host
    taking 3-5 %) and 0.2 gave more queueing (median tab 152 ms against 113 ms in runs alternated before the switch
    interval)."""
    window: float = 0.5
    """Length of a measuring window [s]."""
    start: float = 0.05
    """The first interval [s] when the budget is first exceeded (the browser's 20 Hz)."""
    ceiling: float = 0.5
    """The longest interval [s]: a dragged copy moves at least twice a second."""
    floor: float = 0.02
    """An interval below this [s] is dropped to zero (no pacing)."""
    _interval: float = 0.0
    _spent: float = 0.0
    _since: float | None = None
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def spent(self, seconds: float, now: float) -> None:
        """A commit of an own copy took ``seconds`` [s] (wall time), ending at ``now`` (``time.monotonic()``)."""
        with self._lock:
            self._roll(now)
            self._spent += max(0.0, float(seconds))

    def interval(self, now: float) -> float:
        """The shortest interval between two commits of one own copy now [s]."""
        with self._lock:
            self._roll(now)
            return self._interval

    def load(self, now: float) -> float:
        """Fraction of the wall time spent on commits in the current window so far."""
        with self._lock:
            self._roll(now)
            elapsed = now - self._since if self._since is not None else 0.0
            return self._spent / elapsed if elapsed > 0 else 0.0

    def _roll(self, now: float) -> None:
        if self._since is None:
            self._since = now
            return
        elapsed = now - self._since
        if elapsed < self.window:
            return
        load = self._spent / elapsed
        self._since, self._spent = now, 0.0
        ratio = load / self.budget
        if self._interval == 0.0:
            if ratio > 1.0:
                self._interval = min(self.ceiling, self.start * ratio)
            return
        self._interval = min(self.ceiling, self._interval * math.sqrt(ratio))  # damped: no oscillation
        if self._interval < self.floor:
            self._interval = 0.0
