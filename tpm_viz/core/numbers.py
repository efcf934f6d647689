"""Numbers as people type them: ``parse_number`` turns a field's text into a finite float or one clear line.

Accepted (``docs/csv.md`` lists the same rules for CSV cells):

- surrounding spaces, a leading ``+`` or ``-``, the Unicode minus ``−`` (U+2212) and the full-width ``－``;
- scientific notation: ``1e9``, ``5E-1``, ``2.5e+3``;
- a decimal comma: ``0,25`` is 0.25 (``2,5e-3`` too). A comma is *always* a decimal separator, so ``1,000`` is
  1.0, never a thousand;
- digit groups separated by spaces (normal, no-break or thin spaces) in the integer part: ``1 000`` and
  ``12 345,5``, but only groups of exactly three digits after the first (``1 00`` is refused);
- the field's own unit after the number when ``unit`` is given: ``5 mm`` in a field in mm; with
  :func:`parse_quantity`, that unit with any other SI prefix too (one rule for every unit the app accepts: ``5 kN``
  in a field in N is 5000, ``0.15 m`` in a field in mm is 150, ``20 µm`` in mm is 0.02, ``1 kHz`` in Hz is 1000).

Refused with :class:`~tpm_viz.core.errors.InputError`: empty text, text that is not a number, a number with both ``.``
and ``,`` or with several commas (``1,234.5``, ``1.234,5``, ``1,000,000``: thousands separators are ambiguous;
write ``1234.5``), NaN and infinities, numbers too large for a float (``1e999``), and texts longer than
:data:`MAX_TEXT` characters. Messages quote at most :data:`QUOTE` characters of what was typed.

:data:`UNITS` and :func:`unit_factor` convert the units people write (``mm``, ``ms``, ``mm/s^2``, ``kN``, ``deg``,
``Hz``) to SI; :func:`parse_quantity` reads a number with any unit of the field's quantity (``0.15 m`` in a field in
mm is 150, ``0.2 kN`` in a field in N is 200, ``30°`` in a field in rad is π/6); :func:`plausibility`
(:func:`plausibility_note`: as text) flags results far beyond the usual size (a hint at an input in the wrong unit).

Numbers as people read them: :func:`fixed` is the one formatter of a shown number (a dash for None, NaN or
infinity; never ``-0.0``: a value that rounds to zero is written as zero, whatever its sign).

Base layer: standard library only.
"""

from __future__ import annotations

import math
import re

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase, T

__all__ = [
    "DASH",
    "MAX_TEXT",
    "QUOTE",
    "UNITS",
    "fixed",
    "parse_number",
    "parse_quantity",
    "plausibility",
    "plausibility_note",
    "shorten",
    "unit_factor",
]

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
    "hz": ("frequency", 1.0, 1.0),
    "rad/s": ("frequency", 1.0, 2.0 * math.pi),
    "kg": ("mass", 1.0, 1.0),
    "g": ("mass", 1.0, 1000.0),
}
_PREFIXES = {"k": (1000.0, 1.0), "m": (1.0, 1000.0), "u": (1.0, 1e6), "c": (1.0, 100.0)}
"""SI prefixes any unit of :data:`UNITS` takes (centi on lengths only), as (multiplier, divisor): kilo, milli, micro
(``µ``, ``μ`` or ``u``). Mega and the rest are left out: case is ignored, so ``MN`` would read as ``mN``."""
_BASES = ("m", "s", "m/s", "m/s^2", "n", "rad", "hz", "g")
for _base in _BASES:
    for _p, (_pm, _pd) in _PREFIXES.items():
        _q, _mul, _div = UNITS[_base]
        if _p + _base not in UNITS and (_p != "c" or _q == "length"):
            UNITS[_p + _base] = (_q, _mul * _pm, _div * _pd)
