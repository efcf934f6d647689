"""Numbers as people type them: ``parse_number`` turns a field's text into a finite float or one clear line.

Accepted (``docs/csv.md`` lists the same rules for CSV cells):

- surrounding spaces, a leading ``+`` or ``-``, the Unicode minus ``−`` (U+2212) and the full-width ``－``;
- scientific notation: ``1e9``, ``5E-1``, ``2.5e+3``;
- a decimal comma: ``0,25`` is 0.25 (``2,5e-3`` too). A comma is *always* a decimal separator, so ``1,000`` is
  1.0, never a thousand;
- digit groups separated by spaces (normal, no-break or thin spaces) in the integer part: ``1 000`` and
  ``12 345,5``, but only groups of exactly three digits after the first (``1 00`` is refused);
- the field's own unit after the number when ``unit`` is given: ``5 mm`` in a field in mm.

Refused with :class:`~tpm_viz.errors.InputError`: empty text, text that is not a number, a number with both ``.``
and ``,`` or with several commas (``1,234.5``, ``1.234,5``, ``1,000,000``: thousands separators are ambiguous;
write ``1234.5``), NaN and infinities, numbers too large for a float (``1e999``), and texts longer than
:data:`MAX_TEXT` characters. Messages quote at most :data:`QUOTE` characters of what was typed.

:data:`UNITS` and :func:`unit_factor` convert the units people write (``mm``, ``ms``, ``mm/s^2``, ``kN``, ``deg``)
to SI; :func:`plausibility_note` flags results far beyond the usual size (a hint at an input in the wrong unit).

Base layer: standard library only.
"""

from __future__ import annotations

import math
import re

from tpm_viz.errors import InputError

__all__ = ["MAX_TEXT", "QUOTE", "UNITS", "parse_number", "plausibility_note", "shorten", "unit_factor"]

MAX_TEXT = 400
"""Longest text accepted as a number [characters] (the exact decimal value of a float fits in far less)."""
QUOTE = 40
"""Most characters of an input quoted in a message."""

UNITS: dict[str, tuple[str, float, float]] = {
    "m": ("length", 1.0, 1.0),
    "mm": ("length", 1.0, 1000.0),
    "cm": ("length", 1.0, 100.0),
    "um": ("length", 1.0, 1e6),
    "s": ("time", 1.0, 1.0),
    "sec": ("time", 1.0, 1.0),
    "ms": ("time", 1.0, 1000.0),
    "m/s": ("velocity", 1.0, 1.0),
    "mm/s": ("velocity", 1.0, 1000.0),
    "m/s^2": ("acceleration", 1.0, 1.0),
    "mm/s^2": ("acceleration", 1.0, 1000.0),
    "n": ("force", 1.0, 1.0),
    "kn": ("force", 1000.0, 1.0),
    "rad": ("angle", 1.0, 1.0),
    "deg": ("angle", math.pi, 180.0),
    "°": ("angle", math.pi, 180.0),
}
"""Units people write (e.g. in a CSV header) -> (quantity, multiplier, divisor): SI value = value * mul / div.
Case is ignored, ``µm``/``μm`` is ``um``, ``s²``/``s2`` is ``s^2``."""
_SI = {"length": "m", "time": "s", "velocity": "m/s", "acceleration": "m/s^2", "force": "N", "angle": "rad"}
_MINUS = str.maketrans({"\u2212": "-", "\uff0d": "-", "\ufe63": "-"})
_SPACES = "\u0020\u00a0\u202f\u2009\u2007"
_GROUPED = re.compile(rf"[+-]?\d{{1,3}}(?:[{_SPACES}]\d{{3}})+(?:[.,]\d*)?(?:[eE][+-]?\d+)?")
_NUMBERISH = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def shorten(text, limit: int = QUOTE) -> str:
    """``repr`` of ``text`` cut to about ``limit`` characters (``'123...'``), for messages."""
    text = str(text)
    if len(text) <= limit:
        return repr(text)
    return repr(text[: max(limit - 3, 1)]) + "..."


def _label(name: str, unit: str) -> str:
    name = str(name)[:QUOTE]
    return f"{name} [{unit}]" if unit else name


