"""The exercises of one app: its gradebook (:class:`tpm_viz.classroom.results.Gradebook`, in the lecture's store),
who each tab's student is, and the lecturer's *Exercise results* in every lecturer's tab, kept live.

:class:`~tpm_viz.ui.app.TpmApp` makes one :class:`ExerciseDesk`, :meth:`~ExerciseDesk.start` s it once the store
is open (the seed key is derived from the cookie secret kept beside it; without a store the results are kept in
memory), tells it each tab's identity when the tab has connected (:meth:`~ExerciseDesk.connected`: a tab without
one, not a browser, gets one of its own for as long as it is open) and each lecturer's folder
(:meth:`~ExerciseDesk.lecturer_added`).

A kept answer redraws the lecturers' tables at most once per :data:`TABLE_DELAY` (the table is read once, outside the
hub's lock, then written into each lecturer's tab in its language; :data:`TABLE_LINES` lines, the CSV has all), and
the other tabs of the same student read their attempts again. :attr:`ExerciseDesk.score_sink` is the LTI grade
passback's hook (:data:`tpm_viz.classroom.results.ScoreSink`; default none).
"""

from __future__ import annotations

import secrets
import sqlite3
import threading
import weakref
from collections.abc import Callable
from typing import Any

from tpm_viz.app.exercises.grading import prompt, variant_of
from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded, log
from tpm_viz.classroom.results import SEED_PURPOSE, Gradebook, ScoreSink
from tpm_viz.classroom.resultsdb import ResultRows, Row
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.words import Phrase, T
from tpm_viz.ui.teaching.exercises.lecturer import CSV_NAME, ResultsSection
from tpm_viz.ui.teaching.exercises.tab import State

__all__ = ["TABLE_DELAY", "TABLE_LINES", "ExerciseDesk"]

TABLE_DELAY = 0.5
"""Longest wait [s] between a kept answer and the lecturers' tables showing it (one redraw for all answers within)."""
TABLE_LINES = 200
"""Lines of the lecturer's table in the panel (the latest answered first; the CSV has every line)."""
LECTURER_ONLY = T("only the lecturer can do this")


