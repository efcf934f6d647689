"""Soak, short: tabs connect, drag and disconnect again and again; nothing is left behind.

A CI-sized version of ``benchmarks/bench_soak.py`` (which runs thousands of cycles against the app in a child
process). Here: a real server on 127.0.0.1 in this process, 30 warm-up cycles, then 240 cycles in batches of four
concurrent tabs; every tab drags (half of them on their own copy) and leaves, half of them without a closing
handshake. Checks: no callback raised and nothing was logged as an error, every view and session of a departed
tab is gone (app, hub, viser), the thread count is back to where it was, and the resident memory grew by less
than 20 MB after the warm-up.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import socket
import threading
import time
from pathlib import Path

import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tests.ui.test_client_reliability import assert_valid
from tpm_viz.classroom.guard import ACTIVITY
from tpm_viz.viserkit.probe import connection_states

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

WARM_UP, CYCLES, BATCH = 30, 240, 4
MAX_GROWTH_MB = 20.0


def rss_mb() -> float:
    """Resident memory of this process [MB] (``/proc/self/status``)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS in /proc/self/status")


def _cycle(app, k: int) -> None:
    """One batch: ``BATCH`` tabs connect, drag (some on their own copy) and leave."""
    before = set(app.views)
    clients = [ProtocolClient(app.port) for _ in range(BATCH)]
    new = wait_for(lambda: len(set(app.views) - before) == BATCH and set(app.views) - before, what="the batch")
    views = [app.views[cid] for cid in sorted(new)]
    wait_for(lambda: all(v.session.readout is not None for v in views), what="first renders")
    for j, (client, view) in enumerate(zip(clients, views, strict=True)):
        if (k + j) % 2:
            client.set_value(view.panel.own_copy, True)
        owner = str(view.client.client_id)
        points = [(0.01 * i * (-1) ** j, 0.008 * i, 0.09) for i in range(1, 6)]
        client.drag(view.scene.gizmo, owner, points, end=(k + j) % 3 != 0)  # some leave mid-drag
    for j, client in enumerate(clients):
        if (k + j) % 2:
            with contextlib.suppress(OSError):
                client.ws.socket.shutdown(socket.SHUT_RDWR)  # gone without a closing handshake
        with contextlib.suppress(Exception):
            client.close()
    wait_for(lambda: not (set(app.views) & new), what="the batch to leave", timeout=20)


def test_connect_drag_disconnect_cycles_leave_nothing_behind(app, caplog):
    threads_before = threading.active_count()
    errors_before = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.WARNING):
        for k in range(WARM_UP // BATCH):
            _cycle(app, k)
        ACTIVITY.wait_idle()
        gc.collect()
        warm = rss_mb()
        start = time.monotonic()
        for k in range(CYCLES // BATCH):
            _cycle(app, k)
        ACTIVITY.wait_idle()
        gc.collect()
        grown = rss_mb() - warm
    elapsed = time.monotonic() - start
    print(f"soak: {CYCLES} tabs in {elapsed:.1f} s, RSS {warm:.0f} MB after warm-up, growth {grown:+.1f} MB")
    assert ACTIVITY.snapshot()[1] == errors_before
    server_side = ("tpm_viz", "websockets.server", "asyncio", "viser")  # not this test's own client sockets
    errors = [r for r in caplog.records if r.levelno >= logging.ERROR and r.name.startswith(server_side)]
    assert not errors, [r.getMessage() for r in errors]
    assert not app.views and not app.hub.shared.views
    assert not connection_states(app.server)  # viser dropped every connection
    pools = ("ThreadPoolExecutor", "tpm-viz-drag")  # viser's callback pool (<= 32 threads) and the drag pool (2)
    wait_for(
        lambda: len([t for t in threading.enumerate() if not t.name.startswith(pools)]) <= threads_before,
        what="per-tab threads to end",
        timeout=20,
    )
    assert threading.active_count() <= threads_before + 34
    assert grown < MAX_GROWTH_MB, f"RSS grew by {grown:.1f} MB over {CYCLES} tabs"
    assert_valid(app.hub.shared.state)