"""Units people write (e.g. in a CSV header) -> (quantity, multiplier, divisor): SI value = value * mul / div.
Case is ignored, ``µm``/``μm`` is ``um``, ``s²``/``s2`` is ``s^2``; every unit also with a prefix of
:data:`_PREFIXES` (``5 kN``, ``0.15 m`` in a field in mm, ``250 ms``, ``1 kHz``, ``500 g``). A frequency is in Hz;
``rad/s`` is an angular frequency, ``ω = 2π f`` (a natural frequency ``ω_n`` typed in rad/s)."""
_SI = {
    "length": "m",
    "time": "s",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "force": "N",
    "angle": "rad",
    "frequency": "Hz",
    "mass": "kg",
}
_QUANTITY = {
    "length": T("length"),
    "time": T("time"),
    "velocity": T("velocity"),
    "acceleration": T("acceleration"),
    "force": T("force"),
    "angle": T("angle"),
    "frequency": T("frequency"),
    "mass": T("mass"),
}
"""The quantities of :data:`UNITS` as words (messages)."""
_ALT = {"m": "mm", "s": "ms", "m/s": "mm/s", "m/s^2": "mm/s^2", "N": "kN", "rad": "deg", "Hz": "rad/s", "kg": "g"}
"""A second unit a refusal suggests besides the SI one, by SI unit."""
_MINUS = str.maketrans({"\u2212": "-", "\uff0d": "-", "\ufe63": "-"})
_SPACES = "\u0020\u00a0\u202f\u2009\u2007"
_GROUPED = re.compile(rf"[+-]?\d{{1,3}}(?:[{_SPACES}]\d{{3}})+(?:[.,]\d*)?(?:[eE][+-]?\d+)?")
_NUMBERISH = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_WITH_UNIT = re.compile(r"(.*[0-9.,])\s*([^0-9\s.,+\-\u2212\uff0d][^\s]*)", re.S)
"""A number followed by a unit: the longest head that ends in a digit or a separator, then a unit that starts with
anything but a digit, a space, a separator or a sign (``1e3mm``: ``1e3`` and ``mm``; ``30°``; ``5 m/s^2``)."""


DASH = "—"
"""What :func:`fixed` shows for a number that is missing or not finite."""


def fixed(x: object, fmt: str = ".1f", scale: float = 1.0) -> str:
    """``x * scale`` formatted with ``fmt`` (a :func:`format` spec: ``".1f"``, ``"+.2f"``, ``".3e"``, ``"g"``)
    as a number is shown to people: :data:`DASH` for None, NaN, infinity or a non-number, and never a negative
    zero (``fixed(-1e-12, ".1f")`` is ``"0.0"``, ``fixed(-0.04, "+.1f")`` is ``"+0.0"``)."""
    if x is None or isinstance(x, bool):
        return DASH
    try:
        v = float(x) * float(scale)  # type: ignore[arg-type]  # anything: not a number shows DASH
    except (TypeError, ValueError, OverflowError):
        return DASH
    if not math.isfinite(v):
        return DASH
    text = format(v, fmt)
    mantissa = re.split("[eE]", text, maxsplit=1)[0]
    if "-" in mantissa and not any(c in "123456789" for c in mantissa):  # rounds to zero: drop the sign
        text = format(0.0, fmt)
    return text


def shorten(text: object, limit: int = QUOTE) -> str:
    """``repr`` of ``text`` cut to about ``limit`` characters (``'123...'``), for messages."""
    text = str(text)
    if len(text) <= limit:
        return repr(text)
    return repr(text[: max(limit - 3, 1)]) + "..."


def _label(name: str | Phrase, unit: str) -> str | Phrase:
    """A field's name and unit in a message: a phrase stays a phrase (shown in a tab's language), a plain name is
    cut to :data:`QUOTE` characters."""
    named: str | Phrase = name if isinstance(name, Phrase) else str(name)[:QUOTE]
    return Phrase("{name} [{unit}]", name=named, unit=unit) if unit else named


