"""The leaner senders (viserkit/windows.py, put on a server's buffers by ``viserkit.install``) send exactly the windows
viser's own window loop sends; a window of the shared buffer is encoded once for every tab, in viser's wire format;
one pause timer serves every tab of a buffer, and a flush ends the pause."""

from __future__ import annotations

import asyncio
import random

import msgspec
import numpy as np
import pytest
import zstandard

from tpm_viz.viserkit.probe import VISER_WINDOW_LOOP, align, lean_buffer, message_buffer
from tpm_viz.viserkit.probe import messages as _messages
from tpm_viz.viserkit.windows import Frames, Tick, encoder, window_loop

MARKER = _messages.ReplayDoneMessage()


def _message(k: int, excluded: int | None = None):
    message = _messages.SetPositionMessage(f"/m{k}", (float(k), 0.0, 0.0))  # distinct names: nothing is culled
    message.excluded_self_client = excluded
    return message


async def _run(loop_impl, persistent: bool, seed: int, client: int = 7):
    """Push a seeded mix of messages (a backlog, atomic blocks, this tab's own echoes, flushes) while ``loop_impl``
    reads the windows; returns the windows as lists of labels (``M`` for the end-of-replay marker)."""
    rng = random.Random(seed)
    lean = loop_impl is window_loop
    buffer = (lean_buffer if lean else message_buffer)(asyncio.get_running_loop(), persistent)
    buffer.max_window_size = 5
    count = 0

    def push(n: int) -> None:
        nonlocal count
        for _ in range(n):
            buffer.push(_message(count, client if rng.random() < 0.2 else None))
            count += 1

    push(12)  # found by a tab that connects now
    windows: list[list[str]] = []
    generator = loop_impl(buffer, client, buffer.message_counter - 1, MARKER if persistent else None)
    push(3)  # live messages, queued after the tab connected but before its first window

    async def read() -> None:
        async for window in generator:
            windows.append(["M" if m is MARKER else m.name for m in window])

    reader = asyncio.create_task(read())
    for _ in range(25):
        await asyncio.sleep(rng.choice([0.0, 0.001, 0.02]))
        if rng.random() < 0.3:
            buffer.atomic_start()
            push(rng.randint(1, 4))
            await asyncio.sleep(0.002)  # the reader may run mid-block: it must not send half of it
            buffer.atomic_end()
        else:
            push(rng.randint(0, 3))
        if rng.random() < 0.3:
            buffer.flush()
    deadline = asyncio.get_running_loop().time() + 5.0
    while asyncio.get_running_loop().time() < deadline and buffer.generator_cursors.get(client, -1) < count - 1:
        await asyncio.sleep(0.01)
    await asyncio.sleep(0.05)
    buffer.set_done()
    await asyncio.wait_for(reader, 5.0)
    return windows, count


@pytest.mark.parametrize("persistent", [True, False], ids=["shared buffer", "a tab's own buffer"])
@pytest.mark.parametrize("seed", range(4))
def test_the_same_messages_in_the_same_order_as_viser_sends_them(persistent, seed):
    ours, count = asyncio.run(_run(window_loop, persistent, seed))
    viser, count_v = asyncio.run(_run(VISER_WINDOW_LOOP, persistent, seed))
    assert count == count_v
    flat = [label for window in ours for label in window]
    assert flat == [label for window in viser for label in window]
    assert len([x for x in flat if x != "M"]) < count  # some were this tab's own echoes, left out
    assert all(len([x for x in w if x != "M"]) <= 5 for w in ours)  # at most max_window_size each
    if persistent:
        assert flat.count("M") == 1
        backlog = flat[: flat.index("M")]
        assert all(int(name[2:]) < 12 for name in backlog)  # the marker right after the backlog, before live ones
        assert all(int(name[2:]) >= 12 for name in flat[flat.index("M") + 1 :])


