"""Exercises in the course's gradebook, end to end without a browser: the test platform (:mod:`tests.lti.platform`)
launches a Learner with a link to an exercise; the app's tab opens that exercise (*Teach › Exercises*, its lesson
chosen, the student's own numbers); a protocol-level tab types the answer; the score arrives at the platform's line
item exactly once, ``scoreGiven`` = the kept score x the line item's ``scoreMaximum``, ``userId`` = the launch's
``sub``. The right answer is computed here by Pinocchio's inverse dynamics (the engine grades with the paper's
closed form), never read from the engine; the ladder is the lesson file's."""

from __future__ import annotations

import html
import io
import json
import re
from contextlib import redirect_stdout

import httpx
import numpy as np
import pytest

from tests.lti.conftest import until, write_config
from tests.lti.platform import READ, SCORE, Item, Link, form_fields
from tests.support.pages import Page, views_of
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.app.lessons import DEMOS
from tpm_viz.classroom.launches import News
from tpm_viz.cli.lti import lti_plug
from tpm_viz.core.words import Lang, Phrase, catalogue, say
from tpm_viz.lti.exercises import POINTS, exercises_catalogue
from tpm_viz.lti.grades import Backoff
from tpm_viz.lti.run import LtiPlug
from tpm_viz.multibody import inverse_dynamics
from tpm_viz.ui.app import main
from tpm_viz.ui.graded import NEWS
from tpm_viz.viserkit.core import widget_uuid

FORCE = "force-at-pose"  # lesson 4; exam ladder [1.0, 0.7, 0.5]; unit N
SUB = "student2-sub"


@pytest.fixture
def served(tmp_path, platform):
    platform.links["force"] = Link(custom={"exercise": FORCE}, lineitem="li-f", scopes=[SCORE, READ])
    platform.links["force-noread"] = Link(custom={"exercise": FORCE}, lineitem="li-g", scopes=[SCORE])
    platform.links["nosuch"] = Link(custom={"exercise": "no-such-exercise"})
    platform.items["li-f"] = Item(score_maximum=20.0, label="The force of actuator 1")
    platform.items["li-g"] = Item(score_maximum=5.0, label="The force of actuator 1 (no read)")
    plug = LtiPlug(write_config(tmp_path, platform), "127.0.0.1", DEMOS, exercises=exercises_catalogue(DEMOS))
    with redirect_stdout(io.StringIO()):
        app = main(host="127.0.0.1", port=0, block=False, session=tmp_path / "store.sqlite3", lti=plug)
    platform.tool_jwks = plug.tool.urls.jwks
    plug.grades.backoff = Backoff(first=0.05, factor=2.0, most=0.2, jitter=0.1)  # down then up: quick retries
    yield app, plug
    app.stop()


def _arrive(app, plug, platform, hint: str, link: str):
    """A browser launched from the LMS opens the app: ``(page, view)`` once the tab is handled."""
    browser = httpx.Client(timeout=10, follow_redirects=False)
    urls = plug.tool.urls
    answer = browser.get(urls.login, params=platform.login_query(urls.launch, hint, link))
    action, fields = form_fields(browser.get(answer.headers["location"]).text)
    answer = browser.post(action, data=fields)
    assert answer.status_code == 303, answer.text
    assert browser.get(answer.headers["location"]).status_code == 200
    cookie = "; ".join(f"{c.name}={c.value}" for c in browser.cookies.jar if c.path == "/")
    before = len(app.views)
    page = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=cookie)
    return page, views_of(app, before + 1)[before]


def _opened(view, ident: str = FORCE):
    """``(mine, card)`` of the exercise the launch opened, once the student's numbers are in."""
    exercises = view.teaching.exercises
    until(lambda: view.teaching.built("teach"), "the Exercises tab built")
    mine = until(lambda: exercises.mine[ident] if exercises.mine[ident].prompt is not None else None, "the prompt")
    card = until(lambda: next((c for c in exercises.cards[ident] if not c.box and not c.gone), None), "the card")
    return mine, card


