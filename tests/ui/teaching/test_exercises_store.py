"""The exercises across browsers, restarts and the lecturer: each student's numbers from the cookie the server issued
(computed here from the secret file beside the store, as ``docs/exercises.md`` states it), the same over a restart
with the same store and on another device of the same browser, the class seed for everybody, the lecturer's live
table, a student who never sees it, and every answer a student was told of still kept after ``kill -9``."""

from __future__ import annotations

import hashlib
import hmac
import html
import os
import re
import signal

import numpy as np
import pytest

from tests.support.pages import Page, classroom_app, views_of
from tests.support.protocol import ServerProcess, wait_for
from tests.support.stores import page_cookie
from tpm_viz.app.exercises.catalogue import by_id, listed
from tpm_viz.app.exercises.grading import prompt, variant_of
from tpm_viz.classroom.identity import SECRET_FILE
from tpm_viz.classroom.store import SqliteStore
from tpm_viz.multibody import inverse_dynamics
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.continuity import lecture_store
from tpm_viz.viserkit.probe import widget_uuid

__all__ = ["classroom_app"]  # the fixture, imported

FORCE = "force-at-pose"


def _serve(path) -> TpmApp:
    store = lecture_store(path)
    store.open()
    return TpmApp(build_server("127.0.0.1", 0, keys=store.keys), store=store)


def _identity(cookie: str) -> str:
    """The stored identity of a cookie ``tpmviz_id=<id>.<mac>``: ``c:`` and SHA-256 of the id."""
    return "c:" + hashlib.sha256(cookie.split("=", 1)[1].split(".")[0].encode()).hexdigest()


def _seed(folder, identity: str, ident: str) -> int:
    """The docs' seed: the key HMAC-SHA256(secret, "tpm-viz derive: exercise seeds"), then HMAC-SHA256(key, identity
    ␟ id), its first 8 bytes big-endian >> 11."""
    key = hmac.new((folder / SECRET_FILE).read_bytes(), b"tpm-viz derive: exercise seeds", hashlib.sha256).digest()
    digest = hmac.new(key, f"{identity}\x1f{ident}".encode(), hashlib.sha256).digest()
    return int.from_bytes(digest[:8], "big") >> 11


def _shows(seed: int, ident: str = FORCE) -> str:
    exercise = by_id(ident).exercise
    return html.escape(prompt(exercise, variant_of(exercise, seed)).render())


def _visit(app, cookie: str, source: str | None = None):
    before = set(app.views.values())
    page = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=cookie, source=source)
    view = wait_for(lambda: next((v for v in app.views.values() if v not in before), None), what="the new tab")
    views_of(app, len(before) + 1)
    view.teaching.open("teach")
    title = next(d.title for d in view.teaching.exercises.lessons if any(e.id == FORCE for e in d.exercises))
    _press(page, view.teaching.exercises.choice, title)  # the Exercises tab shows the lesson of force-at-pose
    return page, view


def _card(view, ident: str = FORCE):
    """``(mine, card)``: the exercise once its prompt has the student's numbers, and its card in the *Exercises* tab
    (None if its lesson is not the one shown there)."""
    exercises = view.teaching.exercises
    wait_for(lambda: exercises.mine[ident].prompt is not None, what="the prompt")
    if ident == FORCE:
        wait_for(lambda: any(not c.box for c in exercises.cards[ident]), what="the card in the Exercises tab")
    return exercises.mine[ident], next((c for c in exercises.cards[ident] if not c.box), None)


def _answer(page: Page, card, text: str) -> None:
    before = card.result.content
    page.send(type="GuiUpdateMessage", uuid=widget_uuid(card.answer), updates={"value": text + "\n"})
    wait_for(lambda: card.result.content != before and "Grading" not in card.result.content, what="the result")


def _press(page: Page, handle, value=True) -> None:
    page.send(type="GuiUpdateMessage", uuid=widget_uuid(handle), updates={"value": value})