def test_an_atomic_block_is_never_split_across_windows():
    async def scenario():
        buffer = lean_buffer(asyncio.get_running_loop(), True)
        windows: list[list[str]] = []

        async def read():
            async for window in window_loop(buffer, 1, -1, None):
                windows.append([m.name for m in window])

        reader = asyncio.create_task(read())
        await asyncio.sleep(0.01)
        buffer.atomic_start()
        for k in range(4):
            buffer.push(_message(k))
            await asyncio.sleep(0.03)  # the loop runs between the block's messages (and a pause ends)
        buffer.atomic_end()
        await asyncio.sleep(0.05)
        buffer.set_done()
        await asyncio.wait_for(reader, 5.0)
        return windows

    assert asyncio.run(scenario()) == [["/m0", "/m1", "/m2", "/m3"]]


class _CountingLoop:
    def __init__(self, loop):
        self.loop, self.timers = loop, 0

    def call_later(self, *args):
        self.timers += 1
        return self.loop.call_later(*args)


def test_one_timer_ends_the_pause_of_every_tab_and_a_flush_ends_it_at_once():
    async def scenario():
        loop = _CountingLoop(asyncio.get_running_loop())
        tick = Tick(loop, 0.05)
        start = asyncio.get_running_loop().time()
        await asyncio.gather(*(tick.pause() for _ in range(50)))
        timed = asyncio.get_running_loop().time() - start
        start = asyncio.get_running_loop().time()
        waiting = asyncio.gather(*(tick.pause() for _ in range(50)))
        await asyncio.sleep(0)
        tick.flushed()
        await waiting
        return timed, asyncio.get_running_loop().time() - start, loop.timers, tick.flushes

    timed, flushed, timers, flushes = asyncio.run(scenario())
    assert 0.04 <= timed < 0.5  # the timer's 50 ms (a loaded machine may add to it)
    assert flushed < 0.04  # the flush ended the pause before the timer
    assert timers == 2  # one per pause, not one per tab (100 waits)
    assert flushes == 1


def test_a_cancelled_tab_does_not_end_the_others_pause():
    async def scenario():
        tick = Tick(asyncio.get_running_loop(), 0.05)
        one, other = asyncio.create_task(tick.pause()), asyncio.create_task(tick.pause())
        await asyncio.sleep(0.01)
        one.cancel()
        await asyncio.sleep(0.005)
        return other.done()

    assert asyncio.run(scenario()) is False


def _decode(frame: bytes) -> tuple[dict, list[np.ndarray]]:
    """A frame as viser's page reads it (``WebsocketMessageHandler``): two lengths, zstd msgpack, aligned arrays."""
    size, compressed = int.from_bytes(frame[:8], "little"), int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(frame[16 : 16 + compressed], max_output_size=size)
    payload = msgspec.msgpack.decode(inner)
    offset, arrays = 16 + compressed, []
    for length in payload["binaryBufferLengths"]:
        offset += (8 - offset % 8) % 8
        arrays.append(np.frombuffer(frame[offset : offset + length], dtype=np.float32))
        offset += length
    return payload, arrays


def test_a_frame_is_viser_s_wire_format_and_encoded_once_for_every_tab():
    zstd = zstandard.ZstdCompressor(level=1)
    calls = []

    def counted(window):
        calls.append(len(window))
        return encode(window)

    encode = encoder(msgspec.msgpack.encode, zstd.compress, align)
    points = np.random.default_rng(3).normal(size=(4, 3)).astype(np.float32)
    window = [_message(1), _messages.SceneNodeUpdateMessage("/links", {"batched_positions": points}), _message(2)]
    frames = Frames(counted, keep=2)
    first = frames.frame(window)
    assert all(frames.frame(list(window)) is first for _ in range(149))  # 150 tabs, one encoding
    assert calls == [3]
    payload, arrays = _decode(first)
    assert [m["name"] for m in payload["messages"]] == ["/m1", "/links", "/m2"]
    assert payload["messages"][0]["position"] == [1.0, 0.0, 0.0]
    np.testing.assert_array_equal(arrays[0].reshape(4, 3), points)
    for k in range(3):  # older windows are forgotten: at most ``keep`` are held
        frames.frame([_message(10 + k)])
    assert frames.frame(window) is not first and calls[-1] == 3
