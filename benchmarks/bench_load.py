"""Load: N protocol-level tabs dragging the platform at 20 Hz against the app in a child process (loopback only).

For each N (default 1, 10, 30) a fresh server (``python app.py --port 0``) and N asyncio tabs
(``benchmarks/wsclient.py``); each tab drags its gizmo around its own small circle at ``--rate`` Hz for
``--seconds`` seconds, with a random phase. Reported per N:

- server CPU: user + system time of the server process over the drag window / wall time (100 % = one core);
- latency: a drag update sent -> the platform update with that position received by the same tab (median, p95);
  updates that the server merged into a later one (latest value wins) have no latency and count as "merged";
- the server log: lines reporting an exception (should be none);
- the CPU of this benchmark's own process and of any other process (the machine has 2 cores: a busy neighbour,
  e.g. a test run, skews the latencies; rerun on a quiet machine), and the CPU time the virtual machine's host
  stole (it runs other machines on our cores: a run with much of it measured the host);
- hall: of the watchers' and the own copies' latencies, the part in the server (the input sent -> the server
  encoded the frame carrying the update, from the frame's own timestamp; the rest is sending and the tab).

Scenarios (``--mode``): ``private`` (default: every tab on its own copy, a class working on its own),
``presenter`` (presenter mode: one presenter drags the shared mechanism, N-1 tabs watch; the watchers'
latency is the presenter's send -> the update reaching them) and ``shared`` (no token, everybody drags the one
shared mechanism at once: the worst case) and ``hall`` (a lecture hall: ``--hall`` tabs, default 150, watch while
the presenter drags the shared mechanism at 20 Hz, and ``--own`` of them, default 30, drag their own copies at the
same time; reported: the presenter's input -> the watchers' scene update (target p95 <= 100 ms) and each own-copy
tab's p95 (target: none over 150 ms)).

Run: ``python benchmarks/bench_load.py`` (about a minute); ``--quick`` for 4 s per N; ``--root DIR`` serves another
checkout (before/after a change: ``git worktree add DIR COMMIT``). Target: p95 < 50 ms at N = 30
(every mode). Bounded: every loop has a count and a time limit; the servers stop by themselves (their own pid).
"""

from __future__ import annotations

import argparse
import asyncio
import math
import random
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from tests.support.protocol import ServerProcess, Tab, machine_busy_seconds, stolen_seconds

TOKEN = "bench-presenter-token"
_HALL_OWN = [30]  # --own (set by main)
_PROFILE: list[Path] = []  # --profile FILE (set by main)


async def _drag_loop(tab: Tab, seconds: float, rate: float, index: int, rng: random.Random) -> int:
    """Drag around a 40 mm circle (centre offset per tab) at ``rate`` Hz for ``seconds``; returns sends."""
    cx, cy = 0.02 * math.cos(index), 0.02 * math.sin(index)
    phase = rng.uniform(0, 2 * math.pi)
    await asyncio.sleep(rng.uniform(0, 1.0 / rate))
    await tab.drag(0, 0, "start")
    start, sends = time.perf_counter(), 0
    while (now := time.perf_counter()) - start < seconds and sends < seconds * rate + 10:
        angle = phase + 2 * math.pi * 0.25 * (now - start) + 1e-4 * sends  # distinct targets
        await tab.drag(cx + 0.04 * math.cos(angle), cy + 0.04 * math.sin(angle))
        sends += 1
        await asyncio.sleep(max(0.0, start + sends / rate - time.perf_counter()))
    await tab.drag(0, 0, "end")
    return sends


OPEN_SECONDS = 2.0
"""Time allowed per tab to open [s] (150 tabs on a busy 2-core machine take minutes), on top of the drag window."""


