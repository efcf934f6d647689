"""Abuse (issue 12): what one hostile or broken tab costs the server and the other tabs (loopback only).

Each scenario starts a fresh server (``python app.py --port 0``, :class:`~tests.support.protocol.ServerProcess`,
stopped by its own pid) and protocol-level tabs (:class:`~tests.support.protocol.Tab`):

- **export flood**: one tab loads the paper's line, then clicks *Download the force plot (PNG)* 100 times and
  *Download the run (CSV)* 3 000 times as fast as it can, while 3 other tabs (own copies) drag at 20 Hz: their
  latency (drag sent -> platform update received; median, p95, max) and the server's CPU time during the flood;
- **non-reading tab**: a tab clicks *Download the run (CSV)* 200 times a second and has stopped reading: server
  memory before / peak / after, and when the server dropped it;
- **unfinished uploads**: one tab starts 1 000 uploads (one 512 KiB part each, never finished), then closes:
  memory before / peak / after;
- **big frames**: 10 clients each send 3 frames of 50 MiB (one connection per frame) while a tab drags: memory
  before / peak / after, the dragging tab's p95;
- **big maps**: a script sends 150 msgpack maps of 15 000 keys (each just under 64 KiB) in 3 s, then one of 10^6
  keys, while a tab drags: the dragging tab's latency (viser decodes every map on the event loop);
- **bad tab**: a tab sends malformed gizmo messages, wrong-kind GUI updates and wrong presenter tokens as fast as
  it can for 5 s: server log lines per second.

Run: ``python benchmarks/bench_abuse.py [scenario ...]`` (about 2 minutes for all six). Bounded: every loop has
a count and a time limit.
"""

from __future__ import annotations

import asyncio
import contextlib
import multiprocessing
import os
import sys
import time
import uuid
from pathlib import Path

import msgspec
import numpy as np
import viser
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from tests.support.protocol import ServerProcess, Tab

TOKEN = "bench-presenter-token"
CSV, PNG, CHOICE = "Download the run (CSV)", "Download the force plot (PNG)", "Trajectory"
UPLOAD = "Upload CSV (t, p1, p2 in s, m)"
SUBPROTOCOL = f"viser-v{viser.__version__}"


def _stats(values: list[float]) -> str:
    if len(values) < 2:
        return f"n={len(values)}"
    ms = np.array(values) * 1e3
    return f"median {np.median(ms):.1f} ms, p95 {np.percentile(ms, 95):.1f} ms, max {ms.max():.0f} ms (n={len(ms)})"


async def _drag(tab: Tab, seconds: float, rate: float = 20.0, index: int = 0) -> None:
    await tab.drag(0, 0, "start")
    start, k = time.perf_counter(), 0
    while time.perf_counter() - start < seconds and k < seconds * rate + 10:
        angle = 2 * np.pi * 0.25 * (time.perf_counter() - start) + 1e-4 * k + index
        await tab.drag(0.03 * np.cos(angle), 0.03 * np.sin(angle))
        k += 1
        await asyncio.sleep(max(0.0, start + k / rate - time.perf_counter()))
    await tab.drag(0, 0, "end")


class Sampler:
    """Server memory every 0.1 s (peak)."""

    def __init__(self, server: ServerProcess) -> None:
        self.server, self.peak, self._task = server, server.rss_mb(), None

    async def _run(self) -> None:
        while True:
            with contextlib.suppress(FileNotFoundError, ValueError):
                self.peak = max(self.peak, self.server.rss_mb())
            await asyncio.sleep(0.1)

    def __enter__(self) -> Sampler:
        self._task = asyncio.get_running_loop().create_task(self._run())
        return self

    def __exit__(self, *exc) -> None:
        self._task.cancel()


async def _open(port: int, n: int, own_copy: bool = True) -> list[Tab]:
    tabs = [Tab(port, f"tab{k}") for k in range(n)]
    for tab in tabs:
        await tab.open()
        if own_copy:
            await tab.set_value("Work on my own copy", True)
    await asyncio.sleep(1.0)  # the copies are made before anything else is chosen
    return tabs


