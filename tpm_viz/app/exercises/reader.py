"""``[[exercise]]`` tables of a lesson file -> :class:`~tpm_viz.app.exercises.model.Exercise` records.

Called by the lesson reader (:func:`tpm_viz.app.lesson_files.load_lesson`) on the text and data it has read with
the bounded reader, so an exercise with a mistake refuses its lesson file with ``file:line: what is wrong`` like
any other key (the format: ``assets/lessons/README.md``). Checked here: known keys and types; an ``id`` of lower-case
letters, digits and dashes; English (and optional Korean) title and prompt whose ``{placeholders}`` are parameters,
drawn inputs or the computation's shown values; a computation ``answer`` of the exercise's kind and every input it
needs drawn; a unit of the computation's quantity; tolerances; the attempt rule; draws (a number, a range
``{ min, max, step }`` or ``{ values = [...] }``, in SI, at most :data:`MAX_GRID` values); mistakes (``factor`` or
another computation ``answer``, a score below 1, feedback); the options of a choice (one per key the computation
may return).
"""

from __future__ import annotations

import itertools
import math
import re
import string

from tpm_viz.app.exercises.lines import key_lines
from tpm_viz.app.exercises.model import (
    INPUTS,
    AttemptRule,
    Draw,
    Exercise,
    Kind,
    Mistake,
    Option,
    Texts,
    decimals_of,
    shown_unit,
)
from tpm_viz.app.exercises.registry import TASKS, shows
from tpm_viz.app.exercises.tasks import CHOICE_TASKS, NumberTask
from tpm_viz.app.lesson_toml import LessonError
from tpm_viz.app.readouts import reason
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.numbers import unit_factor
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Phrase

__all__ = ["KEYS", "MAX_EXERCISES", "MAX_GRID", "key_lines", "read_exercises"]

KEYS = ("id", "title", "prompt", "kind", "unit", "answer", "rtol", "atol", "attempts", "draw", "mistake", "option")
"""The keys of an ``[[exercise]]`` table."""
MAX_EXERCISES = 20
"""Most exercises in one lesson file."""
MAX_GRID = 10_000
"""Most values one draw may choose from."""
MAX_LADDER = 10
"""Longest attempt ladder."""
_ID = re.compile(r"[a-z0-9][a-z0-9-]{0,62}")


class _Table:
    """One exercise's values and where they are written."""

    def __init__(self, lines: dict[tuple[object, ...], int], index: int, values: dict, id_: str = "") -> None:
        self.lines, self.index, self.values, self.id = lines, index, values, id_

    def fail(self, message: Phrase, *where: object) -> LessonError:
        path: tuple[object, ...] = ("exercise", self.index, *where)
        while path and path not in self.lines:
            path = path[:-1]
        named = Phrase("exercise {id}: {why}", id=self.id, why=message) if self.id else message
        return LessonError(named, self.lines.get(path, 1))


def _texts(t: _Table, value: object, *where: object, allowed: set[str]) -> Texts:
    name = ".".join(str(w) for w in where)
    if not isinstance(value, dict) or "en" not in value:
        raise t.fail(
            Phrase('{name} must be a table of languages with en: {{ en = "...", ko = "..." }}', name=name), *where
        )
    for lang, text in value.items():
        if lang not in ("en", "ko"):
            raise t.fail(Phrase("unknown key {name}.{key}; known: en, ko", name=name, key=lang), *where, lang)
        if not isinstance(text, str) or not text.strip():
            raise t.fail(Phrase("{name}.{key} must be a non-empty string", name=name, key=lang), *where, lang)
        try:
            fields = list(string.Formatter().parse(text))
        except ValueError:
            raise t.fail(Phrase("{name}.{key}: unbalanced braces", name=name, key=lang), *where, lang) from None
        for _, field, spec, conversion in fields:
            if field is not None and (field not in allowed or spec or conversion):
                raise t.fail(
                    Phrase(
                        "{name}.{key}: unknown placeholder {field}; known: {known}",
                        name=name,
                        key=lang,
                        field="{" + field + "}",
                        known=", ".join(sorted(allowed)),
                    ),
                    *where,
                    lang,
                )
    return Texts(" ".join(value["en"].split()), " ".join(value.get("ko", "").split()))


