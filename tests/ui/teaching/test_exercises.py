"""The exercises of a tab without a browser: a protocol-level client types and presses what a student would; the
scores are checked against an independent route (Pinocchio's inverse dynamics for the forces, the control lab's
Pinocchio simulation for the gains), the attempts against the lesson file's ladder, what is kept against the
store's rows."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz.app.exercises.gains import RMS_LIMIT
from tpm_viz.app.exercises.grading import reference, variant_of
from tpm_viz.core.numbers import parse_quantity
from tpm_viz.core.words import Lang
from tpm_viz.multibody import inverse_dynamics
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.paper.control import Gains
from tpm_viz.ui.teaching.exercises.text import EXAMPLES

FORCE = "force-at-pose"  # exam: [1.0, 0.7, 0.5], N
POSE = "zero-force-pose"  # homework, pose in mm
GAINS = "tune-ctc"  # homework, gains (heavy)


def _ready(client, view, ident: str, box: bool = False):
    """``(mine, card)`` of exercise ``ident`` once its prompt has the student's numbers (``box``: the card under the
    lesson's text in *Demos*, else the *Exercises* tab's, built now, its lesson chosen in the *Lesson* dropdown)."""
    exercises = view.teaching.exercises
    if not box:
        view.teaching.open("teach")
        title = next(d.title for d in exercises.lessons if any(e.id == ident for e in d.exercises))
        client.set_value(exercises.choice, title)
    mine = wait_for(lambda: exercises.mine[ident] if exercises.mine[ident].prompt is not None else None, what="prompt")
    card = wait_for(lambda: next((c for c in exercises.cards[ident] if c.box == box), None), what="the card")
    return mine, card


def _answer(client, card, text: str, enter: bool = False, shows: str | None = None) -> None:
    """Type ``text`` and submit it; back once the result changed (``shows``: once it shows that, for a tab whose
    result may also be redrawn meanwhile by something else, e.g. a language change)."""
    stamp = card.result.content
    if enter:  # Enter reaches the server as a line break at the end of the whole text
        client.set_value(card.answer, text + "\n")
    else:
        client.set_value(card.answer, text)
        wait_for(lambda: card.answer.value == text, what="the text at the server")
        client.click(card.submit)
    wait_for(
        lambda: (
            card.result.content != stamp
            and "Grading" not in card.result.content
            and (shows is None or shows in card.result.content)
        ),
        what=f"the result{'' if shows is None else ' showing ' + shows}",
    )


def _tau1(mine) -> float:
    v = variant_of(mine.exercise, mine.seed)
    tau = inverse_dynamics(v.params, np.array([v["p1"], v["p2"]]), np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
    return float(tau[0])


def _kept(app, view):
    return app.exercises.book.rows.of(view.teaching.exercises.identity)


def test_a_right_answer_typed_as_anywhere_scores_one_and_is_kept(app, connect):
    client, view = connect()
    mine, card = _ready(client, view, FORCE)
    tau = _tau1(mine)
    typed = f"{tau / 1000:.6f} kN".replace(".", ",").replace("-", "−")  # kN, a decimal comma, the Unicode minus
    _answer(client, card, typed, enter=True)
    assert mine.score == 1.0 and "Score 1.00: correct" in card.result.content
    assert "1 attempt(s), best score 1.00; 2 attempt(s) left." in card.result.content
    assert card.answer.value == typed  # the line break of Enter taken out, the answer as typed
    (row,) = _kept(app, view)
    assert (row.exercise, row.attempt, row.answer, row.score, row.seed) == (FORCE, 1, typed, 1.0, mine.seed)


def test_a_format_error_says_what_to_change_and_uses_no_attempt(app, connect):
    client, view = connect()
    mine, card = _ready(client, view, FORCE)
    for text in ("12 kg", "ten newtons", ""):
        _answer(client, card, text)
        assert mine.error is not None and not mine.refused
        assert "No attempt used." in card.result.content and 'data-q="exercise-error"' in card.result.content
        assert not card.submit.disabled and mine.left == 3
    assert _kept(app, view) == ()


def test_the_ladder_scores_later_attempts_less_then_no_attempts_are_left(app, connect):
    client, view = connect()
    mine, card = _ready(client, view, FORCE)
    ladder = mine.exercise.attempts.ladder
    right = f"{_tau1(mine):.3f}"
    _answer(client, card, "0")
    assert mine.score == 0.0 and "2 attempt(s) left" in card.result.content
    _answer(client, card, right)
    assert mine.score == pytest.approx(ladder[1]) and "best score 0.70; 1 attempt(s) left" in card.result.content
    _answer(client, card, "0")
    assert "3 attempt(s), best score 0.70; no attempts left." in card.result.content
    wait_for(lambda: card.submit.disabled and card.answer.disabled, what="submit closed")
    client.click(card.submit)  # a page that sends it anyway: not graded, not kept
    wait_for(lambda: "Not graded: no attempts left" in card.result.content, what="no attempts left")
    assert [(r.attempt, r.score) for r in _kept(app, view)] == [(1, 0.0), (2, pytest.approx(ladder[1])), (3, 0.0)]


def test_use_current_pose_writes_the_platform_s_position_and_that_pose_is_graded(app, connect):
    client, view = connect()
    mine, card = _ready(client, view, POSE)
    v = variant_of(mine.exercise, mine.seed)
    p1, p2 = reference(mine.exercise, v)  # a pose that rests actuator 1: checked with Pinocchio below
    client.enter(view.panel.p, {"p1": f"{p1:.2f}", "p2": f"{p2:.2f}"})  # the platform moved as a student would
    wait_for(lambda: np.allclose(view.session.state.pose.p * 1e3, (round(p1, 2), round(p2, 2))), what="the move")
    client.click(card.pose)
    shown = view.session.state.pose.p * 1e3
    wait_for(lambda: card.answer.value == f"{shown[0]:.2f}; {shown[1]:.2f}", what="the pose in the box")
    tau = inverse_dynamics(v.params, shown * 1e-3, np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
    assert abs(tau[0]) <= v["tol"]  # Pinocchio: actuator 1 rests there
    stamp = card.result.content
    client.click(card.submit)
    wait_for(lambda: card.result.content != stamp and mine.score is not None, what="graded")
    assert mine.score == 1.0 and _kept(app, view)[-1].answer == card.answer.value


def test_a_gains_answer_is_graded_in_the_fair_worker_with_a_grading_state(app, connect, monkeypatch):
    client, view = connect()
    mine, card = _ready(client, view, GAINS)
    book, threads = app.exercises.book, []
    submit = book.submit

    def recorded(identity, ident, text):
        threads.append(threading.current_thread().name)
        return submit(identity, ident, text)

    monkeypatch.setattr(book, "submit", recorded)
    running, gate = threading.Event(), threading.Event()
    app.services.worker.submit(("gate",), lambda: running.set() or gate.wait(60), None, tab="another tab")
    wait_for(running.is_set, what="the worker busy with another tab's job")
    client.set_value(card.answer, "16; 0.9")
    wait_for(lambda: card.answer.value == "16; 0.9", what="the text")
    client.click(card.submit)
    wait_for(lambda: "Grading…" in card.result.content and card.submit.disabled, what="grading…")
    assert threads == [] and mine.grading
    gate.set()
    wait_for(lambda: mine.score is not None, timeout=60, what="graded")
    assert threads and threads[0].startswith("tpm-viz-worker")
    v = variant_of(mine.exercise, mine.seed)
    setup = ControlSetup(gains=Gains(16.0, 0.9), mass_error=(v["mass_error"],) * 3, force_limit=v["force_limit"])
    try:
        run = simulate(v.params, "circle", setup)  # the control lab's own simulation (Pinocchio)
        passes = run.rms_error < RMS_LIMIT and not bool(run.saturated.any())
    except Exception:  # the loop went unstable
        passes = False
    assert mine.score == (1.0 if passes else 0.0) and not card.submit.disabled
    assert math.isfinite(_kept(app, view)[-1].score)


def test_the_lesson_s_exercises_sit_under_its_text_and_follow_the_lesson(app, connect):
    client, view = connect()
    exercises = view.teaching.exercises
    mine, box = _ready(client, view, "direct-singularity-diagonal", box=True)
    assert {c.id for cards in exercises.cards.values() for c in cards if c.box} == {"direct-singularity-diagonal"}
    for _ in range(3):  # Next, Next, Next: lesson 4
        index = view.teaching.demos.index
        client.set_value(view.teaching.demos.steps, "Next")
        wait_for(lambda index=index: view.teaching.demos.index == index + 1, what="the next lesson")
    wait_for(lambda: {c.id for cs in exercises.cards.values() for c in cs if c.box} == {FORCE, POSE}, what="lesson 4")
    assert box.gone  # the first lesson's card went with it
    mine, card = _ready(client, view, FORCE, box=True)
    _, tab_card = _ready(client, view, FORCE)
    _answer(client, card, f"{_tau1(mine):.3f}")
    wait_for(lambda: tab_card.result.content == card.result.content, what="both cards of the exercise")
    assert "Score 1.00" in tab_card.result.content


def test_a_korean_tab_shows_the_prompt_and_the_result_in_korean(app, connect):
    client, view = connect()
    mine, card = _ready(client, view, FORCE)
    view.words.set(Lang.KO)
    wait_for(lambda: mine.exercise.prompt.ko.split("{")[0] in card.prompt.content, what="the Korean prompt")
    _answer(client, card, "1 kg", shows="읽을 수 없음")  # the result was also retold in Korean meanwhile
    assert "읽을 수 없음" in card.result.content and "시도 횟수를 쓰지 않았습니다" in card.result.content
    _answer(client, card, f"{_tau1(mine):.3f}", shows="점수")
    assert "점수 1.00: 정답" in card.result.content and "남은 시도 2번" in card.result.content


def test_every_other_unit_a_card_suggests_is_read_in_the_exercise_s_unit():
    for unit, text in EXAMPLES.items():
        value = parse_quantity(text, unit=unit)
        assert math.isfinite(value) and value != float(text.split()[0].rstrip("°"))  # converted, not as typed
