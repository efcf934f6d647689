"""Exercises as data: the packaged lessons still load with their ``[[exercise]]`` tables; the issue's four
exercises are there as it defines them; prompts are filled in English and Korean; a table with a mistake refuses
its lesson file with ``file:line: what is wrong``; the README's format example loads and grades."""

from __future__ import annotations

import pathlib
import re

import pytest

from tpm_viz.app.exercises.catalogue import by_id, listed
from tpm_viz.app.exercises.grading import grade, prompt, reference, variant_of
from tpm_viz.app.exercises.model import AttemptRule, Kind
from tpm_viz.app.exercises.reader import KEYS
from tpm_viz.app.exercises.registry import TASKS
from tpm_viz.app.lessons import DEMOS, PROBLEMS, assets_dir, load_lessons
from tpm_viz.core.words import Lang

HANGUL = re.compile("[\uac00-\ud7a3]")

GOOD = """title = "7. Mine"
[text]
en = "A lesson of my own, for the tests."
[pose]
p = [0.0, 0.0]
"""

EXERCISE = """
[[exercise]]
id = "my-force"
kind = "number"
unit = "N"
answer = "tau1"
title = { en = "Force", ko = "힘" }
prompt = { en = "At ({p1}, {p2}) mm with p̈ = ({ddp1}, {ddp2}) m/s², τ1 [N]?", ko = "({p1}, {p2}) mm에서 τ1 [N]은?" }
[exercise.draw]
p1 = { min = -0.05, max = 0.05, step = 0.01 }
p2 = 0.0
ddp1 = { values = [1.0, 2.0] }
ddp2 = 0.0
"""


def test_the_tour_loads_with_at_least_eight_exercises_over_the_six_lessons():
    assert PROBLEMS == ()
    assert len(DEMOS) == 6 and all(demo.exercises for demo in DEMOS)
    ids = [item.exercise.id for item in listed()]
    assert len(ids) >= 8 and len(set(ids)) == len(ids)
    assert {item.lesson_number for item in listed()} == {1, 2, 3, 4, 5, 6}
    assert [item.exercise.id for item in listed(lesson=4)] == ["force-at-pose", "zero-force-pose"]


def test_the_four_exercises_of_the_issue():
    expected = {
        "force-at-pose": (Kind.NUMBER, "N", {"p1", "p2", "ddp1", "ddp2", "m_a", "m_p"}),
        "direct-singularity-diagonal": (Kind.NUMBER, "mm", {"l_a"}),
        "zero-force-pose": (Kind.POSE, "mm", {"ddp1", "ddp2", "tol"}),
        "tune-ctc": (Kind.GAINS, "Hz", {"force_limit", "mass_error"}),
    }
    for ident, (kind, unit, drawn) in expected.items():
        exercise = by_id(ident).exercise
        assert (exercise.kind, exercise.unit) == (kind, unit)
        assert {d.name for d in exercise.draws} == drawn
    assert by_id("zero-force-pose").exercise.atol == "tol"
    assert by_id("force-at-pose").exercise.attempts == AttemptRule((1.0, 0.7, 0.5))
    assert by_id("tune-ctc").exercise.heavy and not by_id("force-at-pose").exercise.heavy


@pytest.mark.parametrize("ident", [item.exercise.id for item in listed()])
def test_prompts_are_filled_in_both_languages(ident):
    exercise = by_id(ident).exercise
    for seed in range(5):
        variant = variant_of(exercise, seed)
        english, korean = (prompt(exercise, variant).render(lang) for lang in (Lang.EN, Lang.KO))
        for text in (english, korean):
            assert "{" not in text and "}" not in text and text.strip() == text
        assert HANGUL.search(korean) and not HANGUL.search(english)
        assert HANGUL.search(exercise.title.get(Lang.KO))
        for draw in exercise.draws:  # every drawn number appears, in the units a prompt shows
            if f"{{{draw.name}}}" in exercise.prompt.en:
                assert re.search(r"-?\d", english)
    assert re.search(r"\d", english)


def test_a_drawn_value_is_shown_as_drawn():
    exercise = by_id("force-at-pose").exercise
    variant = variant_of(exercise, 3)
    text = prompt(exercise, variant).render(Lang.EN)
    p1, p2 = round(variant["p1"] * 1e3), round(variant["p2"] * 1e3)
    assert f"p = ({p1}, {p2}) mm" in text
    assert f"p̈ = ({variant['ddp1']:.1f}, {variant['ddp2']:.1f}) m/s²" in text


def _folder(tmp_path: pathlib.Path, files: dict[str, str]) -> pathlib.Path:
    folder = tmp_path / "lessons"
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder


def test_a_lecturer_s_exercise_loads_and_grades(tmp_path):
    lessons, problems = load_lessons(_folder(tmp_path, {"07-mine.toml": GOOD + EXERCISE}))
    assert problems == ()
    item = by_id("my-force", lessons)
    variant = variant_of(item.exercise, 0)
    (ref,) = reference(item.exercise, variant)
    assert grade(item.exercise, variant, repr(ref)).score == 1.0
    assert item.exercise.attempts.max_attempts is None  # homework by default


