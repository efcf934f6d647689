"""The whole path of a graded exercise in headless Chromium: the LMS's course page -> the tool's login -> the
platform's authorisation (its auto-submitted form) -> the launch -> the app, whose page opens *Teach › Exercises*
by itself with the linked exercise's card; the student types the answer (key by key, a decimal comma) and presses
Enter; the score arrives at the platform's line item once, and the page says it is in the course's gradebook.

The right answer is τ1 of the student's numbers by Pinocchio's inverse dynamics (the engine grades with the paper's
closed form), never read from the engine."""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout

import numpy as np
import pytest

from tests.lti.conftest import until, write_config
from tests.lti.platform import READ, SCORE, Item, Link
from tests.support.browser import launched_chromium, text_input
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.app.lessons import DEMOS
from tpm_viz.classroom.launches import News
from tpm_viz.core.words import Phrase, say
from tpm_viz.lti.exercises import exercises_catalogue
from tpm_viz.lti.run import LtiPlug
from tpm_viz.multibody import inverse_dynamics
from tpm_viz.ui.app import main
from tpm_viz.ui.graded import NEWS

pytestmark = [pytest.mark.browser, pytest.mark.slow]

PAGE_MS = 240_000  # a page on a loaded machine (software WebGL): generous, never a timed assert
FORCE = "force-at-pose"
SUB = "student2-sub"


@pytest.fixture
def served(tmp_path, platform):
    platform.links["force"] = Link(custom={"exercise": FORCE}, lineitem="li-f", scopes=[SCORE, READ])
    platform.items["li-f"] = Item(score_maximum=20.0, label="The force of actuator 1")
    plug = LtiPlug(write_config(tmp_path, platform), "127.0.0.1", DEMOS, exercises=exercises_catalogue(DEMOS))
    with redirect_stdout(io.StringIO()):
        app = main(host="127.0.0.1", port=0, block=False, session=tmp_path / "store.sqlite3", lti=plug)
    urls = plug.tool.urls
    platform.tool_jwks, platform.tool_login, platform.tool_launch = urls.jwks, urls.login, urls.launch
    yield app
    app.stop()


def test_from_the_course_page_to_the_exercise_and_its_score_at_the_line_item(served, platform):
    app = served
    with launched_chromium() as browser:
        context = browser.new_context(viewport={"width": 1400, "height": 860})
        page = context.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.goto(f"{platform.url}/course/student2/force")
        page.click("#open")
        page.wait_for_url(re.compile(rf"^http://127\.0\.0\.1:{app.port}/\?lti="), timeout=PAGE_MS)
        view = until(lambda: next(iter(app.views.values()), None), "the tab's view", PAGE_MS / 1e3)
        until(lambda: view in app.arrived, "the tab handled", PAGE_MS / 1e3)
        exercises = view.teaching.exercises
        mine = until(lambda: exercises.mine[FORCE] if exercises.mine[FORCE].prompt is not None else None, "numbers")
        card = until(lambda: next((c for c in exercises.cards[FORCE] if not c.box), None), "the card")

        # the page opened Teach > Exercises itself (the test clicked no tab): the card's prompt is shown
        exercises_tab = page.locator('[role="tab"][title="Exercises"]').first
        exercises_tab.wait_for(timeout=PAGE_MS)
        until(lambda: exercises_tab.get_attribute("aria-selected") == "true", "the Exercises tab open", PAGE_MS / 1e3)
        page.locator(f'[data-q="exercise-prompt"][data-x="{FORCE}"] >> visible=true').first.wait_for(timeout=PAGE_MS)
        result = page.locator(f'[data-q="exercise-result"][data-x="{FORCE}"]').first

        v = variant_of(mine.exercise, mine.seed)
        tau = inverse_dynamics(v.params, np.array([v["p1"], v["p2"]]), np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
        box = text_input(page, card.answer)
        box.click()
        box.press_sequentially(f"{float(tau[0]):.3f}".replace(".", ","), delay=20)  # a decimal comma, key by key
        box.press("Enter")
        until(lambda: "Score 1.00: correct" in result.inner_text(), "the score in the page", PAGE_MS / 1e3)

        score = until(lambda: platform.result("li-f", SUB), "the score at the line item", PAGE_MS / 1e3)
        assert (score["scoreGiven"], score["scoreMaximum"], score["userId"]) == (20.0, 20.0, SUB)
        told = say(view.lang, Phrase(NEWS[News.SENT].template, title=mine.exercise.title.phrase()))
        page.get_by_text(told).wait_for(timeout=PAGE_MS)
        assert [p["userId"] for p in platform.posts] == [SUB]  # once
        assert errors == []
        context.close()
