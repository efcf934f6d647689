"""Waking viser's senders: once per loop turn, however many messages the callback threads queue.

viser wakes a tab's sender for every message, atomic block and flush it is given, each time with
``loop.call_soon_threadsafe``: one write to the event loop's self-pipe, a system call that also hands the GIL to the
loop thread, which then runs one wake-up and hands it back. A drag commit of an own copy made four of them (1.4 of
its 2.9 ms, ``cProfile``), a presenter's commit one per watching tab drawn. :class:`Wakeups` stands in for the loop
where viser's buffers call it: a call from another thread joins the wake-ups already waiting for the loop (the
same callback once), a call on the loop thread needs no self-pipe at all. Nothing here touches a private viser
name: :mod:`.core` installs it.
"""

from __future__ import annotations

import asyncio
import logging
import threading
from collections.abc import Callable
from typing import Any

__all__ = ["Wakeups", "thread_safe_set"]

log = logging.getLogger(__name__)


class Wakeups:
    """An event loop whose ``call_soon_threadsafe`` coalesces argument-free callbacks (everything else is the loop's).

    Callbacks are run in the order they were first asked for since the last run; a callback asked for again before
    it ran runs once (viser's are ``Event.set``: idempotent). A callback that raises is logged; the others run."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.loop = loop
        self._lock = threading.Lock()
        self._waiting: dict[Callable[[], Any], None] = {}  # insertion-ordered set
        self._scheduled = False

    def __getattr__(self, name: str) -> Any:
        return getattr(self.loop, name)

    def call_soon_threadsafe(self, callback: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Run ``callback()`` on the loop soon; raises RuntimeError if the loop is closed (as asyncio's does)."""
        if args or kwargs:
            self.loop.call_soon_threadsafe(callback, *args, **kwargs)
            return
        if asyncio._get_running_loop() is self.loop:  # on the loop thread: no wake-up needed
            self.loop.call_soon(callback)
            return
        if self.loop.is_closed():
            raise RuntimeError("Event loop is closed")
        with self._lock:
            self._waiting[callback] = None
            if self._scheduled:
                return  # joins the run already asked for
            self._scheduled = True
        try:
            self.loop.call_soon_threadsafe(self._run)
        except RuntimeError:  # closed in between
            with self._lock:
                self._scheduled = False
                self._waiting.clear()
            raise

    def _run(self) -> None:
        with self._lock:
            calls, self._waiting, self._scheduled = list(self._waiting), {}, False
        for call in calls:
            try:
                call()
            except Exception:
                log.exception("a wake-up of viser's senders failed")


def thread_safe_set(event: asyncio.Event, loop: Any) -> Callable[[], None]:
    """``event.set`` that is safe from any thread: asyncio's ``Event.set()`` from another thread races the loop
    adding a waiter ("deque mutated during iteration") and can leave that waiter asleep for good. Off the loop the
    set goes to ``loop`` (once until it ran; not at all if already set: the waiter reads after clearing)."""
    pending = [False]

    def run() -> None:
        pending[0] = False
        asyncio.Event.set(event)

    def set_() -> None:
        if asyncio._get_running_loop() is getattr(loop, "loop", loop):
            asyncio.Event.set(event)
        elif not (event.is_set() or pending[0]) and not loop.is_closed():
            pending[0] = True
            loop.call_soon_threadsafe(run)

    return set_