def parse_number(text: object, name: str | Phrase = "value", unit: str = "") -> float:
    """The finite float that ``text`` spells (rules in the module docstring), else a one-line InputError.

    ``name`` names the field in messages (a plain name, or a phrase such as ``T("duration")``, shown in a tab's
    language), ``unit`` is the field's unit (quoted in messages, and accepted after the number). Real numbers (not
    ``bool``) are accepted as they are if finite.
    """
    label = _label(name, unit)
    if isinstance(text, bool):
        raise InputError(Phrase("{label} must be a number, got {text}", label=label, text=repr(text)))
    if isinstance(text, (int, float)):
        try:
            value = float(text)
        except OverflowError:
            raise InputError(
                Phrase("{label} is too large for a number, got {text}", label=label, text=shorten(text))
            ) from None
        if not math.isfinite(value):
            raise InputError(Phrase("{label} must be a finite number, got {text}", label=label, text=repr(value)))
        return value
    if not isinstance(text, str):
        raise InputError(Phrase("{label} must be a number, got {text}", label=label, text=shorten(text)))
    s = text.strip()
    if not s:
        raise InputError(Phrase("{label} is empty: type a number such as 0.25, 0,25 or 2.5e-1", label=label))
    if len(s) > MAX_TEXT:
        raise InputError(
            Phrase(
                "{label}: {text} is too long for a number ({n} characters; at most {most})",
                label=label,
                text=shorten(s),
                n=len(s),
                most=MAX_TEXT,
            )
        )
    s = s.translate(_MINUS)
    if unit and s.endswith(unit) and len(s) > len(unit):
        s = s[: -len(unit)].rstrip()
    if _GROUPED.fullmatch(s):
        s = "".join(ch for ch in s if ch not in _SPACES)
    if "," in s:
        if "." in s or s.count(",") > 1:
            raise InputError(
                Phrase(
                    "{label}: {text} mixes separators; write the number without thousands separators, with one "
                    "decimal point or comma (1234.5 or 1234,5)",
                    label=label,
                    text=shorten(text.strip()),
                )
            )
        s = s.replace(",", ".")
    try:
        value = float(s)
    except ValueError:
        raise InputError(
            Phrase(
                "{label}: {text} is not a number (examples: 0.25, 0,25, -1.5e-3)",
                label=label,
                text=shorten(text.strip()),
            )
        ) from None
    if not math.isfinite(value):
        if _NUMBERISH.fullmatch(s.replace("_", "")):
            raise InputError(
                Phrase("{label}: {text} is too large (beyond ±1.8e308)", label=label, text=shorten(text.strip()))
            )
        raise InputError(
            Phrase("{label}: {text} is not finite; type a finite number", label=label, text=shorten(text.strip()))
        )
    return value


def parse_quantity(text: object, name: str | Phrase = "value", unit: str = "") -> float:
    """The number ``text`` spells, in the field's ``unit``, with any unit of the same quantity after it (the rules
    of :func:`parse_number`; :data:`UNITS` for the units): in a field in mm, ``150``, ``150 mm``, ``15 cm`` and
    ``0.15 m`` are all 150; in a field in N, ``0,2 kN`` is 200; in a field in Hz, ``62.83 rad/s`` is 10. A unit of
    another quantity, an unknown unit, or any unit in a field without one (``unit`` ""), is a one-line
    :class:`~tpm_viz.core.errors.InputError` naming the field (``name [unit]``) and the units that fit."""
    try:
        return parse_number(text, name, unit)
    except InputError as exc:
        found = _WITH_UNIT.fullmatch(text.strip()) if isinstance(text, str) and len(text) <= MAX_TEXT else None
        if found is None or not any(ch.isdigit() for ch in found.group(1)):
            raise exc from None
    head, typed = found.groups()
    label = _label(name, unit)
    if not unit:
        raise InputError(
            Phrase("{label}: {unit} does not fit: type the number alone", label=label, unit=shorten(typed))
        ) from None
    field = _entry(unit)
    if field is None:  # the field's own unit is not in UNITS: only that unit is understood
        raise InputError(
            Phrase("{label} has an unknown unit {unit} (use {si})", label=label, unit=shorten(typed), si=unit)
        )
    mul, div = unit_factor(typed, field[0], label, str(name))
    value = parse_number(head, name, unit) * mul / div * field[2] / field[1]
    if not math.isfinite(value):
        raise InputError(Phrase("{label}: {text} is too large (beyond ±1.8e308)", label=label, text=shorten(text)))
    return value