async def export_flood(server: ServerProcess) -> None:
    flooder, *others = await _open(server.port, 4)
    await flooder.set_value(CHOICE, "line (Fig. 4)")
    await asyncio.sleep(1.5)
    for tab in others:
        tab.latencies.clear()
    cpu0 = server.cpu_seconds()

    async def flood() -> None:
        for _ in range(100):
            await flooder.set_value(PNG, True)
        for _ in range(3000):
            await flooder.set_value(CSV, True)

    t0 = time.perf_counter()
    await asyncio.gather(flood(), *(_drag(t, 8.0, index=k) for k, t in enumerate(others)))
    flood_cpu = server.cpu_seconds() - cpu0
    latencies = [x for t in others for x in t.latencies]
    print(f"export flood (100 PNG + 3 000 CSV clicks in {time.perf_counter() - t0:.1f} s of dragging):")
    print(f"  other tabs' drag latency: {_stats(latencies)}")
    print(f"  server CPU during the 8 s: {flood_cpu:.1f} s")
    for tab in (flooder, *others):
        await tab.close()


async def non_reading(server: ServerProcess) -> None:
    (other,) = await _open(server.port, 1)
    tab = (await _open(server.port, 1))[0]
    await tab.set_value(CHOICE, "line (Fig. 4)")
    await asyncio.sleep(1.5)
    tab._reader.cancel()  # the tab stops reading; the client library stops reading its socket after 16 frames
    before = server.rss_mb()
    t0, dropped = time.perf_counter(), None
    with Sampler(server) as sampler:
        for _ in range(6000):  # up to 30 s at 200 clicks a second
            try:
                await tab.set_value(CSV, True)
            except ConnectionClosed:
                dropped = time.perf_counter() - t0
                break
            await asyncio.sleep(0.005)
            if time.perf_counter() - t0 > 30:
                break
        await asyncio.sleep(3.0)
        after = server.rss_mb()
    when = f"dropped after {dropped:.1f} s" if dropped is not None else "NOT dropped within 30 s"
    print(f"non-reading tab clicking CSV: memory {before:.0f} -> peak {sampler.peak:.0f} -> {after:.0f} MB ({when})")
    await other.close()


async def unfinished_uploads(server: ServerProcess) -> None:
    (tab,) = await _open(server.port, 1, own_copy=False)
    button = tab.uuids[UPLOAD]
    part = os.urandom(512 << 10)
    before = server.rss_mb()
    with Sampler(server) as sampler:
        t0 = time.perf_counter()
        for _ in range(1000):
            head = {"source_component_uuid": button, "transfer_uuid": str(uuid.uuid4())}
            await tab.send(
                type="FileTransferStartUpload", **head, filename="a.csv", mime_type="", part_count=2, size_bytes=1 << 20
            )
            await tab.send(type="FileTransferPart", **head, part_index=0, content=part)
        sent = time.perf_counter() - t0
        await asyncio.sleep(1.0)
        await tab.close()
        await asyncio.sleep(3.0)
        after = server.rss_mb()
    print(
        f"1 000 unfinished uploads ({sent:.1f} s): memory {before:.0f} -> peak {sampler.peak:.0f} -> {after:.0f} MB "
        "(after the tab closed)"
    )


async def _send_big_frames(port: int, clients: int, frames: int, size: int) -> list:
    """``clients`` scripts, each sending ``frames`` frames of ``size`` bytes, one connection per frame (no camera: a
    script, not a browser); returns the close codes the server sent."""
    frame = os.urandom(size)
    codes: list = []

    async def client() -> None:
        for _ in range(frames):
            ws = await connect(f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL], max_size=None, compression=None)
            with contextlib.suppress(ConnectionClosed):
                await ws.send(frame)
                await asyncio.wait_for(ws.recv(), 10.0)  # the server closes the connection (1009)
            codes.append(ws.close_code)
            if ws.close_code is None:
                await ws.close()

    await asyncio.gather(*(client() for _ in range(clients)))
    return codes


def _big_frames_process(port: int, out) -> None:
    out.put(asyncio.run(_send_big_frames(port, 10, 3, 50 << 20)))


