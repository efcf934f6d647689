"""Numbers typed into the panel: a text field between the keyboard and the value in use. No viser.

viser's number inputs drop what they cannot show (``1e9`` became ``19``) and send every keystroke, so typed numbers
are text fields read with :func:`tpm_viz.core.numbers.parse_number` (scientific notation, decimal commas, the Unicode
minus, the field's unit after the number). This module is their logic, as plain objects driven with explicit
times, so that it is tested without a browser (``tests/ui/widgets/test_typed.py``):

- :class:`Quantity`: what one field holds (name, UI unit, SI scale, accepted range): text -> SI value, or one line
  saying what to change; SI value -> a short text that reads back to it. The field's unit may be typed after the
  number with any SI prefix (:func:`tpm_viz.core.numbers.parse_quantity`: ``0.15 m`` is 150 in a field in mm,
  ``5 kN`` is 5000 in a field in N).
- :class:`TypedField`: one field's text and the value in use. It is *clean* (its text is the app's, written by
  :meth:`TypedField.show`), *typing* (keystrokes not yet settled: never read for use, never overwritten by the app)
  or *held* (settled but not in use: refused, or waiting for the value it asked for). A held text stays until the
  value in use changes or it means that value.
- :class:`TypedGroup`: fields applied together (a vector, the parameter set, the duration). It is *settled* by
  Enter or its Apply button, or, if it has a ``quiet`` time, once no field of it changed for that long: then every
  field's value is read (a clean field gives the value in use, the others their text) and applied at once, or the
  group is refused with the first field's reason. Nothing is ever applied from a text in the middle of typing.
- :meth:`TypedGroup.lines`: what the note under the group says: why a text is refused and the value in use
  (``in use: 200 mm``) whenever a field's text does not mean it.

Plausibility notes for the results (:func:`force_note`, :func:`duration_note`) use
:func:`tpm_viz.core.numbers.plausibility`. Every sentence is a :class:`~tpm_viz.core.words.Phrase`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.numbers import fixed, parse_quantity, plausibility
from tpm_viz.core.words import Phrase

__all__ = [
    "FORCE_TYPICAL",
    "QUIET",
    "SHORT_DURATION",
    "Quantity",
    "TypedField",
    "TypedGroup",
    "duration_note",
    "force_note",
]

QUIET = 1.5
"""Seconds without a keystroke after which a group with a quiet time is applied (instead of a blur event, which
viser's text input does not send) and a group without one says what its typed text would do. Longer than the
pause between two keystrokes of someone typing a number, so that ``-1`` of ``-100000`` is never applied."""
FORCE_TYPICAL = 200.0
"""Actuator force [N] of the paper's motions (peaks 151 N on the line, 177 N on the circle); results more than ten
times larger (2 kN) get a plausibility note."""
SHORT_DURATION = 0.02
"""Trajectory durations below this [s] get a plausibility note (the forces grow as ``1/T²``)."""


CLEAN, TYPING, HELD = "clean", "typing", "held"


def _compact(value: float) -> str:
    """Six significant digits, no trailing zeros, never ``-0`` (``482``, ``0.95``, ``1.5e-05``)."""
    text = format(value, ".6g")
    return "0" if float(text) == 0.0 else text


@dataclass(frozen=True)
class Quantity:
    """What one typed field holds: ``name`` (in messages), its UI ``unit``, ``scale`` (SI value of one UI unit,
    e.g. 1e-3 for mm), the accepted range ``[lo, hi]`` in UI units and the ``resolution`` below which a value is
    shown as 0 (UI units: rounding noise such as ``-3e-14 mm`` of a computed pose is not a number to show);
    ``places``: the decimals the app writes (the readout's: one for the Move tab's millimetres), None: six significant
    digits."""

    name: str
    unit: str = ""
    scale: float = 1.0
    lo: float = -math.inf
    hi: float = math.inf
    resolution: float = 1e-9
    places: int | None = None

    def number(self, text: object) -> float:
        """The number ``text`` spells in the field's unit (the unit may be typed, with any SI prefix: ``0.15 m`` is
        150 in a mm field, ``5 kN`` is 5000 in an N field), not range-checked; else :class:`~tpm_viz.InputError`."""
        return parse_quantity(text, self.name, self.unit)

    def read(self, text: object) -> float:
        """The SI value ``text`` spells, else :class:`~tpm_viz.InputError` with one line saying what to change."""
        value = self.number(text)
        if not self.lo <= value <= self.hi:
            unit = f" {self.unit}" if self.unit else ""
            name, typed, lo, hi = self.name, _compact(value), _compact(self.lo), _compact(self.hi)
            if self.lo == -math.inf:
                why = Phrase(
                    "{name}: {value}{unit} is too large; type at most {hi}{unit}",
                    name=name,
                    value=typed,
                    unit=unit,
                    hi=hi,
                )
            elif self.hi == math.inf:
                why = Phrase(
                    "{name}: {value}{unit} is too small; type at least {lo}{unit}",
                    name=name,
                    value=typed,
                    unit=unit,
                    lo=lo,
                )
            else:
                why = Phrase(
                    "{name}: {value}{unit} is out of range; type a value from {lo} to {hi}{unit}",
                    name=name,
                    value=typed,
                    unit=unit,
                    lo=lo,
                    hi=hi,
                )
            raise InputError(why)
        si = value * self.scale
        if not math.isfinite(si):
            raise InputError(Phrase("{name}: {value} is too large", name=self.name, value=_compact(value)))
        return si

    def text(self, si: float) -> str:
        """The field's text for the SI value ``si`` (UI unit; :attr:`places` decimals, else six significant digits;
        0 below the resolution; never ``-0``)."""
        value = si / self.scale
        if self.places is not None:
            return fixed(value, f".{self.places}f")
        return _compact(0.0 if abs(value) < self.resolution else value)

    def shown(self, si: float) -> str:
        """``si`` in the UI unit with the unit, for a note (``200 mm``)."""
        return f"{self.text(si)} {self.unit}".rstrip()

    def means(self, text: str, si: float) -> bool:
        """Whether ``text`` reads as ``si`` to the digits shown (``5e-1`` means 0.5 s)."""
        try:
            return self.text(self.read(text)) == self.text(si)
        except TpmVizError:
            return False


class TypedField:
    """One text field: its text, the SI value in use and its state (module docstring)."""

    def __init__(self, quantity: Quantity, value: float) -> None:
        self.quantity = quantity
        self.value = float(value)
        """The SI value in use."""
        self.text = quantity.text(value)
        """What the field holds (the browser's text as last received, or the app's)."""
        self.state = CLEAN
        self.typed_at = -math.inf
        """Time of the last keystroke [s] (the caller's clock)."""
        self.problem: Phrase | None = None
        """Why the text was refused when the group was last settled."""

    @property
    def own(self) -> bool:
        """The text is the user's, not the value in use (typing or held)."""
        return self.state != CLEAN

    def typed(self, text: str, now: float) -> None:
        """A keystroke: the field now holds ``text``."""
        self.text, self.typed_at, self.state, self.problem = str(text), now, TYPING, None

    def read(self) -> float:
        """The SI value this field asks for: the value in use if clean, else its text's (InputError if none)."""
        return self.value if self.state == CLEAN else self.quantity.read(self.text)

    def hold(self, problem: Phrase | None = None) -> None:
        """Settled but not in use: refused (with its ``problem``) or waiting for the value it asked for."""
        self.state, self.problem = HELD, problem

    def show(self, value: float, force: bool = False) -> str | None:
        """The value in use is now ``value`` [SI]: the text to write into the field, or None to leave it.

        A field being typed in is left alone (unless ``force``: the user asked for other values, e.g. the paper's);
        a held field until the value changes or its text means it; a clean field is rewritten unless its text
        already means the value (``5e-1`` stays while T = 0.5 s)."""
        changed = self.quantity.text(value) != self.quantity.text(self.value)
        self.value = float(value)
        if not force and (self.state == TYPING or (self.state == HELD and not changed)):
            if self.state == HELD and self.problem is None and self.quantity.means(self.text, value):
                self.state = CLEAN  # it got the value it asked for
            return None
        self.state, self.problem = CLEAN, None
        if self.quantity.means(self.text, value):
            return None
        self.text = self.quantity.text(value)
        return self.text

    def line(self, pending: bool = False) -> Phrase | None:
        """The note about this field: why its text is refused and the value in use, or the value in use when the
        text is not the value in use; None when the field shows the value in use. ``pending``: the field's group
        is applied by Enter or its button only (say so of a valid text still being typed)."""
        in_use = self.quantity.shown(self.value)
        if self.problem is not None:
            return Phrase("{problem} (in use: {value})", problem=self.problem, value=in_use)
        if self.state == CLEAN or self.quantity.means(self.text, self.value):
            return None
        try:
            typed = self.quantity.read(self.text)
        except TpmVizError as exc:
            return Phrase("{problem} (in use: {value})", problem=_phrase(exc), value=in_use)
        if pending and self.state == TYPING:
            return Phrase(
                "{name}: {typed} typed, not applied yet (press Enter or Apply); in use: {value}",
                name=self.quantity.name,
                typed=self.quantity.shown(typed),
                value=in_use,
            )
        return Phrase("{name}: in use {value}", name=self.quantity.name, value=in_use)


def _phrase(exc: Exception) -> Phrase:
    """The phrase of an error (its message as a phrase without fields if it has none)."""
    first = exc.args[0] if exc.args else ""
    return first if isinstance(first, Phrase) else Phrase("{text}", text=str(exc))


class TypedGroup:
    """Fields applied together, by key; ``quiet`` [s]: applied by themselves after that long without a keystroke
    (None: only by Enter or an Apply button)."""

    def __init__(self, fields: Mapping[str, TypedField], quiet: float | None = None) -> None:
        self.fields = dict(fields)
        self.quiet = quiet
        self.refusal: Phrase | None = None
        """Why the group's last application was refused (shown until a later success, or until no field holds a
        text of its own any more)."""

    def limit(self, lo: float, hi: float) -> None:
        """Accept values in ``[lo, hi]`` (UI units) in every field from now on (e.g. the stroke changed)."""
        for f in self.fields.values():
            if (f.quantity.lo, f.quantity.hi) != (lo, hi):
                f.quantity = replace(f.quantity, lo=lo, hi=hi)

    def typed(self, key: str, text: str, now: float) -> None:
        """A keystroke in field ``key``."""
        self.fields[key].typed(text, now)

    def sync(self, texts: Mapping[str, object], now: float) -> bool:
        """The fields' texts as the browser holds them now (by key): each one that differs from the field's is a
        keystroke at ``now``. Whether any did (reading every text, a lost or merged event loses nothing)."""
        changed = False
        for key, text in texts.items():
            f = self.fields.get(key)
            if f is not None and isinstance(text, str) and text != f.text:
                f.typed(text, now)
                changed = True
        return changed

    @property
    def typing(self) -> bool:
        """Some field has keystrokes not yet settled."""
        return any(f.state == TYPING for f in self.fields.values())

    def last_typed(self) -> float:
        """Time of the group's last unsettled keystroke (``-inf`` if none)."""
        return max((f.typed_at for f in self.fields.values() if f.state == TYPING), default=-math.inf)

    def wake_at(self) -> float | None:
        """When :meth:`due` may become true or the note should change (the last keystroke plus the quiet time,
        :data:`QUIET` for a group without one), or None if nothing is being typed."""
        if not self.typing:
            return None
        return self.last_typed() + (QUIET if self.quiet is None else self.quiet)

    def due(self, now: float) -> bool:
        """Whether the group applies itself now (it has a quiet time and nobody typed for that long)."""
        return self.quiet is not None and self.typing and now - self.last_typed() >= self.quiet

    def read(self) -> dict[str, float]:
        """Settle the group and return every field's SI value (clean fields: the value in use). A field whose
        text is refused is held with its reason and the whole group is refused with the first one
        (:class:`~tpm_viz.InputError`); then the other typed fields are held too (their text stays)."""
        values: dict[str, float] = {}
        first: TpmVizError | None = None
        for key, f in self.fields.items():
            try:
                values[key] = f.read()
            except TpmVizError as exc:
                f.hold(_phrase(exc))
                first = first or exc
                continue
            if f.own:
                f.hold()
        if first is not None:
            raise first
        return values

    def applied(self) -> None:
        """The values read were accepted: the refusal goes (the fields wait, held, for the values they asked for)."""
        self.refusal = None

    def refused(self, why: Phrase) -> None:
        """The values read were refused as a whole (``why``); the typed texts stay, held."""
        self.refusal = why

    def waiting(self) -> bool:
        """Some field holds a valid text that is not the value in use (an Apply would use it)."""
        return any(f.own and f.problem is None and not f.quantity.means(f.text, f.value) for f in self.fields.values())

    def problem(self) -> bool:
        """Whether the note says that something was refused (the group, or a field's text)."""
        return self.refusal is not None or any(f.problem is not None for f in self.fields.values())

    def show(self, values: Mapping[str, float], force: bool = False) -> dict[str, str]:
        """The values in use [SI] by key: the texts to write, by key (see :meth:`TypedField.show`). With ``force``
        (new values asked for elsewhere, e.g. the paper's), or when the texts it was about were all replaced by the
        values in use, an earlier refusal goes."""
        owned = [f for f in self.fields.values() if f.own]
        out = {}
        for key, value in values.items():
            text = self.fields[key].show(value, force)
            if text is not None:
                out[key] = text
        if force or (owned and not any(f.own for f in owned)):
            self.refusal = None
        return out

    def lines(self, now: float, extra: Iterable[Phrase | None] = ()) -> list[Phrase]:
        """The note under the group: the group's refusal, each field's line once its typing is quiet (or
        settled), then ``extra`` (plausibility notes)."""
        quiet = QUIET if self.quiet is None else self.quiet
        out = [] if self.refusal is None else [self.refusal]
        for f in self.fields.values():
            if f.state == TYPING and now - f.typed_at < quiet:
                continue
            line = f.line(pending=self.quiet is None)
            if line is not None:
                out.append(line)
        return out + [p for p in extra if p is not None]


def force_note(tau_max: float | None) -> Phrase | None:
    """A note when the largest actuator force [N] is beyond ten times :data:`FORCE_TYPICAL` (2 kN), else None."""
    if tau_max is None:
        return None
    return plausibility(float(tau_max), "|τ|", "N", typical=FORCE_TYPICAL, factor=10.0)


def duration_note(duration: float | None) -> Phrase | None:
    """A note when a trajectory lasts less than :data:`SHORT_DURATION` [s], else None."""
    if duration is None or not math.isfinite(duration) or duration >= SHORT_DURATION:
        return None
    return Phrase(
        "note: T = {ms} ms is very short: the forces grow as 1/T² (check that T is in seconds)",
        ms=_compact(duration * 1e3),
    )