BAD = {
    "not_an_array": ('[exercise]\nid = "x"\n', 6, "exercise must be an array of tables"),
    "bad_id": (EXERCISE.replace('"my-force"', '"My Force"'), 8, "id must be lower-case letters"),
    "unknown_key": (EXERCISE.replace('kind = "number"', 'kind = "number"\ncolour = 1'), 10, "unknown key 'colour'"),
    "kind": (EXERCISE.replace('kind = "number"', 'kind = "essay"'), 9, "kind must be one of number, pose"),
    "answer": (EXERCISE.replace('"tau1"', '"tau9"'), 11, "answer: 'tau9' is no number computation"),
    "unit": (
        EXERCISE.replace('unit = "N"', 'unit = "mm"'),
        10,
        "exercise my-force: unit: 'mm' is a length unit, but tau1 is a force in N",
    ),
    "no_unit": (EXERCISE.replace('unit = "N"\n', ""), 7, "a number needs its unit"),
    "placeholder": (EXERCISE.replace("τ1 [N]?", "τ1 [N] at {speed}?"), 13, "unknown placeholder {speed}"),
    "needs": (EXERCISE.replace("ddp2 = 0.0\n", ""), 14, "tau1 needs draw.ddp2"),
    "draw_name": (EXERCISE.replace("\np2 = 0.0", "\nq2 = 0.0"), 16, "unknown key draw.q2"),
    "draw_range": (EXERCISE.replace("step = 0.01", "step = -0.01"), 15, "draw.p1.step must be a number"),
    "draw_param": (
        EXERCISE.replace("\np2 = 0.0", "\np2 = 0.0\nl_a = { min = 0.01, max = 0.3, step = 0.01 }"),
        17,
        "draw.l_a: ",
    ),
    "ladder": (
        EXERCISE.replace('kind = "number"', 'kind = "number"\nattempts = [0.5, 1.0]'),
        10,
        'attempts must be "homework" or a falling list',
    ),
    "mistake_score": (
        EXERCISE + '[[exercise.mistake]]\nfactor = -1.0\nscore = 1.0\nfeedback = { en = "Sign." }\n',
        21,
        "mistake.0.score must be a number from 0 to 0.99",
    ),
    "mistake_both": (
        EXERCISE + '[[exercise.mistake]]\nfactor = -1.0\nanswer = "tau2"\nfeedback = { en = "S" }\n',
        19,
        "a mistake needs factor or answer (one of them)",
    ),
    "mistake_answer": (
        EXERCISE + '[[exercise.mistake]]\nanswer = "tau7"\nfeedback = { en = "S" }\n',
        20,
        "mistake.answer: 'tau7' is no other number computation",
    ),
    "feedback_lang": (
        EXERCISE + '[[exercise.mistake]]\nfactor = 2.0\nfeedback = { en = "S", fr = "S" }\n',
        21,
        "unknown key mistake.0.feedback.fr",
    ),
    "twice": (EXERCISE + EXERCISE, 21, "id 'my-force' is used twice in this file"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_exercise_refuses_its_file_with_the_line(tmp_path, case):
    text, line, says = BAD[case]
    folder = _folder(tmp_path, {"01-ok.toml": GOOD.replace("7. Mine", "1. Fine"), "02-bad.toml": GOOD + text})
    lessons, problems = load_lessons(folder)
    assert [d.title for d in lessons] == ["1. Fine"]
    (problem,) = problems
    assert problem.startswith(f"{folder / '02-bad.toml'}:{line}: "), problem
    assert says in problem, problem
    assert problem.phrase.render(Lang.KO) != str(problem)  # the refusal comes in Korean too


def test_an_exercise_id_used_by_an_earlier_file_is_refused(tmp_path):
    folder = _folder(tmp_path, {"01-a.toml": GOOD.replace("7. Mine", "1. A") + EXERCISE, "02-b.toml": GOOD + EXERCISE})
    lessons, problems = load_lessons(folder)
    assert [d.title for d in lessons] == ["1. A"]
    (problem,) = problems
    assert problem.startswith(f"{folder / '02-b.toml'}:8: exercise id 'my-force' is already used by ")


def test_the_readme_documents_every_key_and_its_example_loads(tmp_path):
    readme = (assets_dir() / "lessons" / "README.md").read_text()
    assert all(f"`{key}`" in readme or f"{key} =" in readme for key in KEYS)
    for kind, tasks in TASKS.items():
        assert f"`{kind.value}`" in readme
        assert all(f"`{name}`" in readme for name in tasks), kind
    example = re.search(r"```toml\n(\[\[exercise\]\].*?)```", readme, re.S)
    assert example is not None
    lessons, problems = load_lessons(_folder(tmp_path, {"07-mine.toml": GOOD + example.group(1)}))
    assert problems == () and lessons[0].exercises
