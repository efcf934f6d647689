"""Soak, long (by hand): thousands of tabs connect, drag and disconnect against the app in a child process.

``python app.py --port 0`` on 127.0.0.1 and batches of ``--batch`` concurrent protocol-level tabs
(``benchmarks/wsclient.py``): each connects, optionally takes its own copy, drags the platform for ``--drags``
updates at 20 Hz, and leaves (every third one mid-drag, every other one without a closing handshake). The server's
resident memory (``/proc/<pid>/status``) is printed every ``--every`` tabs; reported at the end: memory after the
warm-up and at the end (growth; target < 20 MB), server CPU, tabs per second, and the server log lines that
report an exception (target: none).

Run: ``python benchmarks/bench_soak.py`` (3 000 tabs, ~6 minutes); ``--tabs 600`` for a shorter run. Bounded: at
most ``--tabs`` tabs and ``--max-seconds`` seconds; the server stops by itself (its own pid).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import math
import socket
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from tests.support.protocol import ServerProcess, Tab

WARM_UP = 200  # tabs before the reference memory reading


async def _one_tab(port: int, k: int, drags: int) -> None:
    tab = Tab(port, f"soak{k}")
    try:
        await tab.open(timeout=60)
        if k % 2:
            await tab.set_value("Work on my own copy", True)
        await tab.drag(0, 0, "start")
        for i in range(drags):
            angle = 0.3 * i + k
            await tab.drag(0.04 * math.cos(angle), 0.04 * math.sin(angle))
            await asyncio.sleep(0.05)
        if k % 3:
            await tab.drag(0, 0, "end")
        if k % 2 == 0:  # gone without a closing handshake
            transport = tab.ws.transport
            with contextlib.suppress(OSError):
                transport.get_extra_info("socket").shutdown(socket.SHUT_RDWR)
            transport.abort()
    finally:
        with contextlib.suppress(Exception):
            await asyncio.wait_for(tab.close(), 5)


async def _soak(server: ServerProcess, tabs: int, batch: int, drags: int, every: int, max_seconds: float) -> dict:
    start, done, samples = time.monotonic(), 0, []
    cpu0 = server.cpu_seconds()
    warm = None
    while done < tabs and time.monotonic() - start < max_seconds:
        await asyncio.gather(*(_one_tab(server.port, done + j, drags) for j in range(batch)))
        done += batch
        if warm is None and done >= WARM_UP:
            await asyncio.sleep(1.0)
            warm = server.rss_mb()
            print(f"  after {done:5d} tabs (warm-up): RSS {warm:6.1f} MB", flush=True)
        elif done % every < batch:
            rss = server.rss_mb()
            samples.append((done, rss))
            print(f"  after {done:5d} tabs: RSS {rss:6.1f} MB", flush=True)
    await asyncio.sleep(2.0)  # departures processed
    wall = time.monotonic() - start
    return {
        "tabs": done,
        "wall": wall,
        "cpu": (server.cpu_seconds() - cpu0) / wall,
        "warm": warm,
        "end": server.rss_mb(),
        "samples": samples,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tabs", type=int, default=3000, help="tabs in total (max 20 000)")
    parser.add_argument("--batch", type=int, default=6, help="concurrent tabs per batch (max 40)")
    parser.add_argument("--drags", type=int, default=10, help="drag updates per tab, at 20 Hz")
    parser.add_argument("--every", type=int, default=300, help="print the memory every this many tabs")
    parser.add_argument("--max-seconds", type=float, default=1800.0, help="stop after this long (max 7200)")
    args = parser.parse_args()
    tabs = max(WARM_UP + args.batch, min(args.tabs, 20_000))
    batch = max(1, min(args.batch, 40))
    print(f"Soak: {tabs} tabs in batches of {batch}, {args.drags} drag updates each (server in a child process)")
    server = ServerProcess()
    try:
        r = asyncio.run(_soak(server, tabs, batch, args.drags, args.every, min(args.max_seconds, 7200.0)))
    finally:
        server.stop()
    problems = server.log_problems()
    print(
        f"{r['tabs']} tabs in {r['wall']:.0f} s ({r['tabs'] / r['wall']:.1f} tabs/s), server CPU {100 * r['cpu']:.0f} %"
    )
    if r["warm"] is not None:
        print(
            f"RSS after warm-up {r['warm']:.1f} MB, at the end {r['end']:.1f} MB: growth {r['end'] - r['warm']:+.1f} MB"
            " (target < 20 MB)"
        )
    print(f"server log: {len(problems)} line(s) reporting an exception")
    for line in problems[:10]:
        print(f"    {line}")


if __name__ == "__main__":
    main()
