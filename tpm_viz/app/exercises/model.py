"""The records of the exercise engine: an exercise as read from a lesson file, a student's variant, a grade, a result.

All frozen (hashable where they are keys of a cache). Lengths, masses, forces in SI inside (m, kg, N, rad); an
answer is compared in the unit the exercise declares (``unit``). The words of a file (title, prompt, feedback) come
in English and Korean with the file: :class:`FileText` is a :class:`~tpm_viz.core.words.Phrase` that carries its own
translations instead of looking them up in ``assets/words/ko.toml``.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Lang, Phrase

__all__ = [
    "INPUTS",
    "MAX_ANSWER",
    "SIGNED",
    "AttemptRule",
    "Draw",
    "Exercise",
    "FileText",
    "Grade",
    "Kind",
    "Mistake",
    "Option",
    "Result",
    "Texts",
    "Variant",
    "decimals_of",
    "shown_unit",
]

MAX_ANSWER = 200
"""Longest answer text read [characters]; a longer one is a format error."""

INPUTS: dict[str, tuple[str, float]] = {
    "p1": ("mm", 1e3),
    "p2": ("mm", 1e3),
    "ddp1": ("m/s²", 1.0),
    "ddp2": ("m/s²", 1.0),
    "tol": ("N", 1.0),
    "force_limit": ("N", 1.0),
    "mass_error": ("%", 100.0),
    "t1": ("s", 1.0),
    "t2": ("s", 1.0),
}
"""The inputs a variant may draw besides the parameters: name -> (unit shown in a prompt, SI -> shown scale).
Platform position ``p`` [m], platform acceleration ``p̈`` [m/s²] (``ṗ = 0`` wherever it is drawn), a force
tolerance ``tol`` [N], the actuator ``force_limit`` [N], the controller's relative ``mass_error`` [-] on ``m_a``,
``m_b``, ``m_p`` (shown in %, with its sign), path durations ``t1``, ``t2`` [s]."""
SIGNED = frozenset({"mass_error"})
"""Inputs a prompt shows with their sign (``+20``: the model is heavier than the mechanism)."""


def decimals_of(value: float) -> int:
    """The fewest decimals (at most 6) that show ``value`` as it is (``0.5`` -> 1, ``260.0`` -> 0)."""
    for n in range(7):
        if abs(round(value, n) - value) <= 1e-9 * max(1.0, abs(value)):
            return n
    return 6


def shown_unit(name: str) -> tuple[str, float]:
    """``(unit, scale)`` a prompt shows the quantity ``name`` in (a parameter: mm or kg; an input: :data:`INPUTS`)."""
    if name in PARAM_INFO:
        return PARAM_INFO[name]["ui_unit"], PARAM_INFO[name]["ui_scale"]
    return INPUTS[name]


class Kind(enum.StrEnum):
    """What an answer is."""

    NUMBER = "number"
    """One number in the exercise's ``unit``, compared with the reference by the relabs rule."""
    POSE = "pose"
    """A platform position ``p1, p2`` in mm; the grader checks the pose itself (every correct pose scores)."""
    GAINS = "gains"
    """``ω_n`` [Hz] and ``ζ`` of the computed-torque law; the grader simulates the closed loop."""
    CHOICE = "choice"
    """One of the exercise's options (its key or its number)."""


@dataclass(frozen=True)
class Texts:
    """A text of a file in the UI's languages (``ko`` "": the English is shown)."""

    en: str
    ko: str = ""

    def get(self, lang: Lang) -> str:
        return (self.ko or self.en) if lang is Lang.KO else self.en

    def phrase(self, **values: object) -> FileText:
        """The text with its ``{placeholders}`` to fill, as a phrase."""
        return FileText(self, **values)


class FileText(Phrase):
    """A :class:`~tpm_viz.core.words.Phrase` whose translations come from a file (:class:`Texts`), not the catalogue."""

    texts: Texts

    def __init__(self, texts: Texts, /, **values: object) -> None:
        super().__init__(texts.en, **values)
        object.__setattr__(self, "texts", texts)

    def render(self, lang: Lang = Lang.EN) -> str:
        values = {k: (v.render(lang) if isinstance(v, Phrase) else v) for k, v in self.values.items()}
        for text in (self.texts.get(lang), self.texts.en):
            try:
                return text.format(**values)
            except (KeyError, IndexError, ValueError, AttributeError, TypeError):
                continue
        return self.texts.en

    def __reduce__(self) -> tuple[Any, tuple[Any, dict[str, object]]]:
        return _file_text, (self.texts, dict(self.values))

    def __hash__(self) -> int:
        return hash((self.texts, super().__hash__()))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, FileText) and self.texts == other.texts and super().__eq__(other)


def _file_text(texts: Texts, values: dict[str, object]) -> FileText:
    return FileText(texts, **values)


@dataclass(frozen=True)
class Draw:
    """One quantity of a variant: a parameter (``l_a``, ``m_p``, ...) or an input (:data:`INPUTS`), drawn from
    ``values`` [SI] (one value: fixed), shown in a prompt with ``decimals`` digits in its unit (:func:`shown_unit`)."""

    name: str
    values: tuple[float, ...]
    decimals: int


@dataclass(frozen=True)
class Mistake:
    """A mistake students make, recognised in a wrong answer: the answer is the correct one times ``factor`` (it is
    right once divided by ``factor``: a wrong sign -1; metres in a field in mm 0.001; radians in a field in degrees
    π/180), or it is the value of another computation ``answer`` (τ₂ for τ₁, the distance l_a for the coordinate);
    scored ``score`` < 1 with ``feedback``."""

    feedback: Texts
    score: float = 0.0
    factor: float | None = None
    answer: str | None = None


