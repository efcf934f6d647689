"""The words of the exercises (HTML, in a tab's language): a card's prompt and its result line, and the lecturer's
table. Formatting only; every text that is not a literal of this module (a prompt with its numbers, feedback, an
answer a student typed, a label) is escaped with :func:`html.escape`.

A result that has just arrived carries a ``data-say`` stamp: the page script reads it out once in its live region
(:mod:`tpm_viz.viserkit.page`), as it does the pose banner.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass

from tpm_viz.app.exercises.model import AttemptRule, Exercise, Kind
from tpm_viz.classroom.resultsdb import Row, Summary
from tpm_viz.classroom.text import num
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, T, say

__all__ = ["Mine", "how_phrase", "prompt_html", "result_html", "rule_phrase", "table_html"]

GRADING = T("Grading…")
WAITING = T("Preparing your numbers…")
NO_EXERCISES = T("No exercises in these lessons.")
NONE_YET = T("No graded answers yet.")
OWN, CLASS = T("own"), T("class")
HEADERS = (T("Student"), T("Exercise"), T("Variant"), T("Attempts"), T("Best"), T("Last answer"))
EXAMPLES = {"mm": "0.15 m", "m": "150 mm", "N": "0.2 kN", "kN": "200 N", "deg": "0.52 rad", "rad": "30°"}
EXAMPLES |= {"Hz": "62.8 rad/s", "s": "500 ms", "mm/s": "0.1 m/s", "m/s": "100 mm/s"}
"""An answer in another unit of the quantity, by the exercise's unit (:func:`tpm_viz.core.numbers.parse_quantity`)."""
SHOWN_ANSWERS = 5
"""A card lists the student's last this many answers."""
_BOX = "font-size:0.85em;line-height:1.45;color:#1e293b"
_HEAD = _BOX + ";padding-bottom:6px"  # room for the focused answer box's outline under it
_RED, _GREEN, _SLATE = "#991b1b", "#166534", "#334155"
_NOWRAP = ' style="text-align:left;padding:1px 3px;white-space:nowrap;vertical-align:top"'
_WRAP = ' style="text-align:left;padding:1px 3px;overflow-wrap:anywhere;vertical-align:top"'
"""Table cells: a label, a number or a word on one line; an exercise id and an answer may break anywhere."""


@dataclass
class Mine:
    """One exercise as a tab's student has it: the prompt (None until the tab knows who it is, or ``problem``), the
    counted attempts at the current seed, and what the last submission got."""

    exercise: Exercise
    seed: int | None = None
    prompt: Phrase | None = None
    problem: Phrase | None = None
    attempts: tuple[Row, ...] = ()
    score: float | None = None
    feedback: Phrase | None = None
    error: Phrase | None = None  # a format error (no attempt used) or why it was not graded
    refused: bool = False  # ``error`` is a refusal (not graded), not a format error
    grading: bool = False
    stamp: str = ""  # set when a result arrives: the page reads it out once

    @property
    def left(self) -> int | None:
        """Attempts left at this seed (None: unlimited)."""
        return self.exercise.attempts.left(len(self.attempts))


def how_phrase(exercise: Exercise) -> Phrase:
    """How to type an answer to ``exercise``."""
    if exercise.kind is Kind.POSE:
        return T("Answer p1, p2 in mm (for example -35; 20), or drag the platform and press Use current pose.")
    if exercise.kind is Kind.GAINS:
        return T("Answer ω_n in Hz and ζ (for example 10; 0.7); it is graded by a simulation, in a moment.")
    if exercise.kind is Kind.CHOICE:
        return T("Answer with the number of an option.")
    if not exercise.unit:
        return T("Answer with a number.")
    example = EXAMPLES.get(exercise.unit)
    if example is None:
        return Phrase("Answer in {unit}.", unit=exercise.unit)
    return Phrase(
        "Answer in {unit}; another unit of its quantity is read too ({example}).", unit=exercise.unit, example=example
    )


def rule_phrase(rule: AttemptRule) -> Phrase:
    """The attempt rule in one line."""
    if rule.ladder is None:
        return T("Homework: unlimited attempts; the best counts.")
    worth = ", ".join(num(x, "g") for x in rule.ladder)
    return Phrase("Exam: {n} attempt(s), worth {worth}; the best counts.", n=len(rule.ladder), worth=worth)


def prompt_html(mine: Mine, lang: Lang) -> Html:
    """The card's head: title, prompt with the student's numbers, how to answer, the attempt rule."""
    ex = mine.exercise
    body = mine.problem or mine.prompt or WAITING
    how = f"{say(lang, how_phrase(ex))} {say(lang, rule_phrase(ex.attempts))}"
    return Html(
        f'<div data-q="exercise-prompt" data-x="{html.escape(ex.id)}" lang="{lang.value}" style="{_HEAD}">'
        f"<b>{html.escape(ex.title.get(lang))}</b>"
        f'<p style="margin:2px 0 4px 0">{html.escape(say(lang, body))}</p>'
        f'<div style="color:{_SLATE};font-size:0.9em">{html.escape(how)}</div></div>'
    )


