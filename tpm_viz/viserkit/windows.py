"""Sending viser's messages to the tabs with less work per tab: one frame per window, shared; one timer per buffer.

viser sends each tab its messages in windows, read from a buffer (one shared by every tab, one per tab), by a
producer per tab and buffer (``viser.infra``: ``_message_producer`` and ``AsyncMessageBuffer._window_loop``). In a
lecture hall that work is done 150 times per broadcast update, on the event loop that also reads every tab's input
(``benchmarks/bench_load.py --mode hall --profile``):

- each producer encoded its window itself (msgpack, then zstd), although every watcher's window holds the same
  messages: :class:`Frames` encodes a window of the shared buffer once and hands the same bytes to every tab whose
  window has the same messages (viser's frame timestamp is then the first tab's);
- after each window, each producer waited for a flush or 1/60 s with a new task, ``asyncio.wait`` and a timer:
  :class:`Tick` is one timer per buffer, rung by the timer or by a flush, that every producer of the buffer waits
  on; a flush it has not seen yet ends a producer's wait at once, as before.

The windows themselves are viser's: the same messages in the same order, at most ``max_window_size`` per window, none
while an atomic block is open, a tab's own echo left out, the end-of-replay marker right after the backlog a new tab
found, and each tab's cursor kept for viser's garbage collector of the shared buffer. Nothing here touches a private
viser name: :mod:`.patches` puts it on one server's buffers, with viser's own encoding.
"""

from __future__ import annotations

import asyncio
import contextlib
import time
from collections import OrderedDict
from collections.abc import AsyncGenerator, Callable, Sequence
from typing import Any

__all__ = ["Frames", "Tick", "encoder", "producer", "window_loop"]

Encode = Callable[[Sequence[Any]], bytes]
"""Turns a window of messages into the bytes of one websocket frame (viser's wire format)."""


def encoder(
    msgpack: Callable[[Any], bytes],
    compress: Callable[[bytes], bytes],
    align: Callable[..., None],
    serialize: Callable[[Any, list[Any]], Any] | None = None,
) -> Encode:
    """viser's wire format (its ``_message_producer``), from its own msgpack encoder, zstd compressor and buffer
    alignment: the lengths of the msgpack and of its compressed bytes (8 bytes each), those bytes, the arrays.
    ``serialize(message, buffers)``: a message's wire dict (default: its ``as_serializable_dict``)."""

    def encode(window: Sequence[Any]) -> bytes:
        buffers: list[Any] = []
        if serialize is None:
            messages = tuple(message.as_serializable_dict(buffers) for message in window)
        else:
            messages = tuple(serialize(message, buffers) for message in window)
        lengths = tuple(b.nbytes for b in buffers)
        inner = msgpack({"messages": messages, "timestampSec": time.perf_counter(), "binaryBufferLengths": lengths})
        compressed = compress(inner)
        parts: list[Any] = [len(inner).to_bytes(8, "little"), len(compressed).to_bytes(8, "little"), compressed]
        align(parts, buffers, 16 + len(compressed))
        return b"".join(parts)

    return encode