def _tau1(mine) -> str:
    v = variant_of(mine.exercise, mine.seed)
    tau = inverse_dynamics(v.params, np.array([v["p1"], v["p2"]]), np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
    return f"{tau[0]:.3f}"


def test_a_restart_with_the_same_store_brings_back_the_numbers_the_attempts_and_the_table(tmp_path):
    path = tmp_path / "class.sqlite3"
    app = _serve(path)
    try:
        cookie = page_cookie(app.port)
        page, view = _visit(app, cookie)
        mine, card = _card(view)
        seed = _seed(tmp_path, _identity(cookie), FORCE)
        assert mine.seed == seed and _shows(seed) in card.prompt.content
        _answer(page, card, "0")
        right = _tau1(mine)
        _answer(page, card, right)
        section = app.exercises.section(view)  # no presenter mode: the app treats every tab as the lecturer's
        wait_for(lambda: "force-at-pose" in section.table.content, what="the lecturer's table")
        table = section.table.content
        assert f"<td>Student 1</td><td>{FORCE}</td><td>own</td><td>2</td><td>0.70</td><td>{right}</td>" in _plain(table)
        page.close()
    finally:
        app.stop()
    again = _serve(path)  # a new app on the same store: the lecture of yesterday
    try:
        page, view = _visit(again, cookie)
        mine, card = _card(view)
        assert mine.seed == seed and _shows(seed) in card.prompt.content
        wait_for(lambda: "2 attempt(s), best score 0.70; 1 attempt(s) left." in card.result.content, what="attempts")
        assert [(r.answer, r.score) for r in mine.attempts] == [("0", 0.0), (right, pytest.approx(0.7))]
        section = again.exercises.section(view)
        wait_for(lambda: f"<td>{right}</td>" in _plain(section.table.content), what="the table again")
        _answer(page, card, right)
        assert mine.score == pytest.approx(0.5)  # the ladder's third attempt: counted on from before
        page.close()
    finally:
        again.stop()


def _plain(table: str) -> str:
    """The table's cells without their style attributes."""
    return re.sub(r' style="[^"]*"', "", table)


def test_each_student_has_their_own_numbers_on_every_device_and_the_class_seed_gives_everybody_one(tmp_path):
    app = _serve(tmp_path / "class.sqlite3")
    try:
        ann, bob = page_cookie(app.port), page_cookie(app.port)
        page_a, view_a = _visit(app, ann)
        page_b, view_b = _visit(app, bob)
        _page_a2, view_a2 = _visit(app, ann, source="127.0.0.2")  # Ann's browser on another device: her cookie
        seeds = {who: _seed(tmp_path, _identity(c), FORCE) for who, c in (("ann", ann), ("bob", bob))}
        assert seeds["ann"] != seeds["bob"]
        for view, who in ((view_a, "ann"), (view_b, "bob"), (view_a2, "ann")):
            mine, card = _card(view)
            assert mine.seed == seeds[who] and _shows(seeds[who]) in card.prompt.content
        prompts = {
            who: [_card(view, item.exercise.id)[0].prompt.render() for item in listed()]
            for who, view in (("ann", view_a), ("bob", view_b), ("ann2", view_a2))
        }
        assert prompts["ann"] == prompts["ann2"] != prompts["bob"]
        section = app.exercises.section(view_a)
        _press(page_a, section.seed, "1234")
        wait_for(lambda: section.seed.value == "1234", what="the seed typed")
        _press(page_a, section.fix)
        for view in (view_a, view_b, view_a2):
            wait_for(lambda view=view: _card(view)[0].seed == 1234, what="the class seed in every tab")
            assert _shows(1234) in _card(view)[1].prompt.content
        mine, card = _card(view_b)
        _answer(page_b, card, _tau1(mine))
        row = app.exercises.book.rows.of(_identity(bob))[-1]
        assert (row.seed, row.shared, row.score) == (1234, True, 1.0)
        wait_for(lambda: "Class seed 1234" in section.table.content, what="the status line")
        _press(page_a, section.unfix)
        wait_for(lambda: _card(view_b)[0].seed == seeds["bob"], what="Bob's own numbers again")
        assert _card(view_b)[0].attempts == ()  # his own variant: no attempt yet
        for page in (page_a, page_b, _page_a2):
            page.close()
    finally:
        app.stop()


def test_a_student_never_sees_the_results_only_the_presenter_does(classroom_app):
    app = classroom_app
    lecturer = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=page_cookie(app.port))
    (lv,) = views_of(app, 1)
    student = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=page_cookie(app.port))
    sv = next(v for v in views_of(app, 2) if v is not lv)
    assert app.exercises.section(lv) is not None and app.exercises.section(sv) is None
    sv.teaching.open("teach")
    _press(student, sv.teaching.exercises.choice, by_id(FORCE).lesson.title)
    mine, card = _card(sv)
    _answer(student, card, "0")
    section = app.exercises.section(lv)
    wait_for(lambda: "<td>0</td>" in _plain(section.table.content), what="the answer in the lecturer's table")
    wait_for(lambda: "Exercise results" in lecturer.uuids, what="the lecturer's results on the wire")
    assert "Exercise results" not in student.uuids and "Class seed" not in student.uuids  # never sent to a student
    assert all(r.identity == sv.teaching.exercises.identity for r in mine.attempts)
    app.exercises.download(sv)  # a forged request from the student's tab: refused, nothing sent
    wait_for(lambda: "only the lecturer" in sv.panel.message.content, what="the refusal")
    for page in (lecturer, student):
        page.close()