@dataclass(frozen=True)
class Option:
    """An option of a choice: its ``key`` (what the computation returns), its ``label``, and the ``feedback``
    shown when it is chosen and wrong (none: a generic line)."""

    key: str
    label: Texts
    feedback: Texts | None = None


@dataclass(frozen=True)
class AttemptRule:
    """How attempts count: an exam ``ladder`` (attempt ``k`` earns at most ``ladder[k-1]`` of the score, no attempt
    beyond it: PrairieLearn's 10, 7, 5 points as ``(1.0, 0.7, 0.5)``), or None: homework (unlimited attempts, each
    worth the full score). The exercise's score is the best of its attempts either way (:meth:`best`)."""

    ladder: tuple[float, ...] | None = None

    @property
    def max_attempts(self) -> int | None:
        """How many attempts count (None: unlimited)."""
        return None if self.ladder is None else len(self.ladder)

    def factor(self, attempt: int) -> float:
        """The most attempt ``attempt`` (1-based) may earn; :class:`InputError` if there is no such attempt."""
        if isinstance(attempt, bool) or not isinstance(attempt, int) or attempt < 1:
            raise InputError(Phrase("the attempt must be a whole number from 1, got {got}", got=repr(attempt)))
        if self.ladder is None:
            return 1.0
        if attempt > len(self.ladder):
            raise InputError(Phrase("attempt {k}: this exercise allows {n} attempts", k=attempt, n=len(self.ladder)))
        return self.ladder[attempt - 1]

    def left(self, used: int) -> int | None:
        """Attempts left after ``used`` counted ones (None: unlimited)."""
        return None if self.ladder is None else max(0, len(self.ladder) - used)

    @staticmethod
    def best(scores: Iterable[float | None]) -> float | None:
        """The exercise's score: the best of the attempts' scores (after the ladder); None before any."""
        real = [s for s in scores if s is not None]
        return max(real) if real else None

    @staticmethod
    def latest(scores: Iterable[float | None]) -> float | None:
        """The score of the last graded attempt; None before any."""
        real = [s for s in scores if s is not None]
        return real[-1] if real else None


@dataclass(frozen=True)
class Exercise:
    """One exercise of a lesson file (``assets/lessons/README.md``; read by :mod:`.reader`)."""

    id: str
    kind: Kind
    answer: str  # the computation that gives the reference (a task of :mod:`.tasks` or :mod:`.gains`)
    title: Texts
    prompt: Texts
    unit: str = ""  # the answer's unit ("" dimensionless); pose: mm; gains: Hz (and ζ without unit)
    rtol: float = 0.01
    atol: float | str = 1e-8  # in the answer's unit (pose: the checked quantity's), or the name of a drawn input
    draws: tuple[Draw, ...] = ()
    mistakes: tuple[Mistake, ...] = ()
    options: tuple[Option, ...] = ()
    attempts: AttemptRule = AttemptRule()
    lesson: str = ""  # the key of its lesson
    base: tuple[tuple[str, float], ...] = ()  # the lesson's parameter overrides (SI)
    source: str = ""  # the file

    @property
    def heavy(self) -> bool:
        """Whether grading runs a simulation (``gains``: up to a second; submit it to the fair worker)."""
        return self.kind is Kind.GAINS


@dataclass(frozen=True)
class Variant:
    """A student's numbers for an exercise: the mechanism ``params`` and the drawn ``inputs`` [SI]."""

    exercise: str
    seed: int
    params: Params
    inputs: tuple[tuple[str, float], ...] = ()

    def __getitem__(self, name: str) -> float:
        if name in PARAM_INFO:
            return float(getattr(self.params, name))
        for key, value in self.inputs:
            if key == name:
                return value
        raise InputError(Phrase("the variant has no {name}", name=name))

    def values(self) -> dict[str, float]:
        """Every parameter and input [SI] by the command line's names (``a, b, l_a, ..., p1, ddp1, tol, ...``)."""
        out = {name: float(getattr(self.params, name)) for name in PARAM_INFO}
        out.update(self.inputs)
        return out


@dataclass(frozen=True)
class Grade:
    """What one submission got. A format error (``format_error`` set) uses no attempt and has no score."""

    score: float | None  # in [0, 1], after the attempt ladder; None for a format error
    raw: float | None  # before the ladder
    format_error: Phrase | None
    feedback: Phrase | None  # one line: the matched mistake, or why it is right or wrong
    attempts_used: int  # 0 (format error) or 1
    attempts_left: int | None  # after this submission (None: unlimited)
    values: tuple[float, ...] = ()  # the answer as read, in the exercise's unit (choice: empty)
    choice: str = ""  # the option key chosen (choice only)

    def json(self, lang: Lang = Lang.EN) -> dict[str, object]:
        """The command line's object: ``score``, ``format_error``, ``feedback``, ``attempts_used``."""
        return {
            "score": self.score,
            "format_error": None if self.format_error is None else self.format_error.render(lang),
            "feedback": None if self.feedback is None else self.feedback.render(lang),
            "attempts_used": self.attempts_used,
        }


@dataclass(frozen=True)
class Result:
    """One graded submission as the results store keeps it (format errors are not attempts: not stored)."""

    student: str  # the identity's stored hash (``tpm_viz.classroom.identity.hashed``) or a label
    exercise: str
    seed: int
    attempt: int  # 1-based, counted attempts only
    answer: str  # as typed, at most MAX_ANSWER characters
    score: float  # after the ladder, [0, 1]
    time: float  # seconds since the epoch

    def __post_init__(self) -> None:
        if not (math.isfinite(self.score) and 0.0 <= self.score <= 1.0):
            raise InputError(Phrase("a score must be from 0 to 1, got {got}", got=repr(self.score)))
        object.__setattr__(self, "answer", str(self.answer)[:MAX_ANSWER])
