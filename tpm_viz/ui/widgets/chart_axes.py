"""The axes of the time charts, decided on the server: ticks, their labels, the ranges and the room they need.

The charts of the app are uPlot charts (:mod:`tpm_viz.ui.teaching.player.charts`). uPlot can place ticks itself, but in
the browser, from the chart's current size and scales, and it formats them with the page's number format (``-0``
for a tick computed as ``-0.0``, ``100,000,000`` wider than its axis). So the app sends each axis as numbers and
text instead (uPlot's static ``splits`` and ``values``) with a fixed range:

- :func:`time_ticks`: the time axis spans exactly the run, ``[t0, t1]``, with 3 to ``most`` ticks on multiples
  of a 1-2-5 step (``t0 = 0``: always ``0`` and at least two more), for any duration, spaced so that their labels
  do not touch on the narrowest chart (``room``: the browser picks the chart's width, the server cannot know it);
- :func:`value_ticks`: a value axis widened to the nearest ticks around the data, with a flat or negligible
  series (``|v| <= resolution``, e.g. ``-1e-12``) shown as ``[-1, 1]`` or ``c ± 10 %``;
- :func:`tick_labels`: one format for every label of an axis (the same decimals; ``×10ⁿ`` from 10⁶ up, or for
  steps below 10⁻⁴ on an axis below 1), a true minus sign, and never a negative zero;
- :func:`text_width`: a conservative width [CSS px] of a text in the charts' font (DejaVu Sans, the widest of
  the usual sans fonts), from which the y axis gets its width and a chart its height.

Pure: numbers in, numbers and strings out (display units: the caller scales SI values first).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["MINUS", "Ticks", "nice_step", "text_width", "tick_labels", "time_ticks", "value_ticks"]

MINUS = "\u2212"
"""The minus sign of the labels (U+2212, as matplotlib prints it)."""

_MULTIPLES = (1, 2, 5)
_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_FIXED_MAX = 1e6  # labels of ticks up to this magnitude are written out (1,000,000 is the first in ×10ⁿ)
_FIXED_MIN_EXP = -4  # steps down to 10⁻⁴ are written out (0.0005); finer steps use ×10ⁿ


@dataclass(frozen=True)
class Ticks:
    """One axis: its range ``[lo, hi]``, the tick positions (ascending, inside the range) and their labels."""

    lo: float
    hi: float
    values: tuple[float, ...]
    labels: tuple[str, ...]


def _nice(raw: float) -> tuple[int, int]:
    """The smallest ``m × 10^k`` (m in 1, 2, 5) at or above ``raw > 0``, as ``(m, k)``."""
    k = math.floor(math.log10(raw))
    for exponent in (k - 1, k, k + 1):
        for m in _MULTIPLES:
            if m * 10.0**exponent >= raw * (1 - 1e-12):
                return m, exponent
    return 1, k + 2  # pragma: no cover (10^(k+1) >= raw always)


def _step_of(m: int, k: int) -> float:
    return m * 10.0**k if k >= 0 else m / 10.0 ** (-k)


def nice_step(raw: float) -> float:
    """The smallest step of the 1-2-5 series (``1, 2, 5 × 10^k``) at or above ``raw > 0``."""
    return _step_of(*_nice(raw))


def _next(m: int, k: int) -> tuple[int, int]:
    i = _MULTIPLES.index(m)
    return (_MULTIPLES[i + 1], k) if i + 1 < len(_MULTIPLES) else (1, k + 1)


def _zero_free(text: str) -> str:
    """``text`` with a true minus sign, and without the sign of a label that reads as zero (``-0.00``)."""
    if text.startswith("-"):
        if not any(c in "123456789" for c in text.split("×")[0]):
            return text[1:]
        return MINUS + text[1:]
    return text


def _exponent(x: float) -> int:
    """``floor(log10(x))`` for ``x > 0``, robust to a product such as ``3 * 0.1`` landing just off a power of ten."""
    return math.floor(math.log10(x) + 1e-9)


def tick_labels(values: Iterable[float], k: int) -> tuple[str, ...]:
    """Labels of ticks on multiples of ``m × 10^k``: written out with ``max(0, -k)`` decimals (thousands
    separated by commas), or as ``a.b×10ⁿ`` (one exponent for the axis) when a tick reaches 10⁶, or when
    ``k < -4`` on an axis whose ticks all lie below 1 (``5×10⁻⁶`` rather than ``0.000005``)."""
    vals = [float(v) for v in values]
    top = max((abs(v) for v in vals), default=0.0)
    if top < _FIXED_MAX and (k >= _FIXED_MIN_EXP or top >= 1.0):
        decimals = max(0, -k)
        return tuple(_zero_free(f"{v:,.{decimals}f}") for v in vals)
    exponent = _exponent(top) if top > 0 else k
    decimals = max(0, exponent - k)
    power = f"×10{str(exponent).translate(_SUPERSCRIPT)}"
    out = []
    for v in vals:
        mantissa = f"{v / 10.0**exponent:.{decimals}f}"
        out.append("0" if float(mantissa) == 0.0 else _zero_free(mantissa + power))
    return tuple(out)


def _ticks_on(m: int, k: int, lo: float, hi: float, inside: bool) -> tuple[int, int]:
    """First and last multiple index of the step ``m × 10^k``: inside ``[lo, hi]`` or around it."""
    step = _step_of(m, k)
    slack = 1e-9  # of a step: a tick a rounding error away from the edge counts as on it
    if inside:
        return math.ceil(lo / step - slack), math.floor(hi / step + slack)
    return math.floor(lo / step + slack), math.ceil(hi / step - slack)


def _build(m: int, k: int, first: int, last: int, lo: float, hi: float) -> Ticks:
    step = _step_of(m, k)
    values = tuple(min(max(i * step, lo), hi) for i in range(first, last + 1))
    values = tuple(0.0 if v == 0 else v for v in values)  # no -0.0 on the wire either
    return Ticks(float(lo), float(hi), values, tick_labels(values, k))


_SPAN_MAX = 1e300  # a range wider than this is narrowed to it (its width would overflow to infinity)


def _finite_range(lo: float, hi: float) -> tuple[float, float]:
    return max(lo, -_SPAN_MAX), min(hi, _SPAN_MAX)


def time_ticks(
    t0: float, t1: float, most: int = 6, room: float | None = None, gap: float = 12.0, px: float = 12.0
) -> Ticks:
    """Ticks of a time axis spanning exactly ``[t0, t1]`` [s], on multiples of a 1-2-5 step: between 3
    (``t0 = 0``; 2 for another start) and ``most`` of them (``most >= 6``, raised to 6 if smaller).

    The smallest such step is taken, unless ``room`` is given: the width [CSS px] of the narrowest plot the axis
    may be drawn on. Then the step is also large enough that neighbouring labels (``px`` CSS px,
    :func:`text_width`) leave ``gap`` px between them, if any step with enough ticks allows it (else the one with
    the fewest)."""
    t0, t1 = float(t0), float(t1)
    if not (math.isfinite(t0) and math.isfinite(t1)):
        t0, t1 = 0.0, 1.0
    t0, t1 = _finite_range(t0, t1)
    if t1 <= t0:
        t1 = t0 + (abs(t0) if t0 else 1.0)
    most = max(6, int(most))
    fewest = 3 if t0 == 0.0 else 2
    span = t1 - t0
    m, k = _nice(span / (10 * most))  # well below the first step with at most `most` ticks
    best: Ticks | None = None
    while True:
        first, last = _ticks_on(m, k, t0, t1, inside=True)
        count = last - first + 1
        if count < fewest and best is not None:
            return best  # no larger step has room for more: the fewest labels that still make an axis
        if fewest <= count <= most:
            best = _build(m, k, first, last, t0, t1)
            widest = max(text_width(label, px) for label in best.labels)
            if room is None or room * _step_of(m, k) / span >= widest + gap:
                return best
        if count < fewest:  # pragma: no cover (the step after one with > most ticks has >= fewest, see tests)
            return _build(m, k, first, max(first, last), t0, t1)
        m, k = _next(m, k)


def value_ticks(data: ArrayLike, most: int = 5, resolution: float = 1e-9) -> Ticks:
    """Ticks around the finite values of ``data`` (display units): the range is the smallest span of whole
    steps holding every value, at most ``most`` ticks (``most >= 3``), all of them inside it. Values within
    ``resolution`` of each other are one flat line, shown over ``c ± 10 %`` of their level ``c`` (``[-1, 1]``
    when ``|c| <= resolution``). Values beyond ±1e300 count as ±1e300."""
    arr = np.asarray(data, dtype=float).ravel()
    arr = np.clip(arr[np.isfinite(arr)], -_SPAN_MAX, _SPAN_MAX)
    lo, hi = (float(arr.min()), float(arr.max())) if arr.size else (0.0, 0.0)
    level = max(abs(lo), abs(hi))
    if hi - lo <= max(resolution, 1e-9 * level):
        centre = 0.5 * lo + 0.5 * hi
        if abs(centre) <= resolution:
            lo, hi = min(lo, -1.0), max(hi, 1.0)
        else:
            lo, hi = min(lo, centre - 0.1 * abs(centre)), max(hi, centre + 0.1 * abs(centre))
    most = max(3, most)
    m, k = _nice((hi - lo) / (most - 1))
    while True:
        first, last = _ticks_on(m, k, lo, hi, inside=False)
        if last - first + 1 <= most:
            step = _step_of(m, k)
            # The ticks a rounding error inside the data still count as its ends: the range takes the data.
            return _build(m, k, first, last, min(first * step, lo), max(last * step, hi))
        m, k = _next(m, k)


_NARROW = frozenset(".,:;!|' ()[]ilIjtf")
_WIDE = frozenset("mwMW%@")
_SIGNS = frozenset("+−×=<>±~")


def text_width(text: str, px: float = 12.0, bold: bool = False) -> float:
    """A width [CSS px] no smaller than ``text`` takes in DejaVu Sans at ``px`` (bold: 10 % wider): per-character
    widths rounded up (digits 0.7 em, signs 0.84 em, Hangul and CJK 1 em, ...)."""
    em = 0.0
    for c in text:
        if c.isdigit() and c.isascii():
            em += 0.70
        elif c in _NARROW:
            em += 0.42
        elif c in _SIGNS:
            em += 0.84
        elif c in _WIDE:
            em += 1.05
        elif c in "⁰¹²³⁴⁵⁶⁷⁸⁹⁻":
            em += 0.48
        elif c.isascii():
            em += 0.80 if c.isupper() else 0.68
        elif "\u1100" <= c <= "\u11ff" or "\u3000" <= c <= "\u9fff" or "\uac00" <= c <= "\ud7af":
            em += 1.0
        else:
            em += 0.80
    return em * px * (1.1 if bold else 1.0)
