"""Shared timing helpers for the benchmark scripts (medians over repeats, ratio to a target)."""

from __future__ import annotations

import statistics
import time


def median_seconds(fn, repeat: int, inner: int = 1) -> float:
    """Median wall time [s] of one call of ``fn`` over ``repeat`` runs of ``inner`` calls (after a warm-up)."""
    fn()
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(inner):
            fn()
        samples.append((time.perf_counter() - t0) / inner)
    return statistics.median(samples)


def report(name: str, seconds: float, target: float | None, unit: str, scale: float) -> None:
    """One line: the median in ``unit`` (``seconds * scale``), the target and their ratio."""
    tail = "" if target is None else f"   target {target * scale:7.1f} {unit}   ratio {seconds / target:5.2f}"
    print(f"{name:<58} median {seconds * scale:9.2f} {unit}{tail}")


def samples_seconds(fn, repeat: int) -> list[float]:
    """Wall time [s] of each of ``repeat`` calls of ``fn`` (no warm-up: the first may be cold)."""
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def p95(samples: list[float]) -> float:
    """The 95th percentile of ``samples`` (nearest rank)."""
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
