"""``tpm-viz exercise``: the issue's contract (JSON keys, CSV columns, exit codes), end to end through ``main``."""

from __future__ import annotations

import csv
import io
import json
import re

import pytest

from tests.support import cli
from tpm_viz.app.exercises.catalogue import listed
from tpm_viz.cli import main
from tpm_viz.core.params import PARAM_INFO

SHOW_KEYS = {"id", "lesson", "kind", "unit", "rtol", "atol", "params", "prompt"}
GRADE_KEYS = {"score", "format_error", "feedback", "attempts_used"}


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out, out.err


def one_object(text: str) -> dict:
    assert text.endswith("\n") and text.count("\n") == 1  # one object, one line
    return json.loads(text)


def test_list_is_the_csv_of_the_contract(capsys):
    status, out, _ = run(capsys, "exercise", "list")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert status == 0 and out.splitlines()[0] == "id,lesson,kind,unit,title"
    assert [r["id"] for r in rows] == [item.exercise.id for item in listed()]
    assert {r["id"]: (r["lesson"], r["kind"], r["unit"]) for r in rows}["force-at-pose"] == ("4", "number", "N")
    status, out, _ = run(capsys, "exercise", "list", "--lesson", "4", "--lang", "ko")
    assert [r["title"] for r in csv.DictReader(io.StringIO(out))] == ["구동기 1의 힘", "구동기 1이 쉬는 자세"]
    assert run(capsys, "exercise", "list", "--lesson", "0")[0] == 2


@pytest.mark.parametrize("ident", [item.exercise.id for item in listed()])
def test_show_then_grade_the_revealed_answer(capsys, ident):
    status, out, _ = run(capsys, "exercise", "show", ident, "--seed", "17", "--reveal")
    shown = one_object(out)
    assert status == 0 and set(shown) == SHOW_KEYS | {"answer"}
    assert shown["id"] == ident and isinstance(shown["lesson"], int)
    assert set(PARAM_INFO) <= set(shown["params"]) and all(isinstance(v, float) for v in shown["params"].values())
    assert all(isinstance(x, int | float) for x in shown["answer"])
    if shown["kind"] in ("gains", "choice"):
        assert shown["rtol"] is None and shown["atol"] is None
    answer = "; ".join(repr(x) for x in shown["answer"])
    status, out, _ = run(capsys, "exercise", "grade", ident, "--seed", "17", f"--answer={answer}")
    graded = one_object(out)
    assert status == 0 and set(graded) == GRADE_KEYS
    assert graded["score"] == 1.0 and graded["format_error"] is None and graded["attempts_used"] == 1
    status, out, _ = run(capsys, "exercise", "show", ident, "--seed", "17")
    assert "answer" not in one_object(out)


def test_show_gives_the_variant_in_si_and_the_prompt_in_korean(capsys):
    _, out, _ = run(capsys, "exercise", "show", "force-at-pose", "--seed", "3", "--lang", "ko")
    shown = one_object(out)
    p = shown["params"]
    assert -0.08 <= p["p1"] <= 0.08 and -10 <= p["ddp1"] <= 10 and p["l_a"] == 0.26  # metres, m/s²
    assert f"({round(p['p1'] * 1e3)}, {round(p['p2'] * 1e3)}) mm" in shown["prompt"] and "구동기" in shown["prompt"]
    _, out, _ = run(capsys, "exercise", "show", "zero-force-pose", "--seed", "3")
    shown = one_object(out)
    assert shown["atol"] == shown["params"]["tol"] and shown["unit"] == "mm"


def test_grade_answers_anything_with_status_zero(capsys):
    for text in ("twelve", "", "1; 2; 3", "5 kg", "1e999", "−12,5", "∞"):
        status, out, _ = run(capsys, "exercise", "grade", "force-at-pose", "--seed", "1", "--answer", text)
        graded = one_object(out)
        assert status == 0 and set(graded) == GRADE_KEYS
        if graded["format_error"] is not None:
            assert graded["score"] is None and graded["attempts_used"] == 0 and graded["feedback"] is None
        else:
            assert 0 <= graded["score"] <= 1 and graded["attempts_used"] == 1
    _, out, _ = run(capsys, "exercise", "grade", "force-at-pose", "--seed", "1", "--answer", "x", "--lang", "ko")
    assert re.search("[\uac00-\ud7a3]", one_object(out)["format_error"])  # in Korean


