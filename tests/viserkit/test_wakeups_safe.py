"""viser wakes its senders with ``asyncio.Event.set()`` from whatever thread pushes a message. From a callback thread
that races the event loop adding a waiter ("deque mutated during iteration", seen in the server log under
``bench_load.py --mode hall``) and can leave a sender asleep for good. The safe wake-ups (viserkit/patches.py) hand the
wake-up to the loop instead; here four threads push while thirty senders wait and clear, as viser's do for a
broadcast: no push raises, and no sender misses a wake-up (a lost one times out)."""

from __future__ import annotations

import asyncio
import sys
import threading

from tpm_viz.viserkit.probe import message_buffer, wake_safely

PUSHES = 4 * 2000


def test_pushes_from_threads_wake_every_sender_and_never_raise():
    loop = asyncio.new_event_loop()
    buffer = message_buffer(loop, False)
    wake_safely(buffer)
    event = buffer.message_event
    errors: list[BaseException] = []
    count, lock, stuck = [0], threading.Lock(), [0]

    def pusher() -> None:
        for _ in range(PUSHES // 4):
            with lock:  # push counts the message under its buffer lock, then wakes the senders
                count[0] += 1
            try:
                event.set()
            except BaseException as exc:
                errors.append(exc)

    async def sender() -> None:
        seen = 0
        while seen < PUSHES:
            try:
                await asyncio.wait_for(event.wait(), timeout=2.0)
            except TimeoutError:
                stuck[0] += 1
                return
            event.clear()
            seen = count[0]

    async def main() -> None:
        threads = [threading.Thread(target=pusher) for _ in range(4)]
        senders = [asyncio.create_task(sender()) for _ in range(30)]
        for t in threads:
            t.start()
        await asyncio.gather(*senders)
        for t in threads:
            t.join()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)  # switch threads often: the race needs a switch inside Event.set()
    try:
        loop.run_until_complete(main())
    finally:
        sys.setswitchinterval(interval)
        loop.close()
    assert not errors
    assert stuck[0] == 0
