"""A lesson's exercises as the offline page carries them (issue 39): the prompt is ``tpm-viz exercise show``'s, the
reference its ``--reveal`` answer, and each ``answer`` mistake's value is one that ``tpm-viz exercise grade`` itself
recognises as that mistake (the command line is the independent route: the page only carries numbers)."""

from __future__ import annotations

import contextlib
import io
import json
import math

import pytest

from tpm_viz.app.lessons import DEMOS
from tpm_viz.cli import main
from tpm_viz.core.words import Lang
from tpm_viz.media.page_exercises import exercise_entry, lesson_exercises

EXERCISES = [ex for demo in DEMOS for ex in demo.exercises]


def cli(*argv: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(list(argv)) == 0
    return json.loads(out.getvalue())


def finite(value: object) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(finite(v) for v in value.values())
    if isinstance(value, list):
        return all(finite(v) for v in value)
    return True


@pytest.mark.parametrize("lang", list(Lang))
@pytest.mark.parametrize("seed", [0, 11])
@pytest.mark.parametrize("exercise", EXERCISES, ids=lambda ex: ex.id)
def test_the_prompt_is_the_one_exercise_show_prints(exercise, seed, lang):
    entry = exercise_entry(exercise, seed, lang)
    shown = cli("exercise", "show", exercise.id, "--seed", str(seed), "--lang", lang.value, "--reveal")
    assert entry["prompt"] == shown["prompt"]
    assert entry["seed"] == seed and entry["graded"] == (exercise.kind.value != "gains")
    json.dumps(entry, allow_nan=False)
    assert finite(entry)
    if entry["kind"] == "number":
        assert entry["ref"] == shown["answer"][0]
        assert (entry["rtol"], entry["atol"]) == (shown["rtol"], shown["atol"])
    if entry["kind"] == "choice":
        assert [o["key"] for o in entry["options"]].index(entry["right"]) + 1 == shown["answer"][0]


@pytest.mark.parametrize("exercise", [ex for ex in EXERCISES if ex.kind.value == "number"], ids=lambda ex: ex.id)
def test_each_answer_mistake_the_page_carries_is_graded_as_that_mistake(exercise):
    """Typed at full precision, the value the page carries for an ``answer`` mistake gets that mistake's score and
    feedback from ``tpm-viz exercise grade`` (unless an earlier rule claims it: the right answer or an earlier
    mistake, as the grader checks them in order)."""
    for seed in (0, 3):
        entry = exercise_entry(exercise, seed, Lang.EN)
        for k, mistake in enumerate(entry["mistakes"]):
            if mistake["value"] is None:
                continue
            got = cli("exercise", "grade", exercise.id, "--seed", str(seed), f"--answer={mistake['value']!r}")
            earlier = [m for m in entry["mistakes"][:k] if m["feedback"] == got["feedback"]]
            if got["feedback"] == entry["correct"] or earlier:
                continue
            assert (got["score"], got["feedback"]) == (mistake["score"], mistake["feedback"])


def test_a_lesson_without_exercises_has_none_and_a_gains_exercise_carries_only_its_prompt():
    assert lesson_exercises((), 0, Lang.EN) == []
    gains = next(ex for ex in EXERCISES if ex.kind.value == "gains")
    entry = exercise_entry(gains, 0, Lang.KO)
    assert not entry["graded"] and "ref" not in entry and "mistakes" not in entry