async def big_frames(server: ServerProcess) -> None:
    (dragger,) = await _open(server.port, 1)
    before = server.rss_mb()
    queue: multiprocessing.Queue = multiprocessing.Queue()
    sender = multiprocessing.Process(target=_big_frames_process, args=(server.port, queue))  # its own CPU
    with Sampler(server) as sampler:
        dragger.latencies.clear()
        sender.start()
        await _drag(dragger, 6.0)
        await asyncio.get_running_loop().run_in_executor(None, sender.join, 60.0)
        await asyncio.sleep(3.0)
        after = server.rss_mb()
    codes = sorted(set(queue.get(timeout=5.0))) if not queue.empty() else "?"
    print(
        f"10 clients x 3 frames of 50 MiB (closed with {codes}): memory {before:.0f} -> peak {sampler.peak:.0f} -> "
        f"{after:.0f} MB; a dragging tab meanwhile: {_stats(dragger.latencies)}"
    )
    await dragger.close()


async def big_maps(server: ServerProcess) -> None:
    (dragger,) = await _open(server.port, 1)
    entries = {i: 0 for i in range(15_000)}  # ~60 KiB of msgpack: under the 64 KiB "not an upload part" limit
    small = msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": "x", "updates": entries})
    big = msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": "x", "updates": {i: 0 for i in range(10**6)}})
    ws = await connect(f"ws://127.0.0.1:{server.port}", subprotocols=[SUBPROTOCOL], max_size=None, compression=None)
    dragger.latencies.clear()

    async def flood() -> None:
        for _ in range(150):  # 150 maps of 15 000 keys in ~3 s
            await ws.send(small)
            await asyncio.sleep(0.02)
        with contextlib.suppress(ConnectionClosed):
            await ws.send(big)  # 10^6 keys (~3 MiB): over the frame limit
            await asyncio.wait_for(ws.recv(), 10.0)

    await asyncio.gather(_drag(dragger, 4.0), flood())
    print(
        f"maps: 150 x 15 000 keys ({len(small) >> 10} KiB) then one of 10^6 keys ({len(big) >> 20} MiB, closed with "
        f"{ws.close_code}); a dragging tab meanwhile: {_stats(dragger.latencies)}"
    )
    await dragger.close()


async def bad_tab(server: ServerProcess) -> None:
    (tab,) = await _open(server.port, 1, own_copy=False)
    log = Path(server.log.name)
    lines0 = len(log.read_text(errors="replace").splitlines())
    t0, sent = time.perf_counter(), 0
    while time.perf_counter() - t0 < 5.0 and sent < 200_000:
        await tab.send(
            type="TransformControlsUpdateMessage", name="/gizmo", wxyz=(1, 0, 0, 0), position=(0, 0), owner=""
        )
        await tab.send(type="TransformControlsUpdateMessage", name=3, wxyz="x", position="abc", owner=tab.owner)
        await tab.set_value("Load", "not an option")
        await tab.set_value("Presenter token", "guess")
        await tab.set_value("Log in as presenter", True)
        sent += 5
        if sent % 500 == 0:
            await asyncio.sleep(0)
    await asyncio.sleep(1.0)
    wall = time.perf_counter() - t0
    text = log.read_text(errors="replace").splitlines()[lines0:]
    tracebacks = sum("Traceback" in line or "never retrieved" in line for line in text)
    print(
        f"bad tab: {sent} bad messages in 5 s -> {len(text)} log lines ({len(text) / wall:.1f}/s), "
        f"{tracebacks} tracebacks"
    )
    await tab.close()


async def main(only: list[str]) -> None:
    for scenario, token in (
        (export_flood, None),
        (non_reading, None),
        (unfinished_uploads, None),
        (big_frames, None),
        (big_maps, None),
        (bad_tab, TOKEN),
    ):
        if only and scenario.__name__ not in only:
            continue
        server = ServerProcess(presenter_token=token)
        try:
            await asyncio.sleep(1.0)
            await scenario(server)
            problems = [line for line in server.log_problems() if "Traceback" in line]
            if problems:
                print(f"  server log: {len(problems)} tracebacks")
        finally:
            server.stop()


if __name__ == "__main__":
    asyncio.run(main(sys.argv[1:]))  # optional: names of the scenarios to run