class ExerciseDesk:
    """The exercises of one app (``hub``: its lock; ``services``: the lessons and the worker; ``views``: the app's
    tabs by client id; ``lecturer(view)``: whether a tab is the lecturer's)."""

    def __init__(self, hub: Any, services: Any, views: Callable[[], list[Any]], lecturer: Callable[[Any], bool]):
        self.hub, self.services, self._views, self._lecturer = hub, services, views, lecturer
        self.book: Gradebook | None = None
        """The results (None until :meth:`start`)."""
        self._sections: weakref.WeakKeyDictionary[Any, ResultsSection] = weakref.WeakKeyDictionary()
        self._timer: threading.Timer | None = None
        self._lock = threading.Lock()
        self._memory: ResultRows | None = None

    def start(self, lecture: Any) -> None:
        """Open the gradebook of ``lecture`` (the app's :class:`~tpm_viz.classroom.lecture.LectureStore`, opened)."""
        store = getattr(lecture, "store", None)
        if store is None:
            self._memory = rows = ResultRows.memory()
        else:
            rows = store.results
        self.book = Gradebook(rows, lecture.keys.derive(SEED_PURPOSE), self.services.lessons)
        self.book.listeners.append(self._kept)

    @property
    def score_sink(self) -> ScoreSink | None:
        """Called after each graded answer is kept (:data:`~tpm_viz.classroom.results.ScoreSink`); None: nobody."""
        return None if self.book is None else self.book.sink

    @score_sink.setter
    def score_sink(self, sink: ScoreSink | None) -> None:
        if self.book is None:
            raise InputError("the exercises are not started yet")
        self.book.sink = sink

    def stop(self) -> None:
        """No more redraws; a memory gradebook is closed."""
        with self._lock:
            if self._timer is not None:
                self._timer.cancel()
        if self._memory is not None:
            self._memory.close()

    # -- students --------------------------------------------------------------------------------------------------
    def connected(self, view: Any, identity: str | None) -> None:
        """``view``'s student is ``identity`` (None: not a browser, an identity of its own while it is open)."""
        exercises = getattr(getattr(view, "teaching", None), "exercises", None)
        if exercises is not None:
            exercises.identify(identity if identity is not None else f"t:{secrets.token_hex(16)}")

    def states(self, identity: str, keys: tuple[str, ...]) -> tuple[State, int | None]:
        """``identity``'s seed, prompt (or why there is none) and attempts of each exercise ``keys``, and their number
        in the table (in the worker: the variants are drawn here)."""
        book = self._book()
        try:
            return self._states(book, identity, keys)
        except sqlite3.Error as exc:  # the store closed (the app stops) or cannot be read now: said in the cards
            raise InputError(_unreadable(exc)) from None

    def _states(self, book: Gradebook, identity: str, keys: tuple[str, ...]) -> tuple[State, int | None]:
        out: State = {}
        for key in keys:
            exercise, seed = book.exercises[key].exercise, book.seed(identity, key)
            try:
                out[key] = (
                    seed,
                    prompt(exercise, variant_of(exercise, seed)),
                    None,
                    book.attempts(identity, key, seed),
                )
            except TpmVizError as exc:
                out[key] = (seed, None, reason(exc), ())
        return out, book.rows.number(identity)

    def number(self, identity: str | None) -> int | None:
        """The student's number in the table (None before a first graded answer, or when the store cannot say)."""
        try:
            return None if identity is None or self.book is None else self.book.rows.number(identity)
        except sqlite3.Error:
            return None

    def _book(self) -> Gradebook:
        if self.book is None:
            raise InputError("the exercises are not started yet")
        return self.book

    def _kept(self, row: Row) -> None:
        """An answer was kept (on the grading thread): the student's other tabs read theirs again; the tables redraw."""
        for view in self._views():
            exercises = getattr(getattr(view, "teaching", None), "exercises", None)
            if exercises is not None and exercises.identity == row.identity and not view.closed:
                exercises.refresh()
        self._schedule()

    # -- the lecturer ----------------------------------------------------------------------------------------------
    def lecturer_added(self, view: Any, panel: Any) -> None:
        """``view`` got its *Lecturer* folder (``panel``; under the hub's lock): the results section in it, if
        ``view`` may read the results (``lecturer(view)``)."""
        if not self._lecturer(view):
            return
        with panel.folder:
            self._sections[view] = ResultsSection(view.gui, self, view, self._book().class_seed)
        self._schedule()

    def leaving(self, view: Any) -> None:
        """``view`` is closing: its results section goes with it (the section refers to the view, so a weak key
        alone would never die: 60 lecturer's tabs that left held 100 MB, tests/viserkit/test_upload_flood.py)."""
        self._sections.pop(view, None)

    def section(self, view: Any) -> ResultsSection | None:
        """``view``'s *Exercise results* (None: not a lecturer's tab)."""
        return self._sections.get(view)

    def _schedule(self) -> None:
        with self._lock:
            if self._timer is not None:
                return
            self._timer = timer = threading.Timer(TABLE_DELAY, self._redraw)
        timer.daemon = True
        timer.name = "tpm-viz-results"
        timer.start()

    @guarded
    def _redraw(self) -> None:
        with self._lock:
            self._timer = None
        book = self._book()
        try:
            lines, total, seed = book.summary(TABLE_LINES), book.rows.lines(), book.class_seed  # outside the lock
        except sqlite3.Error:  # the store closed (the app stops): nothing to show
            return
        with self.hub.locked():
            for view, section in list(self._sections.items()):
                if view.closed or section.gone or not self._lecturer(view):
                    self._sections.pop(view, None)
                    continue
                section.show(lines, total, seed)
                view.client.flush()

    def retell(self, view: Any) -> None:
        """``view``'s language changed: its table again, in it (under the hub's lock)."""
        if view in self._sections:
            self._schedule()

    def fix(self, view: Any, seed: object) -> None:
        """The lecturer fixes ``seed`` for the class (None: a variant per student again); every tab's numbers follow."""
        if not self._lecturer(view):
            with self.hub.locked():
                view.refuse(LECTURER_ONLY, resync=False)
            return
        try:
            fixed = self._book().fix(seed)
        except (TpmVizError, sqlite3.Error) as exc:
            with self.hub.locked():
                view.refuse(exc if isinstance(exc, TpmVizError) else _unreadable(exc), resync=False)
            return
        log.info("exercises: %s", "a variant per student" if fixed is None else f"class seed {fixed}")
        for other in self._views():
            exercises = getattr(getattr(other, "teaching", None), "exercises", None)
            if exercises is not None and not other.closed:
                exercises.refresh()
        self._schedule()

    def download(self, view: Any) -> None:
        """*Download results (CSV)* (the lecturer's tab only)."""
        if not self._lecturer(view):
            with self.hub.locked():
                view.refuse(LECTURER_ONLY, resync=False)
            return
        try:
            data = self._book().csv().encode("utf-8")
        except sqlite3.Error as exc:
            with self.hub.locked():
                view.refuse(_unreadable(exc), resync=False)
            return
        view.client.send_file_download(CSV_NAME, data, save_immediately=True)


def _unreadable(exc: sqlite3.Error) -> Phrase:
    return Phrase("the results cannot be read now ({why})", why=type(exc).__name__)