def parse_number(text, name: str = "value", unit: str = "") -> float:
    """The finite float that ``text`` spells (rules in the module docstring), else a one-line InputError.

    ``name`` names the field in messages, ``unit`` is the field's unit (quoted in messages, and accepted after
    the number). Real numbers (not ``bool``) are accepted as they are if finite.
    """
    label = _label(name, unit)
    if isinstance(text, bool):
        raise InputError(f"{label} must be a number, got {text!r}")
    if isinstance(text, (int, float)):
        try:
            value = float(text)
        except OverflowError:
            raise InputError(f"{label} is too large for a number, got {shorten(text)}") from None
        if not math.isfinite(value):
            raise InputError(f"{label} must be a finite number, got {value!r}")
        return value
    if not isinstance(text, str):
        raise InputError(f"{label} must be a number, got {shorten(text)}")
    s = text.strip()
    if not s:
        raise InputError(f"{label} is empty: type a number such as 0.25, 0,25 or 2.5e-1")
    if len(s) > MAX_TEXT:
        raise InputError(f"{label}: {shorten(s)} is too long for a number ({len(s)} characters; at most {MAX_TEXT})")
    s = s.translate(_MINUS)
    if unit and s.endswith(unit) and len(s) > len(unit):
        s = s[: -len(unit)].rstrip()
    if _GROUPED.fullmatch(s):
        s = "".join(ch for ch in s if ch not in _SPACES)
    if "," in s:
        if "." in s or s.count(",") > 1:
            raise InputError(
                f"{label}: {shorten(text.strip())} mixes separators; write the number without thousands "
                "separators, with one decimal point or comma (1234.5 or 1234,5)"
            )
        s = s.replace(",", ".")
    try:
        value = float(s)
    except ValueError:
        raise InputError(f"{label}: {shorten(text.strip())} is not a number (examples: 0.25, 0,25, -1.5e-3)") from None
    if not math.isfinite(value):
        if _NUMBERISH.fullmatch(s.replace("_", "")):
            raise InputError(f"{label}: {shorten(text.strip())} is too large (beyond ±1.8e308)")
        raise InputError(f"{label}: {shorten(text.strip())} is not finite; type a finite number")
    return value


def plausibility_note(value: float, name: str, unit: str = "", typical: float | None = None) -> str | None:
    """A one-line note when ``|value|`` exceeds ``typical`` (same unit) by more than a factor of 1000, else None.

    For results that are computed correctly but hint at an input in the wrong unit (forces of meganewtons from
    positions typed in millimetres as metres, a 1000 s run from times in milliseconds).
    """
    if typical is None or not math.isfinite(value) or abs(value) <= 1000.0 * abs(typical):
        return None
    u = f" {unit}" if unit else ""
    return (
        f"note: {_label(name, '')} = {value:.3g}{u} is more than 1000 times the usual {typical:.3g}{u}; "
        "check the units of the inputs"
    )


def unit_factor(unit: str, quantity: str | None, label: str, name: str) -> tuple[float, float]:
    """``(multiplier, divisor)`` from ``unit`` to SI for a ``quantity`` (``"length"``, ...; None: takes no unit).

    ``""`` is SI. An unknown unit, or one of another quantity, is a one-line InputError starting with ``label``
    and naming the quantity of ``name`` (``p1 is a length in m``).
    """
    if not unit:
        return 1.0, 1.0
    key = unit.lower().replace(" ", "").replace("µ", "u").replace("μ", "u").replace("²", "^2")
    entry = UNITS.get(key[:-1] + "^2" if key.endswith("/s2") else key)
    si = _SI.get(quantity or "", "")
    if entry is None:
        hint = f" (use {si} or {'mm' if si == 'm' else 'ms' if si == 's' else si})" if si else ""
        raise InputError(f"{label} has an unknown unit {shorten(unit)}{hint}")
    if quantity != entry[0]:
        what = f"{name} is a {quantity} in {si}" if quantity else f"{name} takes no unit"
        raise InputError(f"{label}: {shorten(unit)} is a {entry[0]} unit, but {what}")
    return entry[1], entry[2]
