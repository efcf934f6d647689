"""Browsers that upload a large CSV to their own copy and leave (issue 35): for ``tests/viserkit/test_upload_flood.py``
and ``benchmarks/bench_upload_flood.py``.

A browser (:func:`one_browser`) gets its cookie from ``GET /`` and opens its websocket from its own loopback address,
as a browser of another machine would; ticks *Work on my own copy*; uploads :data:`CSV` (20,000 rows of ``t, p1,
p2``, the largest the app takes: ~540 kB) to the Player's upload button in viser's 512 KiB parts; and closes
``linger`` seconds after the last part. It reports whether the server refused the upload (the red notification
"Upload refused": the caps of ``tpm_viz.viserkit.uploads``).
"""

from __future__ import annotations

import asyncio
import dataclasses
import http.client
import math
import socket
import uuid

import msgspec
import viser
from websockets.asyncio.client import connect

from tests.support.protocol import CAMERA, decode_batch

__all__ = ["CSV", "OWN", "PART", "UPLOAD", "Flood", "flood", "one_browser", "upload_messages"]

UPLOAD = "Upload CSV (t, p1, p2 in s, m)"
OWN = "Work on my own copy"
PART = 512 * 1024
"""viser's upload part [bytes]."""


def _csv(rows: int = 20_000) -> bytes:
    """A slow circle of radius 20 mm about the origin, 1 ms apart (inside the paper's workspace)."""
    lines = ["t,p1,p2"] + [
        f"{i * 1e-3:.3f},{0.02 * math.cos(i * 1e-3):.6f},{0.02 * math.sin(i * 1e-3):.6f}" for i in range(rows)
    ]
    return ("\n".join(lines) + "\n").encode()


CSV = _csv()


def upload_messages(button: str, data: bytes, name: str, transfer: str | None = None) -> list[dict]:
    """What a browser sends to upload ``data`` as ``name`` with the upload button ``button``."""
    transfer = transfer or str(uuid.uuid4())
    head = {"source_component_uuid": button, "transfer_uuid": transfer}
    parts = [data[i : i + PART] for i in range(0, len(data), PART)]
    start = {"type": "FileTransferStartUpload", **head, "filename": name, "mime_type": "text/csv"}
    messages = [dict(start, part_count=len(parts), size_bytes=len(data))]
    messages += [{"type": "FileTransferPart", **head, "part_index": i, "content": p} for i, p in enumerate(parts)]
    return messages


def _cookie(port: int, source: str) -> str:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60, source_address=(source, 0))
    try:
        conn.request("GET", "/")
        response = conn.getresponse()
        response.read()
        return (response.getheader("Set-Cookie") or "").split(";", 1)[0]
    finally:
        conn.close()


async def one_browser(port: int, source: str, k: int, linger: float = 1.5, timeout: float = 120.0) -> bool:
    """One browser from ``source`` (see the module docstring). -> whether its upload was refused."""
    cookie = await asyncio.to_thread(_cookie, port, source)
    sock = socket.create_connection(("127.0.0.1", port), timeout, (source, 0))
    ws = await connect(
        f"ws://127.0.0.1:{port}",
        subprotocols=[f"viser-v{viser.__version__}"],
        max_size=None,
        compression=None,
        origin=f"http://127.0.0.1:{port}",
        additional_headers={"Cookie": cookie} if cookie else None,
        sock=sock,
        open_timeout=timeout,
    )
    uuids: dict[str, str] = {}
    ready, refused = asyncio.Event(), asyncio.Event()

    async def read() -> None:
        try:
            async for raw in ws:
                for m in decode_batch(raw):
                    props = m.get("props")
                    if not isinstance(props, dict):
                        continue
                    if m["type"].startswith("Gui") and props.get("label"):
                        uuids.setdefault(props["label"], m["uuid"])
                        if UPLOAD in uuids and OWN in uuids:
                            ready.set()
                    elif m["type"] == "NotificationShowMessage" and props.get("title") == "Upload refused":
                        refused.set()
        except Exception:  # the connection closed
            return

    reader = asyncio.create_task(read())
    try:
        await ws.send(msgspec.msgpack.encode(CAMERA))
        await asyncio.wait_for(ready.wait(), timeout)
        tick = {"type": "GuiUpdateMessage", "uuid": uuids[OWN], "updates": {"value": True}}
        await ws.send(msgspec.msgpack.encode(tick))
        for message in upload_messages(uuids[UPLOAD], CSV, f"flood{k}.csv"):
            await ws.send(msgspec.msgpack.encode(message))
        await asyncio.sleep(linger)
    finally:
        await ws.close()
        await asyncio.wait([reader], timeout=5.0)
    return refused.is_set()


@dataclasses.dataclass
class Flood:
    """What a flood saw: the server's peak memory [MB], uploads refused, browsers that failed."""

    peak: float
    refused: int
    errors: list[str]


async def flood(server, tabs: int, addresses: int, batch: int) -> Flood:
    """``tabs`` browsers from ``addresses`` loopback addresses (``127.0.0.2`` up), ``batch`` at a time, on
    ``server`` (a :class:`~tests.support.protocol.ServerProcess`)."""
    peak, refused, errors = server.rss_mb(), 0, []
    for start in range(0, tabs, batch):
        ks = range(start, min(tabs, start + batch))
        results = await asyncio.gather(
            *(one_browser(server.port, f"127.0.0.{2 + k % addresses}", k) for k in ks), return_exceptions=True
        )
        peak = max(peak, server.rss_mb())
        refused += sum(r is True for r in results)
        errors += [f"{type(r).__name__}: {r}" for r in results if isinstance(r, BaseException)]
    return Flood(peak, refused, errors)