def _number(t: _Table, value: object, lo: float, hi: float, *where: object) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or not lo <= value <= hi
    ):
        raise t.fail(
            Phrase(
                "{name} must be a number from {lo:g} to {hi:g}, got {got}",
                name=".".join(map(str, where)),
                lo=lo,
                hi=hi,
                got=repr(value),
            ),
            *where,
        )
    return float(value)


def _draw(t: _Table, name: str, spec: object, base: Params) -> Draw:
    if name not in PARAM_INFO and name not in INPUTS:
        known = ", ".join([*PARAM_INFO, *INPUTS])
        raise t.fail(Phrase("unknown key draw.{name}; known: {known}", name=name, known=known), "draw", name)
    scale = shown_unit(name)[1]
    if isinstance(spec, dict) and "values" in spec:
        if set(spec) != {"values"} or not isinstance(spec["values"], list) or not 1 <= len(spec["values"]) <= MAX_GRID:
            raise t.fail(
                Phrase("draw.{name} must be {{ values = [...] }} with 1 to {most} numbers", name=name, most=MAX_GRID),
                "draw",
                name,
            )
        values = tuple(_number(t, v, -1e6, 1e6, "draw", name) for v in spec["values"])
    elif isinstance(spec, dict):
        if set(spec) != {"min", "max", "step"}:
            raise t.fail(
                Phrase("draw.{name} must be a number, {{ min, max, step }} or {{ values = [...] }}", name=name),
                "draw",
                name,
            )
        lo, hi = (_number(t, spec[k], -1e6, 1e6, "draw", name, k) for k in ("min", "max"))
        step = _number(t, spec["step"], 1e-12, 1e6, "draw", name, "step")
        count = math.floor((hi - lo) / step + 1e-9) + 1
        if hi < lo or count > MAX_GRID:
            raise t.fail(
                Phrase("draw.{name}: min <= max and at most {most} steps", name=name, most=MAX_GRID), "draw", name
            )
        values = tuple(float(f"{lo + k * step:.12g}") for k in range(count))
        decimals = max(decimals_of(lo * scale), decimals_of(step * scale))
        return _checked(t, Draw(name, values, decimals), base)
    else:
        values = (_number(t, spec, -1e6, 1e6, "draw", name),)
    return _checked(t, Draw(name, values, max(decimals_of(v * scale) for v in values)), base)


def _checked(t: _Table, draw: Draw, base: Params) -> Draw:
    if draw.name in PARAM_INFO:
        for value in (min(draw.values), max(draw.values)):
            try:
                base.replace(**{draw.name: value})
            except TpmVizError as exc:
                raise t.fail(Phrase("draw.{name}: {why}", name=draw.name, why=reason(exc)), "draw", draw.name) from None
    return draw


def _attempts(t: _Table) -> AttemptRule:
    value = t.values.get("attempts", "homework")
    if value == "homework":
        return AttemptRule()
    ok = isinstance(value, list) and 1 <= len(value) <= MAX_LADDER
    ladder = tuple(_number(t, v, 0.0, 1.0, "attempts") for v in value) if ok else ()
    if not ok or ladder[0] <= 0 or any(b > a for a, b in itertools.pairwise(ladder)):
        raise t.fail(
            Phrase(
                'attempts must be "homework" or a falling list of 1 to {most} scores from 1 down to 0, '
                "such as [1.0, 0.7, 0.5]",
                most=MAX_LADDER,
            ),
            "attempts",
        )
    return AttemptRule(ladder)


def _unit(t: _Table, kind: Kind, task: object) -> str:
    unit = t.values.get("unit", None)
    fixed = {Kind.POSE: "mm", Kind.GAINS: "Hz", Kind.CHOICE: ""}
    if kind in fixed:
        if unit is not None and unit != fixed[kind]:
            raise t.fail(Phrase("a {kind} answer has the unit {unit}", kind=kind.value, unit=repr(fixed[kind])), "unit")
        return fixed[kind]
    if not isinstance(unit, str):
        raise t.fail(Phrase('a number needs its unit (unit = "N", "mm", "deg", or "" for none)'), "unit")
    quantity = task.quantity if isinstance(task, NumberTask) else None
    try:
        unit_factor(unit, quantity, "unit", t.values["answer"])
    except TpmVizError as exc:
        raise t.fail(reason(exc), "unit") from None
    if quantity is not None and not unit:
        raise t.fail(
            Phrase("{answer} is a {quantity}: give its unit", answer=t.values["answer"], quantity=quantity), "unit"
        )
    return unit