def _tau1(mine) -> float:
    """τ1 [N] of the student's numbers, by Pinocchio (ṗ = 0)."""
    v = variant_of(mine.exercise, mine.seed)
    tau = inverse_dynamics(v.params, np.array([v["p1"], v["p2"]]), np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
    return float(tau[0])


def _answer(page: Page, card, text: str) -> None:
    """Type ``text`` and press Enter (the line break reaches the server with the text); back once it is graded."""
    before = card.result.content
    page.send(type="GuiUpdateMessage", uuid=widget_uuid(card.answer), updates={"value": text + "\n"})
    until(lambda: card.result.content != before and "Grading" not in card.result.content, "the result")


def _told(view, news: News) -> bool:
    title = view.teaching.exercises.mine[FORCE].exercise.title.phrase()
    return say(view.lang, Phrase(NEWS[news].template, title=title)) in html.unescape(view.panel.message.content)


def _mine(platform) -> list[dict]:
    return [p for p in platform.posts if p["userId"] == SUB]


def test_a_launched_exercise_opens_and_its_right_answer_reaches_the_line_item_once(served, platform):
    app, plug = served
    page, view = _arrive(app, plug, platform, "student2", "force")
    try:
        mine, card = _opened(view)
        exercises = view.teaching.exercises
        lesson = next(d.title for d in DEMOS if any(e.id == FORCE for e in d.exercises))
        assert exercises.choice.value == lesson and not view.session.shared  # its lesson; the student's own copy
        assert mine.seed == app.exercises.book.seed(view.launch.key, FORCE)  # the LMS user's own variant
        (path,) = re.findall(r'data-path="([^"]*)"', app.graded.shown[view])
        assert json.loads(html.unescape(path)) == ["Teach", "Exercises"]  # the page is asked to show that tab
        _answer(page, card, f"{_tau1(mine):.4f} N")
        assert mine.score == 1.0
        result = until(lambda: platform.result("li-f", SUB), "the score at the line item")
        assert (result["scoreGiven"], result["scoreMaximum"], result["userId"]) == (20.0, 20.0, SUB)
        until(lambda: _told(view, News.SENT), "the student told the grade is in the gradebook")
        assert len(_mine(platform)) == 1 and plug.ledger.outbox() == []  # sent: none waiting
    finally:
        page.close()


def test_wrong_then_right_sends_the_best_and_a_worse_answer_after_it_sends_nothing(served, platform):
    app, plug = served
    page, view = _arrive(app, plug, platform, "student2", "force-noread")
    try:
        mine, card = _opened(view)
        ladder = mine.exercise.attempts.ladder
        _answer(page, card, "0 N")  # wrong (τ1 is never 0 with these draws: checked below)
        assert abs(_tau1(mine)) > 0.05 and mine.score == 0.0
        until(lambda: platform.result("li-g", SUB), "the first score")
        _answer(page, card, f"{_tau1(mine):.4f}")
        until(lambda: platform.result("li-g", SUB)["scoreGiven"] > 0, "the better score")
        _answer(page, card, "0")  # worse than the best: nothing new
        result = platform.result("li-g", SUB)
        # no read scope: the exercise's maximum (deep linking's) is sent, not the line item's
        assert (result["scoreGiven"], result["scoreMaximum"]) == (pytest.approx(ladder[1] * POINTS), POINTS)
        until(lambda: plug.ledger.outbox() == [], "nothing waiting")
        assert [p["scoreGiven"] for p in _mine(platform)] == [0.0, pytest.approx(ladder[1] * POINTS)]
    finally:
        page.close()


def test_the_platform_down_then_up_gets_the_score_once_and_the_student_is_told(served, platform):
    app, plug = served
    page, view = _arrive(app, plug, platform, "student2", "force")
    try:
        mine, card = _opened(view)
        platform.mode = "down"
        _answer(page, card, f"{_tau1(mine):.4f}")
        until(lambda: _told(view, News.ON_ITS_WAY), "the student told the grade is on its way")
        assert platform.result("li-f", SUB) is None
        platform.mode = "up"
        plug.grades.wake()
        result = until(lambda: platform.result("li-f", SUB), "the score once the platform is back")
        assert (result["scoreGiven"], result["scoreMaximum"]) == (20.0, 20.0)
        until(lambda: _told(view, News.SENT), "the student told it arrived")
        assert len(_mine(platform)) == 1 and len([a for a in platform.applied if a["userId"] == SUB]) == 1
    finally:
        page.close()


def test_an_unknown_exercise_is_one_line_and_an_instructor_s_answers_are_not_sent(served, platform):
    app, plug = served
    page, view = _arrive(app, plug, platform, "student2", "nosuch")
    try:
        line = Phrase(
            "The course's link names the exercise {id}, which this tpm-viz does not have.", id="no-such-exercise"
        )
        until(lambda: say(view.lang, line) in html.unescape(view.panel.message.content), "the one line")
        assert view not in app.graded.shown  # nothing else: no tab shown
    finally:
        page.close()
    page, teacher = _arrive(app, plug, platform, "teacher", "force")
    try:
        mine, card = _opened(teacher)  # the presenter gets the exercise too
        _answer(page, card, f"{_tau1(mine):.4f}")
        assert mine.score == 1.0 and app.exercises.book.rows.of(teacher.launch.key)
        assert platform.posts == [] and plug.ledger.outbox() == []  # an instructor's score is not the course's
    finally:
        page.close()


def test_serve_lti_offers_every_exercise_of_its_lessons_graded(tmp_path, platform):
    plug = lti_plug(write_config(tmp_path, platform), "127.0.0.1", None, [], [])  # what `serve --lti` builds
    try:
        offered = [item for item in plug.catalogue() if item.kind == "exercise"]
    finally:
        plug.stop()
    expected = [(e.id, e.title.en, e.title.ko or e.title.en) for d in DEMOS for e in d.exercises]
    assert [(i.id, i.title_en.split(". ", 1)[1], i.title_ko.split(". ", 1)[1]) for i in offered] == expected
    assert expected and all(i.graded and i.score_maximum == POINTS for i in offered)


def test_an_instructor_deep_links_an_exercise_with_its_line_item(served, platform):
    _, plug = served
    urls = plug.tool.urls
    with httpx.Client(timeout=10, follow_redirects=False) as browser:
        answer = browser.get(urls.login, params=platform.login_query(urls.deeplink, "teacher", "dl"))
        action, fields = form_fields(browser.get(answer.headers["location"]).text)
        picker = browser.post(action, data=fields)
        assert picker.status_code == 200 and f'value="exercise:{FORCE}"' in picker.text
        assert f"graded, out of {POINTS:g} points" in picker.text
        _, fields = form_fields(picker.text)
        chosen = browser.post(urls.picked, data={"pick": fields["pick"], "item": [f"exercise:{FORCE}"], "do": "add"})
        action, fields = form_fields(chosen.text)
        assert browser.post(action, data=fields).status_code == 200  # to the platform, which checks it
    (claims,) = platform.deep_link_answers
    (item,) = claims["https://purl.imsglobal.org/spec/lti-dl/claim/content_items"]
    title = next(e.title.en for d in DEMOS for e in d.exercises if e.id == FORCE)
    assert item["custom"] == {"exercise": FORCE} and title in item["title"]
    assert item["lineItem"]["scoreMaximum"] == POINTS


def test_a_korean_tab_is_asked_to_show_the_tabs_by_their_korean_names(served, platform):
    app, plug = served
    page, view = _arrive(app, plug, platform, "student", "force")  # the LMS speaks Korean (ko-KR)
    try:
        _opened(view)
        (path,) = re.findall(r'data-path="([^"]*)"', app.graded.shown[view])
        assert view.lang is Lang.KO
        assert json.loads(html.unescape(path)) == [catalogue(Lang.KO)["Teach"], catalogue(Lang.KO)["Exercises"]]
    finally:
        page.close()
