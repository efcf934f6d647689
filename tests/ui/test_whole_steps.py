"""A met ``wait_for`` returns once the hub's locked step that wrote the awaited value is over (the ``whole_steps``
fixture, tests/support/fixtures.py): what a test reads next was written in that step."""

from __future__ import annotations

import threading

from tests.support.protocol import wait_for


def test_a_met_wait_returns_after_the_step_that_met_it(app):
    written: dict[str, int] = {}
    first = threading.Event()

    def step() -> None:
        with app.hub.lock:  # one locked step: a value, then (a moment later) its sibling
            written["picked"] = 3
            first.set()
            threading.Event().wait(0.5)
            written["described"] = 3

    writer = threading.Thread(target=step)
    writer.start()
    try:
        assert first.wait(30.0)
        wait_for(lambda: written.get("picked") == 3, what="the first value")
        assert written.get("described") == 3  # the step was over when the wait returned
    finally:
        writer.join(30.0)