def _tolerances(t: _Table, kind: Kind, drawn: set[str]) -> tuple[float, float | str]:
    if kind in (Kind.GAINS, Kind.CHOICE):
        for key in ("rtol", "atol"):
            if key in t.values:
                raise t.fail(Phrase("{key} does not apply to a {kind} answer", key=key, kind=kind.value), key)
        return 0.0, 0.0
    rtol = _number(t, t.values.get("rtol", 0.01 if kind is Kind.NUMBER else 0.0), 0.0, 0.5, "rtol")
    atol = t.values.get("atol", 1e-8)
    if isinstance(atol, str):
        if atol not in drawn or atol not in INPUTS:
            raise t.fail(Phrase("atol names no drawn input: {got}", got=repr(atol)), "atol")
        return rtol, atol
    return rtol, _number(t, atol, 0.0, 1e6, "atol")


def _mistakes(t: _Table, kind: Kind, allowed: set[str]) -> tuple[Mistake, ...]:
    raw = t.values.get("mistake", [])
    if not isinstance(raw, list) or not all(isinstance(m, dict) for m in raw):
        raise t.fail(Phrase("mistakes are tables: [[exercise.mistake]]"), "mistake")
    if raw and kind is Kind.CHOICE:
        raise t.fail(Phrase("a choice has no mistakes: give each option its feedback"), "mistake")
    out = []
    for j, m in enumerate(raw):
        for key in m:
            if key not in ("factor", "answer", "score", "feedback"):
                raise t.fail(
                    Phrase("unknown key mistake.{key}; known: factor, answer, score, feedback", key=key),
                    "mistake",
                    j,
                    key,
                )
        if ("factor" in m) == ("answer" in m):
            raise t.fail(Phrase("a mistake needs factor or answer (one of them)"), "mistake", j)
        factor = answer = None
        if "factor" in m:
            factor = _number(t, m["factor"], -1e6, 1e6, "mistake", j, "factor")
            if factor == 0:
                raise t.fail(Phrase("mistake.factor must not be 0"), "mistake", j, "factor")
        elif kind is Kind.GAINS or m["answer"] not in TASKS[kind] or m["answer"] == t.values["answer"]:
            raise t.fail(
                Phrase(
                    "mistake.answer: {got} is no other {kind} computation; known: {known}",
                    got=repr(m["answer"]),
                    kind=kind.value,
                    known=", ".join(TASKS[kind]),
                ),
                "mistake",
                j,
                "answer",
            )
        else:
            answer = m["answer"]
        score = _number(t, m.get("score", 0.0), 0.0, 0.99, "mistake", j, "score")
        if "feedback" not in m:
            raise t.fail(Phrase("a mistake needs its feedback"), "mistake", j)
        feedback = _texts(t, m["feedback"], "mistake", j, "feedback", allowed=allowed)
        out.append(Mistake(feedback=feedback, score=score, factor=factor, answer=answer))
    return tuple(out)


def _options(t: _Table, kind: Kind, allowed: set[str]) -> tuple[Option, ...]:
    raw = t.values.get("option", [])
    if kind is not Kind.CHOICE:
        if raw:
            raise t.fail(Phrase("options belong to a choice"), "option")
        return ()
    if not isinstance(raw, list) or not all(isinstance(o, dict) for o in raw):
        raise t.fail(Phrase("options are tables: [[exercise.option]]"), "option")
    out = []
    for j, o in enumerate(raw):
        if set(o) - {"key", "label", "feedback"} or not isinstance(o.get("key"), str):
            raise t.fail(Phrase("an option has key, label and optional feedback"), "option", j)
        label = _texts(t, o.get("label"), "option", j, "label", allowed=set())
        feedback = _texts(t, o["feedback"], "option", j, "feedback", allowed=allowed) if "feedback" in o else None
        out.append(Option(o["key"], label, feedback))
    keys = [o.key for o in out]
    needed = CHOICE_TASKS[t.values["answer"]].keys
    if sorted(keys) != sorted(needed):
        raise t.fail(Phrase("the options must be exactly {keys}", keys=", ".join(needed)), "option")
    return tuple(out)


