"""Upload flood (issue 35, by hand): browsers from many addresses each upload a 540 kB CSV to their own copy and leave
1.5 s later; the server's resident memory before, at its peak and once every tab has left.

A fresh server (``python app.py --port 0``, :class:`~tests.support.protocol.ServerProcess`, stopped by its own pid,
or the ``app.py`` of ``--root``: another checkout, to measure the code before a change). Each browser is a
protocol-level tab (:class:`tests.support.upload_flood.FloodTab`): it gets its cookie from ``GET /`` and opens its
websocket from its own loopback address (``127.0.0.2`` ... ``127.0.0.<addresses + 1>``), ticks *Work on my own
copy*, uploads a 20,000-row CSV (t, p1, p2; 540 kB, the largest the app takes) to the Player in 512 KiB parts, and
closes 1.5 s after the last part. ``--batch`` browsers at once. Printed: the baseline (after one browser in and
out), the peak, the memory each ``--every`` s until it has not moved for 20 s (at most ``--settle`` s), what was
retained per browser, and the uploads the server refused (one line each to the tab: the caps of
``tpm_viz.viserkit.uploads``).

Run: ``python benchmarks/bench_upload_flood.py`` (275 browsers from 250 addresses, ~2 minutes); ``--tabs 60
--addresses 6`` for the test's size. Bounded: ``--tabs`` browsers, ``--settle`` seconds.
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from tests.support.protocol import ServerProcess
from tests.support.upload_flood import flood, one_browser


async def main(args: argparse.Namespace) -> None:
    server = ServerProcess(root=Path(args.root) if args.root else None)
    try:
        await asyncio.sleep(1.0)
        await one_browser(server.port, "127.0.0.2", 0)  # the baseline is a server that has served a browser
        await asyncio.sleep(3.0)
        baseline = server.rss_mb()
        print(f"server {server.pid} ({args.root or 'this checkout'}): baseline {baseline:.0f} MB", flush=True)
        t0 = time.monotonic()
        result = await flood(server, args.tabs, args.addresses, args.batch)
        print(
            f"{args.tabs} browsers from {args.addresses} addresses in {time.monotonic() - t0:.0f} s: peak "
            f"{result.peak:.0f} MB; {result.refused} uploads refused (one line each), {len(result.errors)} failed "
            f"browsers {result.errors[:2]}",
            flush=True,
        )
        samples: list[float] = []
        start = time.monotonic()
        while time.monotonic() - start < args.settle:
            await asyncio.sleep(args.every)
            samples.append(server.rss_mb())
            print(f"  +{time.monotonic() - start:.0f} s: {samples[-1]:.0f} MB", flush=True)
            steady = int(20 / args.every)
            if len(samples) > steady and max(samples[-steady:]) - min(samples[-steady:]) < 2.0:
                break
        after = samples[-1] if samples else server.rss_mb()
        print(
            f"memory {baseline:.0f} -> peak {result.peak:.0f} -> {after:.0f} MB after every browser left "
            f"({after - baseline:+.0f} MB, {(after - baseline) / args.tabs * 1024:.0f} kB per browser)"
        )
        problems = [line for line in server.log_problems() if "Traceback" in line]
        if problems:
            print(f"  server log: {len(problems)} tracebacks")
    finally:
        server.stop()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tabs", type=int, default=275)
    parser.add_argument("--addresses", type=int, default=250)
    parser.add_argument("--batch", type=int, default=25)
    parser.add_argument("--every", type=float, default=5.0)
    parser.add_argument("--settle", type=float, default=120.0)
    parser.add_argument("--root", default="", help="run the app.py of this checkout (default: this one)")
    asyncio.run(main(parser.parse_args()))