class Tick:
    """The end of the pause between two windows of every producer of one buffer: a flush, or ``seconds`` after the
    first producer started waiting (one timer for all of them, not one per tab)."""

    def __init__(self, loop: Any, seconds: float) -> None:
        self.loop = loop
        self.seconds = seconds
        self.flushes = 0
        """How many flushes the buffer was given (a producer that has seen fewer does not wait)."""
        self._event = asyncio.Event()
        self._timer: Any = None

    def flushed(self) -> None:
        """The buffer was flushed (on the event loop): end every pause now."""
        self.flushes += 1
        self._ring()

    def after(self, flush_set: Callable[[], None]) -> Callable[[], None]:
        """``flush_set`` (viser's flush event's ``set``) followed by :meth:`flushed`."""

        def flush() -> None:
            flush_set()
            self.flushed()

        return flush

    async def pause(self) -> None:
        """Wait for the next flush or the end of the current pause."""
        if self._timer is None:
            self._timer = self.loop.call_later(self.seconds, self._ring)
        await self._event.wait()

    def _ring(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        event, self._event = self._event, asyncio.Event()
        event.set()


def _take(buffer: Any, last: int, newest: int, client_id: int) -> tuple[list[Any], int]:
    """The next window after message id ``last`` (at most up to ``newest``) and the last id it covers."""
    window: list[Any] = []
    size, shared = buffer.max_window_size, buffer.persistent_messages
    get = buffer.message_from_id.get if shared else buffer.pop_message_locked  # a tab's own buffer: sent is removed
    with contextlib.nullcontext() if shared else buffer.buffer_lock:
        while last < newest and len(window) < size and buffer.atomic_counter == 0:
            last += 1
            message = get(last)
            if message is not None and message.excluded_self_client != client_id:
                window.append(message)
    return window, last


async def window_loop(
    buffer: Any, client_id: int, backlog_last_id: int, backlog_done: Any | None
) -> AsyncGenerator[Sequence[Any], None]:
    """viser's ``AsyncMessageBuffer._window_loop`` (same windows, same cursor), pausing on the buffer's :class:`Tick`
    (``buffer.tick``) instead of a task, a timer and ``asyncio.wait`` of its own per window."""
    tick: Tick = buffer.tick
    last, seen, marker_due = -1, tick.flushes, backlog_done is not None
    buffer.generator_cursors[client_id] = last
    try:
        while not buffer.done:
            newest = buffer.message_counter - 1
            window, last = _take(buffer, last, min(newest, backlog_last_id) if marker_due else newest, client_id)
            buffer.generator_cursors[client_id] = last  # the garbage collector may drop what this tab has seen
            if marker_due and last >= backlog_last_id and buffer.atomic_counter == 0:
                marker_due = False  # the backlog is sent: mark its end, before any live message
                window.append(backlog_done)
            if window:
                yield window
            else:
                await buffer.message_event.wait()
                buffer.message_event.clear()
            if not window or buffer.message_counter - 1 == last:  # a pause (a flush ends it) before the next
                if tick.flushes == seen:
                    await tick.pause()
                seen = tick.flushes
    finally:
        buffer.generator_cursors.pop(client_id, None)


class Frames:
    """The frames of the windows of one shared buffer, encoded once for every tab (the last ``keep`` windows)."""

    def __init__(self, encode: Encode, keep: int = 8) -> None:
        self.encode = encode
        self.keep = keep
        self._frames: OrderedDict[tuple[int, ...], tuple[Sequence[Any], bytes]] = OrderedDict()

    def frame(self, window: Sequence[Any]) -> bytes:
        """The bytes of ``window``: encoded now, or taken from a tab that was sent the same messages."""
        key = tuple(map(id, window))  # the entry holds the messages: an id is not reused while it is kept
        found = self._frames.get(key)
        if found is not None:
            return found[1]
        data = self.encode(window)
        self._frames[key] = (window, data)
        if len(self._frames) > self.keep:
            self._frames.popitem(last=False)
        return data


def producer(encode: Encode) -> Callable[..., Any]:
    """viser's ``_message_producer`` (same signature), sending each tab the windows of ``buffer``: encoded once for
    all tabs if the buffer is the shared one (its ``frames``, a :class:`Frames`), else with ``encode``."""

    async def produce(websocket: Any, buffer: Any, client_id: int, backlog_done_message: Any = None) -> None:
        windows = buffer.window_generator(client_id, backlog_done_message=backlog_done_message)
        frames: Frames | None = getattr(buffer, "frames", None)  # the shared buffer's (None for a tab's own buffer)
        try:
            while not buffer.done:
                try:
                    window = await windows.__anext__()
                except StopAsyncIteration:
                    break
                await websocket.send(encode(window) if frames is None else frames.frame(window))
        finally:
            await windows.aclose()  # its cursor is dropped now, not at a later garbage collection

    return produce