def _attempts_line(mine: Mine) -> Phrase | None:
    n = len(mine.attempts)
    if n == 0:
        return None
    best = num(AttemptRule.best(r.score for r in mine.attempts), ".2f")
    left = mine.left
    if left is None:
        return Phrase("{n} attempt(s), best score {best}; unlimited attempts.", n=n, best=best)
    if left == 0:
        return Phrase("{n} attempt(s), best score {best}; no attempts left.", n=n, best=best)
    return Phrase("{n} attempt(s), best score {best}; {left} attempt(s) left.", n=n, best=best, left=left)


def _answers(mine: Mine, lang: Lang) -> Html:
    shown = mine.attempts[-SHOWN_ANSWERS:]
    if not shown:
        return Html("")
    items = "; ".join(f"{r.attempt}) {r.answer} → {num(r.score, '.2f')}" for r in shown)
    line = say(lang, Phrase("Your answers: {items}", items=items))
    return Html(f'<div style="color:{_SLATE};font-size:0.9em">{html.escape(line)}</div>')


def result_html(mine: Mine, lang: Lang) -> Html:
    """The card's result: grading, the score and feedback (or the format error: no attempt used), the attempts."""
    lines: list[str] = []
    if mine.grading:
        lines.append(f'<div style="color:{_SLATE}"><b>{html.escape(say(lang, GRADING))}</b></div>')
    elif mine.error is not None:
        why = mine.error
        said = (
            Phrase("Not graded: {why}", why=why)
            if mine.refused
            else Phrase("Not read: {why}. No attempt used.", why=why)
        )
        text = say(lang, said)
        lines.append(f'<div data-q="exercise-error" style="color:{_RED}">{html.escape(text)}</div>')
    elif mine.score is not None:
        colour = _GREEN if mine.score >= 1.0 else _RED if mine.score == 0.0 else "#92400e"
        score = say(lang, Phrase("Score {score}: {feedback}", score=num(mine.score, ".2f"), feedback=mine.feedback))
        lines.append(f'<div data-q="exercise-score" style="color:{colour}"><b>{html.escape(score)}</b></div>')
    count = _attempts_line(mine)
    if count is not None:
        lines.append(f'<div data-q="exercise-attempts">{html.escape(say(lang, count))}</div>')
    lines.append(_answers(mine, lang))
    say_it = f' data-say="{html.escape(mine.stamp)}"' if mine.stamp else ""
    body = "".join(lines)
    return Html(
        f'<div data-q="exercise-result" data-x="{html.escape(mine.exercise.id)}"{say_it} style="{_BOX}">{body}</div>'
    )


def student_phrase(number: int) -> Phrase:
    """A student's label (``Student 7``) in the tab's language."""
    return Phrase("Student {number}", number=number)


def table_html(lines: Sequence[Summary], total: int, status: Phrase, lang: Lang) -> Html:
    """The lecturer's table: one line per student, exercise and variant, the latest answered first."""
    head = f'<div data-q="results-status" style="color:{_SLATE}">{html.escape(say(lang, status))}</div>'
    if not lines:
        return Html(f'<div data-q="results" style="{_BOX}">{head}<div>{html.escape(say(lang, NONE_YET))}</div></div>')
    cells = "".join(f"<th{_NOWRAP}>{html.escape(say(lang, h))}</th>" for h in HEADERS)
    rows = []
    for line in lines:
        values = (
            say(lang, student_phrase(line.number)),
            line.exercise,
            say(lang, CLASS if line.shared else OWN),
            str(line.attempts),
            num(line.best, ".2f"),
            line.answer,
        )
        tds = (f"<td{_WRAP if k in (1, 5) else _NOWRAP}>{html.escape(v)}</td>" for k, v in enumerate(values))
        rows.append("<tr>" + "".join(tds) + "</tr>")
    more = ""
    if total > len(lines):
        note = Phrase("The latest {shown} of {total} lines; the CSV has them all.", shown=len(lines), total=total)
        more = f"<div>{html.escape(say(lang, note))}</div>"
    table = (
        f'<table style="border-collapse:collapse;font-size:0.92em;font-variant-numeric:tabular-nums"><tr>{cells}</tr>'
    )
    return Html(
        f'<div data-q="results" style="{_BOX};overflow-x:auto">{head}{table}{"".join(rows)}</table>{more}</div>'
    )