async def _scenario(server: ServerProcess, n: int, mode: str, seconds: float, rate: float, progress: dict) -> dict:
    tabs = [Tab(server.port, f"tab{k}") for k in range(n)]
    for tab in tabs:  # one at a time, like a class arriving
        await tab.open()
        progress["opened"] += 1
    progress["step"] = "joining and logging in"
    if mode == "private":
        for tab in tabs:
            await tab.set_value("Work on my own copy", True)
    draggers = tabs
    if mode in ("hall", "presenter"):  # a busy server sends the login's widgets late: waited for, not assumed
        await _widget(tabs[0], "Presenter token")
    if mode == "hall":
        await tabs[0].set_value("Presenter token", TOKEN)
        await tabs[0].set_value("Log in as presenter", True)
        own = tabs[1 : 1 + _HALL_OWN[0]]
        for tab in own:
            await tab.set_value("Work on my own copy", True)
        draggers = tabs[:1] + own
        for tab in tabs[1 + len(own) :]:
            tab.watch = tabs[0].log
    if mode == "presenter":
        await tabs[0].set_value("Presenter token", TOKEN)
        await tabs[0].set_value("Log in as presenter", True)
        draggers = tabs[:1]
        for tab in tabs[1:]:
            tab.watch = tabs[0].log
    await asyncio.sleep(1.0)  # joins, copies and login settle before measuring
    await _quiet(server)
    for tab in tabs:
        tab.latencies.clear()
        tab.in_server.clear()
    progress["step"] = "dragging"
    rng = random.Random(0)
    profiler = _start_profile(server.pid, seconds)
    cpu0, t0, own0, all0 = server.cpu_seconds(), time.perf_counter(), time.process_time(), machine_busy_seconds()
    stolen0 = stolen_seconds()
    sends = await asyncio.gather(*(_drag_loop(t, seconds, rate, k, rng) for k, t in enumerate(draggers)))
    if profiler is not None:
        await asyncio.to_thread(profiler.wait, 30)
    await asyncio.sleep(0.5)  # the last updates arrive
    wall, cpu, own_cpu = time.perf_counter() - t0, server.cpu_seconds() - cpu0, time.process_time() - own0
    others = max(0.0, machine_busy_seconds() - all0 - cpu - own_cpu)
    stolen = stolen_seconds() - stolen0
    own = [x for t in draggers for x in t.latencies]
    watched = [x for t in tabs[1:] for x in t.latencies] if mode == "presenter" else []
    per_tab = []
    split: dict[str, list[float]] = {}  # of the latencies: send -> the server encoded the frame
    if mode == "hall":
        own = list(tabs[0].latencies)  # the presenter's own drag
        watched = [x for t in tabs[len(draggers) :] for x in t.latencies]
        per_tab = [np.percentile(t.latencies, 95) * 1e3 for t in draggers[1:] if t.latencies]
        split["watchers"] = [x for t in tabs[len(draggers) :] for x in t.in_server]
        split["own copies"] = [x for t in draggers[1:] for x in t.in_server]
    for tab in tabs:
        await tab.close()
    return {
        "n": n,
        "sends": sends[0] if mode == "hall" else sum(sends),  # hall: the presenter's (the latency line)
        "cpu": cpu / wall,
        "client_cpu": own_cpu / wall,
        "others": others / wall,
        "stolen": stolen / wall,
        "own": np.array(own) * 1e3,
        "watched": np.array(watched) * 1e3,
        "rss": server.rss_mb(),
        "per_tab": per_tab,
        "split": {k: np.array(v) * 1e3 for k, v in split.items() if v},
    }


async def _widget(tab: Tab, label: str, limit: float = 60.0) -> None:
    """Wait (at most ``limit`` s) until ``tab`` was sent the widget labelled ``label``."""
    deadline = time.monotonic() + limit
    while label not in tab.uuids:
        if time.monotonic() > deadline:
            raise TimeoutError(f"no {label!r} widget within {limit:g} s")
        await asyncio.sleep(0.05)


async def _quiet(server: ServerProcess, limit: float = 30.0) -> None:
    """Wait (at most ``limit`` s) until the server spends under a quarter of a core for half a second: the tabs'
    own copies are built and their first frames sent, so the measurement starts on a settled class."""
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        before = server.cpu_seconds()
        await asyncio.sleep(0.5)
        if server.cpu_seconds() - before < 0.125:
            return


def _start_profile(pid: int, seconds: float) -> subprocess.Popen | None:
    """``py-spy record`` of the server over the drag window only (``--profile FILE``, raw collapsed stacks)."""
    if not _PROFILE:
        return None
    if shutil.which("py-spy") is None:
        print("--profile needs py-spy (pip install py-spy); measuring without it")
        return None
    cmd = ["py-spy", "record", "--pid", str(pid), "--duration", str(max(1, int(seconds))), "--format", "raw"]
    cmd += ["--nonblocking", "--threads", "-o", str(_PROFILE[0])]
    return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _stats(ms: np.ndarray) -> str:
    """``median M ms   p95 P ms   max X ms`` of latencies [ms], or why there are none."""
    if not len(ms):
        return "no update came back (all merged, or the drags were refused)"
    return f"median {np.median(ms):6.1f} ms   p95 {np.percentile(ms, 95):6.1f} ms   max {ms.max():6.1f} ms"