def test_without_presenter_mode_only_the_serving_machine_reads_the_results(monkeypatch, tmp_path):
    """``tpm-viz serve --host 0.0.0.0`` without classroom mode: every tab gets the *Lecturer* folder, but the results
    (everyone's answers, the CSV, the class seed) only a tab on the serving machine (here: exactly 127.0.0.1; a
    student is 127.0.0.2)."""
    monkeypatch.setattr("tpm_viz.ui.room.is_loopback", lambda host: host == "127.0.0.1")
    app = _serve(tmp_path / "lecture.sqlite")
    try:
        here, lv = _visit(app, page_cookie(app.port))
        there, sv = _visit(app, page_cookie(app.port), source="127.0.0.2")
        assert not app.access.enabled and sv.address == "127.0.0.2"
        assert app.room.lecturer(sv)  # the Lecturer folder as before: nobody holds the mechanism
        wait_for(lambda: app.exercises.section(lv) is not None, what="the results in the local tab")
        assert app.exercises.section(sv) is None
        assert "Exercise results" not in there.uuids and "Class seed" not in there.uuids
        app.exercises.fix(sv, 7)  # forged from the student's tab: refused, the class keeps its own variants
        wait_for(lambda: "only the lecturer" in sv.panel.message.content, what="the refusal")
        assert app.exercises.book.class_seed is None
        app.exercises.download(sv)
        assert "only the lecturer" in sv.panel.message.content
        for page in (here, there):
            page.close()
    finally:
        app.stop()


class _Results(Page):
    """A tab that also keeps the exercise results the server sends (the HTML of a card's result)."""

    def __init__(self, *args, **kwargs) -> None:
        self.results: set[str] = set()  # the stamps of the results told (one per answer, in every card of it)
        self.numbers = False  # a prompt with the student's numbers arrived
        super().__init__(*args, **kwargs)

    def take(self, m: dict) -> None:
        super().take(m)
        content = (m.get("updates") or m.get("props") or {}).get("content")
        told = re.search(r'data-say="([^"]+)"', content) if isinstance(content, str) else None
        if told is not None and 'data-q="exercise-result"' in content and "attempt(s)" in content:
            self.results.add(told.group(1))
        if isinstance(content, str) and 'data-q="exercise-prompt"' in content and "Preparing" not in content:
            self.numbers = True


@pytest.mark.slow
def test_every_answer_a_student_was_told_of_is_kept_after_kill_9(tmp_path):
    path = tmp_path / "class.sqlite3"
    server = ServerProcess(session=path)
    try:
        cookie = page_cookie(server.port)
        page = _Results(server.port, origin=f"http://127.0.0.1:{server.port}", cookie=cookie)
        wait_for(lambda: page.numbers, what="the student's numbers")
        for k, text in enumerate(("12", "13,5", "−14 mm"), 1):  # the lesson's first exercise, under its text
            page.set("Answer", text + "\n")
            wait_for(lambda k=k: len(page.results) >= k, what=f"answer {k} told")
        os.kill(server.pid, signal.SIGKILL)  # no save, no goodbye
        server.proc.wait(timeout=30)
        page.close()
    finally:
        server.stop()
    store = SqliteStore(path)
    try:
        rows = store.results.of(_identity(cookie))
        assert [(r.exercise, r.attempt, r.answer) for r in rows] == [
            ("direct-singularity-diagonal", 1, "12"),
            ("direct-singularity-diagonal", 2, "13,5"),
            ("direct-singularity-diagonal", 3, "−14 mm"),
        ]
    finally:
        store.close()