def test_the_ladder_on_the_command_line(capsys):
    _, out, _ = run(capsys, "exercise", "show", "force-at-pose", "--seed", "5", "--reveal")
    answer = repr(one_object(out)["answer"][0])
    scores = []
    for k in ("1", "2", "3"):
        _, out, _ = run(
            capsys, "exercise", "grade", "force-at-pose", "--seed", "5", f"--answer={answer}", "--attempt", k
        )
        scores.append(one_object(out)["score"])
    assert scores == [1.0, 0.7, 0.5]


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["grade", "no-such", "--seed", "1", "--answer", "1"], "unknown exercise 'no-such'"),
        (["grade", "force-at-pose", "--seed", "-1", "--answer", "1"], "the seed must be a whole number"),
        (["grade", "force-at-pose", "--seed", "9007199254740992", "--answer", "1"], "the seed must be"),
        (["grade", "force-at-pose", "--seed", "x", "--answer", "1"], "the seed must be"),
        (["grade", "force-at-pose", "--seed", "1", "--answer", "1", "--attempt", "4"], "allows 3 attempts"),
        (["grade", "force-at-pose", "--seed", "1", "--answer", "1", "--attempt", "0"], "the attempt must be"),
        (["grade", "force-at-pose", "--seed", "1", "--answer", "1", "--lang", "fr"], "invalid choice"),
        (["grade", "force-at-pose", "--answer", "1"], "required: --seed"),
        (["show", "force-at-pose", "--seed", "1", "--colour"], "unrecognized arguments"),
        (["selftest", "--variants", "0"], "--variants"),
    ],
)
def test_bad_ids_seeds_and_flags_exit_two(capsys, argv, says):
    status, out, err = run(capsys, "exercise", *argv)
    assert status == 2 and out == ""
    assert err.startswith("tpm-viz: error: ") and says in err and err.count("\n") == 1


_LESSON = """title = "1. Mine"
[text]
en = "A lesson of my own."
[pose]
p = [0.0, 0.0]

[[exercise]]
id = "merge"
kind = "number"
unit = "mm"
answer = "diagonal_singularity_d"
title = { en = "Merge" }
prompt = { en = "With l_a = {l_a} mm, at which d do the modes merge?" }
[exercise.draw]
l_a = { min = LO, max = HI, step = 0.001 }
"""


def test_selftest_on_a_lecturer_s_folder(tmp_path, capsys):
    good = tmp_path / "good"
    good.mkdir()
    (good / "01-mine.toml").write_text(_LESSON.replace("LO", "0.24").replace("HI", "0.26"))
    status, out, err = run(capsys, "exercise", "selftest", "--variants", "3", "--lessons", str(good))
    assert status == 0, err
    assert out.splitlines() == ["id,variants,reference_ok,perturbed_ok,format_ok,p95_ms", out.splitlines()[1]]
    assert out.splitlines()[1].startswith("merge,3,true,true,true,")
    bad = tmp_path / "bad"
    bad.mkdir()  # a - b - √2 l_a < 0 for every l_a: no variant where the modes merge inside the stroke
    (bad / "01-mine.toml").write_text(_LESSON.replace("LO", "0.28").replace("HI", "0.29"))
    status, out, err = run(capsys, "exercise", "selftest", "--variants", "2", "--lessons", str(bad))
    assert status == 1 and "merge,2,false,false," in out and "no usable variant for seed 0" in err
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "01-mine.toml").write_text(_LESSON.replace("LO", "0.24").replace("HI", "0.26") + "colour = 1\n")
    status, out, err = run(capsys, "exercise", "selftest", "--variants", "1", "--lessons", str(broken))
    assert status == 1 and "01-mine.toml:" in err and "unknown key" in err


@pytest.mark.end_to_end
def test_the_installed_command(tmp_path):
    """The real entry point: the installed ``tpm-viz`` (a child process), JSON on stdout, status 0 and 2."""
    done = cli.run_installed("exercise", "grade", "leg-angle", "--seed", "4", "--answer", "0.3 rad")
    assert done.returncode == 0 and set(json.loads(done.stdout)) == GRADE_KEYS
    done = cli.run_installed("exercise", "show", "leg-angle", "--seed", "x")
    assert done.returncode == 2 and done.stdout == "" and "seed" in done.stderr
