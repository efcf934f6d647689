"""A student answers an exercise in headless Chromium and the lecturer's table and CSV show it, in English and in
Korean (classroom mode: the first tab is the presenter's, the lecturer's; the second, from another browser, a
student's). The student types the answer with the keyboard (Enter submits), the result is read out in the live region,
and the lecturer's live table and the CSV download carry the answer. Screenshots of both at 1366×768 and at a
390×844 phone go to a temporary folder named in the test's output (to look at, never committed)."""

from __future__ import annotations

import csv
import io
import os
import tempfile

import pytest

from tests.support.browser import launched_chromium, text_input
from tests.support.pages import classroom_app
from tests.support.protocol import wait_for
from tests.support.stage import open_tab
from tpm_viz.app.exercises.grading import reference, variant_of
from tpm_viz.core.words import Lang, catalogue

pytestmark = [pytest.mark.browser, pytest.mark.slow]

__all__ = ["classroom_app"]  # the fixture, imported

IDENT = "direct-singularity-diagonal"
WIDE, PHONE = {"width": 1366, "height": 768}, {"width": 390, "height": 844}
SHOWN = ("Teach", "Exercises", "Demos", "Download results (CSV)")
WORDS = {"en": {k: k for k in SHOWN}, "ko": {k: catalogue(Lang.KO)[k] for k in SHOWN}}  # as each page shows them
SCORE = {"en": "Score 1.00: correct", "ko": "점수 1.00: 정답"}
STUDENT = {"en": "Student 1", "ko": "학생 1"}


def _view(app, n: int):
    wait_for(lambda: len(app.views) >= n and all(v in app.arrived for v in app.views.values()), what=f"{n} tabs")
    return list(app.views.values())[n - 1]


@pytest.mark.parametrize("lang", ["en", "ko"])
def test_a_student_answers_and_the_lecturer_s_table_and_csv_show_it(classroom_app, lang):
    app, words = classroom_app, WORDS[lang]
    shots = tempfile.mkdtemp(prefix=f"tpm-viz-exercises-{lang}-")
    locale = "ko-KR" if lang == "ko" else "en-US"
    with launched_chromium() as browser:
        lecturer_ctx = browser.new_context(locale=locale, viewport=WIDE, accept_downloads=True)
        student_ctx = browser.new_context(locale=locale, viewport=WIDE)  # another browser: its own cookie
        try:
            lecturer = lecturer_ctx.new_page()
            errors: list[str] = []
            lecturer.on("pageerror", lambda exc: errors.append(str(exc)))
            lecturer.goto(f"http://127.0.0.1:{app.port}/")
            lv = _view(app, 1)
            wait_for(lambda: app.exercises.section(lv), what="the lecturer's results")
            student = student_ctx.new_page()
            student.on("pageerror", lambda exc: errors.append(str(exc)))
            student.goto(f"http://127.0.0.1:{app.port}/")
            sv = _view(app, 2)
            assert app.exercises.section(sv) is None and sv.lang is Lang(lang)

            open_tab(student, words["Exercises"], group=words["Teach"])
            exercises = sv.teaching.exercises
            wait_for(lambda: exercises.mine[IDENT].prompt is not None and exercises.cards[IDENT], what="the card")
            mine = exercises.mine[IDENT]
            card = next(c for c in exercises.cards[IDENT] if not c.box)
            answer = f"{reference(mine.exercise, variant_of(mine.exercise, mine.seed))[0]:.2f}"
            box = text_input(student, card.answer)
            box.click()
            box.press_sequentially(answer.replace(".", ","), delay=20)  # a decimal comma, typed key by key
            box.press("Enter")
            result = student.locator(f'[data-q="exercise-result"][data-x="{IDENT}"] >> visible=true').first
            wait_for(lambda: SCORE[lang] in result.inner_text(), what="the score in the student's page")
            wait_for(lambda: SCORE[lang] in student.locator("#tpmviz-live").text_content(), what="read out")
            result.scroll_into_view_if_needed()
            student.screenshot(path=os.path.join(shots, "student-1366x768.png"))
            open_tab(student, words["Demos"], group=words["Teach"])  # the same result under the lesson's text
            wait_for(lambda: SCORE[lang] in result.inner_text(), what="the score under the lesson's text")
            result.scroll_into_view_if_needed()
            student.screenshot(path=os.path.join(shots, "student-demos-1366x768.png"))
            student.set_viewport_size(PHONE)
            open_tab(student, words["Exercises"], group=words["Teach"])
            result.scroll_into_view_if_needed()
            student.screenshot(path=os.path.join(shots, "student-390x844.png"))

            table = lecturer.locator('[data-q="results"] >> visible=true').first
            table.scroll_into_view_if_needed()
            typed = answer.replace(".", ",")
            wait_for(lambda: all(t in table.inner_text() for t in (STUDENT[lang], IDENT, typed)), what="the table")
            row = next(line for line in table.inner_text().splitlines() if IDENT in line)
            assert row.split("\t")[3:5] == ["1", "1.00"], row  # one attempt, best score 1
            lecturer.screenshot(path=os.path.join(shots, "lecturer-1366x768.png"))
            with lecturer.expect_download(timeout=20_000) as info:
                lecturer.get_by_role("button", name=words["Download results (CSV)"], exact=True).click()
            text = open(info.value.path(), encoding="utf-8").read()
            assert info.value.suggested_filename == "tpm-viz-results.csv"
            assert text.startswith("student,exercise,variant,seed,attempts,best_score,latest_score,last_answer,")
            lines = list(csv.reader(io.StringIO(text)))
            assert [r[:8] for r in lines[1:]] == [
                ["Student 1", IDENT, "own", str(mine.seed), "1", "1", "1", "'" + typed]
            ]
            lecturer.set_viewport_size(PHONE)
            table.scroll_into_view_if_needed()
            lecturer.screenshot(path=os.path.join(shots, "lecturer-390x844.png"))
            assert errors == []
            print(f"screenshots: {shots}")
        finally:
            lecturer_ctx.close()
            student_ctx.close()
