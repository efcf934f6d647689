"""A reconnect storm: N browser tabs on their own copies drop at once and come back at once (the wifi blip of a
lecture hall). Shared by tests/e2e/test_store_faults.py and benchmarks/bench_reconnect.py.

Each :class:`StormTab` gets its cookie the way a browser does (``GET /``: the page response's ``Set-Cookie``), then
opens the websocket with that cookie and an ``Origin``; it knows it has its own copy when the server says the
*Work on my own copy* box is ticked (the widget's value as sent, or an update of it).
"""

from __future__ import annotations

import asyncio
import http.client
import time

import msgspec
import viser
from websockets.asyncio.client import connect

from tests.support.protocol import CAMERA, decode_batch

__all__ = ["OWN", "StormTab", "page_cookie", "storm"]

OWN = "Work on my own copy"


def page_cookie(port: int, host: str = "127.0.0.1") -> str:
    """The ``name=value`` of the cookie the page response sets (what a browser keeps and sends back)."""
    conn = http.client.HTTPConnection(host, port, timeout=30)
    try:
        conn.request("GET", "/", headers={"Host": f"{host}:{port}"})
        response = conn.getresponse()
        response.read()
        header = response.getheader("Set-Cookie") or ""
    finally:
        conn.close()
    if "=" not in header:
        raise AssertionError(f"the page set no cookie (HTTP {response.status})")
    return header.split(";", 1)[0].strip()


class StormTab:
    """One tab of one browser (its cookie), without a browser."""

    def __init__(self, port: int, cookie: str) -> None:
        self.port, self.cookie = port, cookie
        self.own_uuid: str | None = None
        self.own = asyncio.Event()
        self.drawn = asyncio.Event()  # after the tick: a node of the own copy's scene arrived
        self._ticked = False
        self.ws = None
        self._reader: asyncio.Task | None = None

    async def open(self, timeout: float = 60.0) -> None:
        self.own.clear()
        self.own_uuid = None
        self.ws = await connect(
            f"ws://127.0.0.1:{self.port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            compression=None,
            open_timeout=timeout,
            origin=f"http://127.0.0.1:{self.port}",
            additional_headers={"Cookie": self.cookie},
        )
        self._reader = asyncio.create_task(self._read())
        await self.ws.send(msgspec.msgpack.encode(CAMERA))

    async def _read(self) -> None:
        try:
            async for raw in self.ws:
                for m in decode_batch(raw):
                    if self._ticked and str(m.get("name", "")).startswith("/own"):
                        self.drawn.set()
                    props = m.get("props")
                    if m["type"].startswith("Gui") and isinstance(props, dict) and props.get("label") == OWN:
                        self.own_uuid = m["uuid"]
                        if m.get("value") is True:
                            self.own.set()
                    elif m["type"] == "GuiUpdateMessage" and m.get("uuid") == self.own_uuid:
                        if m.get("updates", {}).get("value") is True:
                            self.own.set()
        except Exception:  # connection closed
            return

    async def tick_own_copy(self, timeout: float = 60.0) -> None:
        deadline = time.monotonic() + timeout
        while self.own_uuid is None and time.monotonic() < deadline:
            await asyncio.sleep(0.02)
        assert self.own_uuid is not None, "the own-copy box never arrived"
        self._ticked = True
        message = {"type": "GuiUpdateMessage", "uuid": self.own_uuid, "updates": {"value": True}}
        await self.ws.send(msgspec.msgpack.encode(message))
        await asyncio.wait_for(self.drawn.wait(), timeout)
        self._ticked = False

    async def close(self) -> None:
        if self.ws is not None:
            await self.ws.close()
        if self._reader is not None:
            await asyncio.wait([self._reader], timeout=5.0)


async def storm(port: int, n: int, settle, timeout: float = 120.0) -> list[float | None]:
    """``n`` tabs (one browser each) tick their own copy, all drop, ``settle()`` (awaited: e.g. until the server
    parked them), all reconnect at once; returns each tab's seconds from the reconnect to its copy back (None: not
    back within ``timeout``)."""
    tabs = [StormTab(port, page_cookie(port)) for _ in range(n)]
    for k in range(0, n, 10):  # a class arriving, ten at a time
        batch = tabs[k : k + 10]
        await asyncio.gather(*(t.open() for t in batch))
        await asyncio.gather(*(t.tick_own_copy() for t in batch))
    await asyncio.gather(*(t.close() for t in tabs))
    await settle()
    start = time.perf_counter()
    await asyncio.gather(*(t.open() for t in tabs))

    async def back(tab: StormTab) -> float | None:
        try:
            await asyncio.wait_for(tab.own.wait(), max(1.0, timeout - (time.perf_counter() - start)))
        except TimeoutError:
            return None
        return time.perf_counter() - start

    times = await asyncio.gather(*(back(t) for t in tabs))
    await asyncio.gather(*(t.close() for t in tabs))
    return list(times)