def _one(t: _Table, base: Params, lesson: str, base_items: tuple[tuple[str, float], ...], source: str) -> Exercise:
    v = t.values
    for key in v:
        if key not in KEYS:
            raise t.fail(Phrase("unknown key {key}; known: {known}", key=repr(key), known=", ".join(KEYS)), key)
    for key in ("kind", "answer", "title", "prompt"):
        if key not in v:
            raise t.fail(Phrase("missing {key}", key=key))
    if v["kind"] not in [k.value for k in Kind]:
        raise t.fail(
            Phrase(
                "kind must be one of {known}, got {got}", known=", ".join(k.value for k in Kind), got=repr(v["kind"])
            ),
            "kind",
        )
    kind = Kind(v["kind"])
    if not isinstance(v["answer"], str) or v["answer"] not in TASKS[kind]:
        raise t.fail(
            Phrase(
                "answer: {got} is no {kind} computation; known: {known}",
                got=repr(v["answer"]),
                kind=kind.value,
                known=", ".join(TASKS[kind]),
            ),
            "answer",
        )
    task = TASKS[kind][v["answer"]]
    spec = v.get("draw", {})
    if not isinstance(spec, dict):
        raise t.fail(Phrase("draw must be a table: [exercise.draw]"), "draw")
    draws = tuple(_draw(t, name, value, base) for name, value in spec.items())
    drawn = {d.name for d in draws}
    for need in task.needs:
        if need not in drawn:
            raise t.fail(Phrase("{answer} needs draw.{name}", answer=v["answer"], name=need), "draw")
    allowed = set(PARAM_INFO) | drawn | set(shows(task))
    rtol, atol = _tolerances(t, kind, drawn)
    return Exercise(
        id=t.id,
        kind=kind,
        answer=v["answer"],
        title=_texts(t, v["title"], "title", allowed=set()),
        prompt=_texts(t, v["prompt"], "prompt", allowed=allowed),
        unit=_unit(t, kind, task),
        rtol=rtol,
        atol=atol,
        draws=draws,
        mistakes=_mistakes(t, kind, allowed),
        options=_options(t, kind, allowed),
        attempts=_attempts(t),
        lesson=lesson,
        base=base_items,
        source=source,
    )


def read_exercises(
    text: str, data: dict, lesson: str = "", base: tuple[tuple[str, float], ...] = (), source: str = ""
) -> tuple[Exercise, ...]:
    """The exercises of one parsed lesson file (``text`` and ``data`` as :func:`tpm_viz.app.lesson_toml.parse`
    gives them) whose lesson has the key ``lesson`` and the parameter overrides ``base`` [SI]; raises
    :class:`~tpm_viz.app.lesson_toml.LessonError` with the line."""
    raw = data.get("exercise", [])
    lines = key_lines(text)
    if not isinstance(raw, list) or not all(isinstance(e, dict) for e in raw):
        raise LessonError(
            Phrase("exercise must be an array of tables: write [[exercise]]"), lines.get(("exercise",), 1)
        )
    if len(raw) > MAX_EXERCISES:
        raise LessonError(
            Phrase("at most {most} exercises per lesson", most=MAX_EXERCISES), lines.get(("exercise",), 1)
        )
    params = Params.paper().replace(**dict(base))
    out: list[Exercise] = []
    for index, values in enumerate(raw):
        t = _Table(lines, index, values)
        ident = values.get("id")
        if not isinstance(ident, str) or not _ID.fullmatch(ident):
            raise t.fail(
                Phrase(
                    "id must be lower-case letters, digits and dashes (at most 63), got {got}", got=repr(ident)[:70]
                ),
                "id",
            )
        if any(e.id == ident for e in out):
            raise t.fail(Phrase("id {id} is used twice in this file", id=repr(ident)), "id")
        t.id = ident
        out.append(_one(t, params, lesson, base, source))
    return tuple(out)
