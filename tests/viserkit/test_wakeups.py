"""Waking viser's senders once per loop turn (``viserkit/wakeups.py``): a thread that asks for a thousand wake-ups
while the
loop is busy costs one self-pipe write, every callback still runs (once, in the order first asked), a call on the
loop thread writes nothing, a closed loop refuses like asyncio's, and one failing callback does not stop the others.
Also: viser's buffers see their loop through one shared :class:`Wakeups` once the safe wake-ups are on them
(``viserkit.install``)."""

from __future__ import annotations

import asyncio
import threading

import pytest

from tpm_viz.viserkit.probe import message_buffer, wake_safely
from tpm_viz.viserkit.wakeups import Wakeups


class CountingLoop(asyncio.SelectorEventLoop):
    """An event loop that counts its self-pipe wake-ups (``call_soon_threadsafe``)."""

    def __init__(self) -> None:
        super().__init__()
        self.writes = 0

    def call_soon_threadsafe(self, callback, *args, context=None):
        self.writes += 1
        return super().call_soon_threadsafe(callback, *args, context=context)


def _run_thread(target) -> None:
    thread = threading.Thread(target=target)
    thread.start()
    thread.join(10)


def test_many_wakeups_from_a_thread_cost_one_write_and_run_each_callback_once_in_order():
    loop = CountingLoop()
    wakeups = Wakeups(loop)
    ran: list[str] = []
    first, second = (lambda: ran.append("first")), (lambda: ran.append("second"))

    def ask() -> None:
        for _ in range(1000):
            wakeups.call_soon_threadsafe(first)
            wakeups.call_soon_threadsafe(second)

    _run_thread(ask)  # the loop is not running: nothing ran yet
    assert loop.writes == 1 and ran == []
    loop.run_until_complete(asyncio.sleep(0))
    assert ran == ["first", "second"]
    _run_thread(ask)  # after the run, the next request writes again
    loop.run_until_complete(asyncio.sleep(0))
    assert loop.writes == 2 and ran == ["first", "second"] * 2
    loop.close()


def test_a_call_on_the_loop_thread_needs_no_write_and_arguments_go_to_the_loop():
    loop = CountingLoop()
    wakeups = Wakeups(loop)
    ran: list[object] = []

    async def main() -> None:
        wakeups.call_soon_threadsafe(lambda: ran.append("on loop"))
        await asyncio.sleep(0)

    loop.run_until_complete(main())
    assert ran == ["on loop"] and loop.writes == 0
    _run_thread(lambda: wakeups.call_soon_threadsafe(ran.append, 7))  # not coalesced: it has an argument
    loop.run_until_complete(asyncio.sleep(0))
    assert ran == ["on loop", 7] and loop.writes == 1
    assert wakeups.is_closed() is False and wakeups.get_debug() == loop.get_debug()  # everything else: the loop's
    loop.close()


def test_a_closed_loop_refuses_as_asyncio_does():
    loop = asyncio.new_event_loop()
    wakeups = Wakeups(loop)
    loop.close()
    errors: list[BaseException] = []

    def ask() -> None:
        try:
            wakeups.call_soon_threadsafe(lambda: None)
        except RuntimeError as exc:
            errors.append(exc)

    _run_thread(ask)
    assert len(errors) == 1 and "closed" in str(errors[0])


def test_a_failing_wakeup_is_logged_and_the_others_run(caplog):
    loop = asyncio.new_event_loop()
    wakeups = Wakeups(loop)
    ran: list[str] = []

    def broken() -> None:
        raise ValueError("boom")

    def ask() -> None:
        wakeups.call_soon_threadsafe(broken)
        wakeups.call_soon_threadsafe(lambda: ran.append("after"))

    _run_thread(ask)
    loop.run_until_complete(asyncio.sleep(0))
    loop.close()
    assert ran == ["after"]
    assert any("wake-up" in r.getMessage() and r.exc_info for r in caplog.records)


@pytest.mark.parametrize("buffers", [2, 5])
def test_viser_buffers_share_one_wakeups_per_loop(buffers):
    loop = CountingLoop()
    made = [message_buffer(loop, False) for _ in range(buffers)]
    for b in made:
        wake_safely(b)
    assert all(isinstance(b.event_loop, Wakeups) for b in made)
    assert len({id(b.event_loop) for b in made}) == 1 and made[0].event_loop.loop is loop

    def pulse() -> None:  # what viser does per message, atomic block and flush of every tab
        for _ in range(50):
            for b in made:
                b.flush()
                b.message_event.set()

    _run_thread(pulse)
    assert loop.writes == 1
    loop.run_until_complete(asyncio.sleep(0))
    assert all(b.flush_event.is_set() and b.message_event.is_set() for b in made)
    loop.close()