def _line(r: dict, mode: str) -> str:
    own = r["own"]
    merged = 1 - len(own) / max(r["sends"], 1)
    text = (
        f"  N = {r['n']:>3}   server CPU {100 * r['cpu']:5.1f} %   latency {_stats(own)}   merged {100 * merged:4.1f} %"
        f"   ({r['sends']} updates, RSS {r['rss']:.0f} MB; CPU of this client {100 * r['client_cpu']:.0f} %,"
        f" of other processes {100 * r['others']:.0f} %, stolen by the host {100 * r['stolen']:.0f} %)"
    )
    if mode in ("presenter", "hall") and len(r["watched"]):
        w = r["watched"]
        text += f"\n           watchers: {_stats(w)}"
    if mode == "hall" and r["per_tab"]:
        p = np.array(r["per_tab"])
        text += (
            f"\n           {len(p)} own copies: p95 per tab median {np.median(p):6.1f} ms, worst {p.max():6.1f} ms"
            f", {int((p > 150).sum())} tab(s) over 150 ms"
        )
    for who, part in r.get("split", {}).items():  # where the time goes: the rest is sending, the network, the tab
        text += f"\n           {who}: in the server (input sent -> update encoded) {_stats(part)}"
    return text


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mode", choices=["private", "presenter", "shared", "hall"], default="private")
    parser.add_argument("--hall", type=int, default=150, help="tabs in the lecture hall (--mode hall, max 190)")
    parser.add_argument("--own", type=int, default=30, help="of which on their own copies, dragging (--mode hall)")
    parser.add_argument("--tabs", type=int, nargs="+", default=[1, 10, 30], help="values of N (max 60)")
    parser.add_argument("--seconds", type=float, default=10.0, help="drag time per N (max 120)")
    parser.add_argument("--rate", type=float, default=20.0, help="drag updates per second per tab")
    parser.add_argument("--quick", action="store_true", help="4 s per N")
    parser.add_argument("--root", type=Path, help="serve this checkout's app.py (e.g. a worktree of an older commit)")
    parser.add_argument("--profile", type=Path, help="write py-spy's collapsed stacks of the drag window here")
    args = parser.parse_args()
    if args.profile is not None:
        _PROFILE.append(args.profile)
    seconds = min(4.0 if args.quick else args.seconds, 120.0)
    print(f"Load, mode {args.mode}: N tabs dragging at {args.rate:g} Hz for {seconds:g} s (server in a child process)")
    problems = 0
    _HALL_OWN[0] = max(0, min(args.own, args.hall - 1))
    for n in [min(max(args.hall, 2), 190)] if args.mode == "hall" else args.tabs:
        n = n if args.mode == "hall" else max(1, min(n, 60))
        server = ServerProcess(TOKEN if args.mode in ("presenter", "hall") else None, root=args.root)
        progress = {"opened": 0, "step": "opening tabs"}
        budget = seconds + 60.0 + OPEN_SECONDS * n
        try:
            scenario = _scenario(server, n, args.mode, seconds, args.rate, progress)
            result = asyncio.run(asyncio.wait_for(scenario, budget))
            print(_line(result, args.mode), flush=True)
        except Exception as exc:  # a result line either way: what happened, never a bare traceback
            why = f"{type(exc).__name__}: {str(exc)[:120]}" if str(exc) else type(exc).__name__
            print(
                f"  N = {n:>3}   no result ({why}) while {progress['step']}, {progress['opened']} of {n} tabs open "
                f"after at most {budget:.0f} s (a busy machine? rerun on a quiet one)",
                flush=True,
            )
        finally:
            server.stop()
            found = server.log_problems()
            problems += len(found)
            for line in found[:5]:
                print(f"    server log: {line}")
    print(f"server log: {problems} line(s) reporting an exception")


if __name__ == "__main__":
    main()