def _entry(unit: str) -> tuple[str, float, float] | None:
    """The :data:`UNITS` entry of ``unit`` as people write it (case, ``µ``, ``²``), or None; a unit written with a
    capital ``M`` is None (mega is not taken: ``MN`` must never read as ``mN``)."""
    if unit.startswith("M"):
        return None
    key = unit.lower().replace(" ", "").replace("µ", "u").replace("μ", "u").replace("²", "^2")
    return UNITS.get(key[:-1] + "^2" if key.endswith("/s2") else key)


def plausibility(
    value: float, name: str, unit: str = "", typical: float | None = None, factor: float = 1000.0
) -> Phrase | None:
    """A one-line note when ``|value|`` exceeds ``typical`` (same unit) by more than ``factor``, else None.

    For results that are computed correctly but hint at an input in the wrong unit (forces of meganewtons from
    positions typed in millimetres as metres, a 1000 s run from times in milliseconds). ``str()`` of the phrase is
    the English line; the app renders it in a tab's language.
    """
    if typical is None or not math.isfinite(value) or abs(value) <= factor * abs(typical):
        return None
    return Phrase(
        "note: {name} = {value:.3g}{unit} is more than {factor:g} times the usual {typical:.3g}{unit}; "
        "check the units of the inputs",
        name=str(name)[:QUOTE],
        value=value,
        unit=f" {unit}" if unit else "",
        factor=factor,
        typical=typical,
    )


def plausibility_note(
    value: float, name: str, unit: str = "", typical: float | None = None, factor: float = 1000.0
) -> str | None:
    """:func:`plausibility` as English text (the command line), or None."""
    note = plausibility(value, name, unit, typical, factor)
    return None if note is None else str(note)


def unit_factor(unit: str, quantity: str | None, label: str | Phrase, name: str) -> tuple[float, float]:
    """``(multiplier, divisor)`` from ``unit`` to SI for a ``quantity`` (``"length"``, ...; None: takes no unit).

    ``""`` is SI. An unknown unit, or one of another quantity, is a one-line InputError starting with ``label``
    (text, or a phrase shown in a tab's language) and naming the quantity of ``name`` (``p1 is a length in m``).
    """
    if not unit:
        return 1.0, 1.0
    entry = _entry(unit)
    si = _SI.get(quantity or "", "")
    if entry is None:
        if not si:
            raise InputError(Phrase("{label} has an unknown unit {unit}", label=label, unit=shorten(unit)))
        alt = _ALT.get(si, si)
        raise InputError(
            Phrase(
                "{label} has an unknown unit {unit} (use {si} or {alt})",
                label=label,
                unit=shorten(unit),
                si=si,
                alt=alt,
            )
        )
    if quantity != entry[0]:
        kind = _QUANTITY[entry[0]]
        if not quantity:
            raise InputError(
                Phrase(
                    "{label}: {unit} is a {kind} unit, but {name} takes no unit",
                    label=label,
                    unit=shorten(unit),
                    kind=kind,
                    name=name,
                )
            )
        raise InputError(
            Phrase(
                "{label}: {unit} is a {kind} unit, but {name} is a {quantity} in {si}",
                label=label,
                unit=shorten(unit),
                kind=kind,
                name=name,
                quantity=_QUANTITY.get(quantity, quantity),
                si=si,
            )
        )
    return entry[1], entry[2]
