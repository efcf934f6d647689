"""Exercises launched from the LMS: the launch's exercise opens in its tab, and the student's kept score goes back
to the course's gradebook (``tpm-viz serve --lti``; docs/lti.md, "Exercises in the gradebook").

:func:`grade_launches` wires one :class:`Graded` into the app: the ``open_exercise`` of its
:class:`~tpm_viz.ui.launched.Launched` and the exercises' score sink
(:attr:`~tpm_viz.ui.teaching.exercises.desk.ExerciseDesk.score_sink`).

- **Open** (:meth:`Graded.open_exercise`, a fresh launch whose link says ``custom`` ``exercise=ID``): a student's
  tab moves to its own copy (as a lesson link does: *Use current pose* reads the student's own mechanism); the *Teach ›
  Exercises* tab is built, that exercise's lesson chosen and its cards drawn, with the student's own numbers (the
  seed of the LMS user's identity, or the class seed: :class:`~tpm_viz.classroom.results.Gradebook`); the presenter
  gets the same. The page is asked to show that tab (a hidden ``data-tpmviz-show`` element naming the tabs to click,
  in the tab's language: :mod:`tpm_viz.viserkit.seen`). An id this tpm-viz does not have: one line in the tab.
- **Score back** (:meth:`Graded.sink`, the gradebook's :data:`~tpm_viz.classroom.results.ScoreSink`, called on the
  grading thread after a graded answer is kept): the student's open tabs (same identity) whose launch is a
  Learner's link to *that* exercise give the launch's ``ref``; the score is handed to the grade sender
  (:meth:`tpm_viz.lti.grades.GradeSender.submit`: it checks the AGS score scope and the line item, queues in the
  store and sends in the background). The fraction is the exercise's score: the best of the attempts at this seed
  (after the ladder, 0..1), with :attr:`~tpm_viz.classroom.launches.Rule.BEST` (the exercise engine's attempt rule:
  docs/exercises.md). No such tab open: nothing is sent (a student answers in the tab the course opened).
- **Told**: the grade sender's news reach the student's open tabs' message line, each once: *on its way* (the LMS
  does not answer yet: the score waits in the store and is tried again), then *in the course's gradebook* or
  *refused* (kept on the server; the lecturer is told by the log).
"""

from __future__ import annotations

import html
import itertools
import json
import weakref
from typing import Any

from tpm_viz.classroom.guard import log
from tpm_viz.classroom.launches import Launch, News, Role, Rule
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Phrase, T
from tpm_viz.ui.panels import GROUPS
from tpm_viz.ui.shown import show_text
from tpm_viz.ui.teaching.exercises.tab import TAB

__all__ = ["NEWS", "Graded", "grade_launches"]

NEWS = {
    News.ON_ITS_WAY: T(
        "Your grade for {title} is on its way to the course: the course does not answer yet, and tpm-viz keeps trying."
    ),
    News.SENT: T("Your grade for {title} is in the course's gradebook."),
    News.REFUSED: T("The course refused your grade for {title}; it is kept here: tell your lecturer."),
}
"""What a student is told of a grade, by news (templates: ``title`` is the exercise's)."""
_STAMPS = itertools.count(1)


def _unknown(ident: str) -> Phrase:
    return Phrase("The course's link names the exercise {id}, which this tpm-viz does not have.", id=ident[:70])


class Graded:
    """The LMS's exercises of one app (``app``: its ``hub``, ``lti``, ``exercises``, ``views``)."""

    def __init__(self, app: Any) -> None:
        self.app = app
        self.shown: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()
        """The *show this tab* element each tab was given (its HTML; tests)."""

    # -- a launch's exercise, in its tab ---------------------------------------------------------------------------
    def open_exercise(self, view: Any, launch: Launch) -> None:
        """Open ``launch.exercise`` in ``view`` (not under the hub's lock; see the module docstring)."""
        ident = str(launch.exercise)
        exercises = view.teaching.exercises
        if not any(e.id == ident for d in exercises.lessons for e in d.exercises):
            with self.app.hub.locked():
                view.tell(_unknown(ident))
                view.client.flush()
            return
        view.teaching.open("teach")  # the Exercises tab, built now (it takes the lock)
        with self.app.hub.locked():
            if view.closed:
                return
            if launch.role is Role.STUDENT and view.session.shared:
                view.switch(True)
                view.panel.own_copy.value = True  # echoed with client=None: ignored
            exercises.show(ident)
            self._reveal(view)
            view.client.flush()
        log.info("client %s opened exercise %s from the LMS", view.client.client_id, ident)

    def _reveal(self, view: Any) -> None:
        """Ask the page to show *Teach › Exercises* (under the hub's lock)."""
        path = [show_text(view.lang, "label", GROUPS["teach"]), show_text(view.lang, "label", TAB.template)]
        stamp = f"{view.client.client_id}-{next(_STAMPS)}"
        mark = Html(
            f'<div data-tpmviz-show="{html.escape(stamp)}" data-path="{html.escape(json.dumps(path))}" hidden></div>'
        )
        view.gui.add_html(mark)  # once per tab: a tab arrives with one launch
        self.shown[view] = str(mark)

    # -- scores back to the course ---------------------------------------------------------------------------------
    def sink(self, identity: str, exercise: str, best: float, latest: float) -> None:
        """The gradebook kept a graded answer of ``identity`` to ``exercise`` (module docstring)."""
        grades = getattr(self.app.lti, "grades", None)
        if grades is None:
            return
        tabs = self._tabs(identity)
        launch = next(
            (
                v.launch
                for v in tabs
                if v.launch is not None and v.launch.exercise == exercise and v.launch.role is Role.STUDENT
            ),
            None,
        )
        if launch is None:
            return
        item = self.app.exercises.book.exercises.get(exercise)
        title: Any = exercise if item is None else item.exercise.title.phrase()
        news = grades.submit(launch.ref, exercise, best, Rule.BEST, tell=lambda n: self._tell(identity, title, n))
        log.info("LTI grade of exercise %s: %s", exercise, news.value)

    def _tabs(self, identity: str) -> list[Any]:
        out = []
        for view in self.app._tabs():
            mine = getattr(getattr(view, "teaching", None), "exercises", None)
            if mine is not None and mine.identity == identity and not view.closed:
                out.append(view)
        return out

    def _tell(self, identity: str, title: Any, news: News) -> None:
        """``news`` of a grade, to the student's open tabs (from the grade sender's thread)."""
        template = NEWS.get(news)
        if template is None:
            return
        phrase = Phrase(template.template, title=title)
        for view in self._tabs(identity):
            with self.app.hub.locked():
                if not view.closed:
                    view.tell(phrase)
                    view.client.flush()


def grade_launches(app: Any) -> Graded:
    """A :class:`Graded` for ``app`` (its launches opened, its scores sent back)."""
    graded = Graded(app)
    app.launched.open_exercise = graded.open_exercise
    app.exercises.score_sink = graded.sink
    return graded
