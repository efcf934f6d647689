"""Memory kept after abandoned uploads (issue 35, item 6), written as the attack: browsers from several addresses
each upload a 540 kB CSV to their own copy and leave 1.5 s later; and the caps on upload bytes in flight, per tab, per
address and per server, each refusing with one line.

Before the fix, 60 such browsers left a server 154 MB above its baseline for good (275 from 250 addresses: 241 ->
718 MB): every private copy was kept alive by the worker's memory of who asked lately, the store's codec kept the
last 512 uploads' samples, and glibc kept the freed upload buffers in its thread heaps
(``benchmarks/bench_upload_flood.py``, docs/classroom.md §5).
"""

from __future__ import annotations

import asyncio

import pytest

from tests.support.protocol import ProtocolClient, ServerProcess, wait_for
from tests.support.upload_flood import CSV, flood, one_browser, upload_messages
from tpm_viz.classroom.away import MAX_UPLOAD_BYTES as KEPT_UPLOAD_BYTES
from tpm_viz.core.words import Lang, say
from tpm_viz.viserkit import transport
from tpm_viz.viserkit.core import widget_uuid
from tpm_viz.viserkit.uploads import BUSY_ADDRESS, BUSY_SERVER, budget_of

TABS, ADDRESSES = 60, 6
SAMPLES = 20_000 * 3 * 8
"""Bytes of one upload's samples (t, p1, p2 as float64) that the server keeps with a tab that left, for 30 minutes
(bounded in all by ``Away``'s :data:`~tpm_viz.classroom.away.MAX_UPLOAD_BYTES`)."""
MARGIN_MB = 64.0
"""What else a flood may leave [MB] (the away records themselves, pages of the allocators that stay partly used):
measured 35-55 MB beyond the kept uploads with 60 browsers on this kind of machine; before the fix the whole flood
left +154 MB."""


@pytest.mark.slow
def test_memory_returns_near_its_baseline_after_an_upload_flood():
    server = ServerProcess()
    try:
        asyncio.run(one_browser(server.port, "127.0.0.2", 0))  # the baseline: a server that has served a browser
        baseline = _settled(server)  # its upload's run computed and freed
        result = asyncio.run(flood(server, TABS, ADDRESSES, batch=20))
        assert result.errors == [] and result.refused == 0  # within every cap: each upload was taken
        kept = min(TABS * SAMPLES, KEPT_UPLOAD_BYTES) / 2**20  # the own copies' uploads, kept by design
        bound = kept + MARGIN_MB
        wait_for(
            lambda: server.rss_mb() - baseline < bound,
            timeout=120.0,
            what=f"memory back within {bound:.0f} MB of the baseline {baseline:.0f} MB (now {server.rss_mb():.0f})",
        )
        assert not [line for line in server.log_problems() if "Traceback" in line]
    finally:
        server.stop()


def _settled(server: ServerProcess) -> float:
    """The server's memory [MB] once it has stopped moving (three readings 1 s apart within 2 MB; bounded)."""
    readings: list[float] = []

    def still() -> bool:
        readings.append(server.rss_mb())
        return len(readings) >= 3 and max(readings[-3:]) - min(readings[-3:]) < 2.0

    wait_for(still, timeout=60.0, interval=1.0, what="the server's memory to settle")
    return readings[-1]


class _Tab(ProtocolClient):
    """A tab that also records the notifications it is shown."""

    def __init__(self, port: int, source: str) -> None:
        self.notes: list[tuple[str, str]] = []
        super().__init__(port, source)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        props = m.get("props")
        if m["type"] == "NotificationShowMessage" and isinstance(props, dict):
            self.notes.append((props.get("title"), props.get("body")))


def _start(tab: _Tab, button: str, size: int, name: str) -> str:
    """An upload of ``size`` bytes announced (its first part only sent): it stays in flight."""
    first, *parts = upload_messages(button, b"x" * size, name)
    tab.send(**dict(first))
    tab.send(**parts[0])
    return first["transfer_uuid"]


def test_upload_bytes_in_flight_are_capped_per_tab_per_address_and_in_all(app):
    budget = budget_of(app.server)
    budget.per_address, budget.total = 3 << 20, 5 << 20  # small bounds: a few tabs reach them
    opened: list[_Tab] = []
    try:

        def tab(source: str):
            before = set(app.views)
            opened.append(_Tab(app.port, source))
            new = wait_for(lambda: set(app.views) - before, what="the tab's view")
            view = app.views[next(iter(new))]
            wait_for(lambda: view in app.arrived, what="the tab built")
            return opened[-1], view, widget_uuid(view.teaching.player.upload)

        a, view_a, button_a = tab("127.0.0.5")
        for k in range(transport.MAX_UPLOADS):
            _start(a, button_a, 1 << 20, f"a{k}.csv")
        wait_for(lambda: budget.held("127.0.0.5") == 2 << 20, what="two uploads in flight")
        _start(a, button_a, 1 << 20, "a-third.csv")  # per tab: at most two
        per_tab = say(Lang.EN, "at most {count} uploads at a time", count=transport.MAX_UPLOADS)
        wait_for(lambda: ("Upload refused", per_tab) in a.notes, what="the per-tab refusal")

        b, _view_b, button_b = tab("127.0.0.5")  # the same address: 2 MiB held, 3 MiB allowed
        _start(b, button_b, 1 << 20, "b0.csv")
        wait_for(lambda: budget.held("127.0.0.5") == 3 << 20, what="three uploads of one address in flight")
        _start(b, button_b, 1 << 20, "b1.csv")
        wait_for(lambda: ("Upload refused", str(BUSY_ADDRESS)) in b.notes, what="the per-address refusal")

        c, _view_c, button_c = tab("127.0.0.6")  # another address: 3 MiB held in all, 5 MiB allowed
        _start(c, button_c, 1 << 20, "c0.csv")
        _start(c, button_c, 1 << 20, "c1.csv")
        wait_for(lambda: budget.held() == 5 << 20, what="five uploads in flight in all")
        d, view_d, button_d = tab("127.0.0.7")
        _start(d, button_d, 1 << 20, "d0.csv")
        wait_for(lambda: ("Upload refused", str(BUSY_SERVER)) in d.notes, what="the server's refusal")
        assert [n for n in a.notes + b.notes + c.notes + d.notes if n[0] == "Upload refused"] == [
            ("Upload refused", per_tab),
            ("Upload refused", str(BUSY_ADDRESS)),
            ("Upload refused", str(BUSY_SERVER)),
        ]  # one line each, nothing else refused

        a.close()  # a tab that leaves gives its bytes back at once (not after the 30 s of its timers)
        wait_for(lambda: budget.held("127.0.0.5") == 1 << 20, what="the first tab's bytes given back")
        for message in upload_messages(button_d, CSV, "whole.csv"):  # room again: a whole upload goes through
            d.send(**message)
        upload = view_d.teaching.player.upload
        wait_for(lambda: getattr(upload.value, "name", "") == "whole.csv", what="the whole upload taken")
        assert budget.held() == 3 << 20  # its bytes given back when it ended: b's one and c's two still in flight
        wait_for(lambda: view_a.closed, what="the first tab gone")
    finally:
        for client in opened:
            client.close()
