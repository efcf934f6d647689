"""The exercises of one browser tab: the *Teach › Exercises* tab (every lesson's, by lesson) and the current lesson's
under its text in *Demos*; both show the same state (:class:`~.text.Mine` per exercise), drawn in every card of it.

- Who the student is comes from the app when the tab has connected (:meth:`ExercisesView.identify`, the identity
  the server issued); the prompts with the student's numbers and their attempts so far are then read in the fair
  worker (:meth:`ExercisesView.refresh`, never under the hub's lock), and again when the lecturer fixes or unfixes a
  class seed, or another tab of the same student answered.
- *Submit* (or Enter in the answer box) grades the typed text as the student's next attempt
  (:meth:`tpm_viz.classroom.results.Gradebook.submit`: kept in the store before the tab is told); a ``gains``
  exercise (``exercise.heavy``) in the fair worker with a "grading…" state, the others on the callback's thread;
  never under the hub's lock. One submission per exercise at a time.
- *Use current pose* writes the platform's position of the tab's session (mm) into the answer box.
"""

from __future__ import annotations

import contextlib
import functools
import html
import itertools
import weakref
from collections.abc import Callable, Sequence
from typing import Any

from tpm_viz.app.demos import Demo
from tpm_viz.app.exercises.catalogue import listed
from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.results import NO_ATTEMPTS, Submitted
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html, Markdown
from tpm_viz.core.words import Phrase, T, say
from tpm_viz.ui.teaching.exercises.card import Card
from tpm_viz.ui.teaching.exercises.text import NO_EXERCISES, Mine
from tpm_viz.ui.worded import TabGui, Worded

__all__ = ["TAB", "ExercisesView", "State"]

INTRO = T(
    "Practice that grades itself: each lesson's exercises with your own numbers. Type an answer as anywhere in the "
    "app (units, decimal commas) and press Submit or Enter. An answer that cannot be read uses no attempt."
)
BOX = T("Exercises of this lesson")
LESSON = T("Lesson")
NONE = T("(no exercises)")
TAB = T("Exercises")
"""The tab's name (in *Teach*)."""
State = dict[str, tuple[int, Phrase | None, Phrase | None, tuple[Any, ...]]]
"""What :meth:`~.desk.ExerciseDesk.states` reads for a student: exercise id -> (seed, prompt, problem, attempts)."""
_STAMPS = itertools.count(1)


def _call_if_alive(method: weakref.WeakMethod[Callable[[], None]]) -> None:
    """A deferred call that does not keep its tab alive."""
    call = method()
    if call is not None:
        call()


def _why(error: Exception | None) -> Phrase:
    """What to tell about a submission that got no grade: the refusal's words, or that a bug was logged."""
    if error is None:
        return T("not graded: try again")
    if isinstance(error, TpmVizError):
        return reason(error)
    return Phrase("internal error ({kind}), logged on the server", kind=type(error).__name__)


def _failed(owner: ExercisesView, exc: Exception) -> None:
    owner.view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__), resync=False)


class ExercisesView:
    """The exercises of one tab (``view``: its :class:`~tpm_viz.ui.client.ClientView`; ``services``: the hub's,
    whose ``exercises`` is the app's :class:`~.desk.ExerciseDesk`; ``lesson``: the *Demos* tab's lesson index)."""

    def __init__(self, view: Any, services: Any, lessons: Sequence[Demo], lesson: Callable[[], int]) -> None:
        self.view, self.services, self.lessons, self._lesson = view, services, tuple(lessons), lesson
        self.mine = {item.exercise.id: Mine(item.exercise) for item in listed(self.lessons)}
        self.cards: dict[str, list[Card]] = {key: [] for key in self.mine}
        self.identity: str | None = None
        """The student's stored identity (set by :meth:`identify`)."""
        self.number: int | None = None
        """The student's number in the lecturer's table (``Student 7``), once known."""
        self._box: Worded | None = None
        self._box_lesson: int | None = None
        self._gui: TabGui | None = None
        self._tab: Any = None
        self._shelf: Worded | None = None
        self._tab_lesson: str | None = None
        self.choice: Any = None
        """The *Exercises* tab's *Lesson* dropdown (once the tab is built)."""
        self.whoami: Worded | None = None

    # -- building --------------------------------------------------------------------------------------------------
    def build(self, gui: TabGui, tab: Worded) -> None:
        """The *Exercises* tab's widgets (inside ``tab``'s context, under the hub's lock): the lesson to show (first,
        so that the tab's first control is in view), then its exercises."""
        self._gui, self._tab = gui, tab
        titles = tuple(d.title for d in self.lessons if d.exercises)
        shown = self.lessons[self._lesson()].title if 0 <= self._lesson() < len(self.lessons) else ""
        self.choice = gui.add_dropdown(
            LESSON.template, titles or (NONE.template,), initial_value=shown if shown in titles else None
        )
        self.choice.disabled = not titles
        gui.add_markdown(Markdown(INTRO.template if titles else NO_EXERCISES.template))  # the catalogue's words
        self.whoami = gui.add_html(self._whoami())
        self._fill_tab(inside=True)
        self.choice.on_update(self._on_lesson)
        if any(mine.prompt is None and mine.problem is None for mine in self.mine.values()):
            self.refresh()  # asked for now: not at the quiet moment it waits for

    def _fill_tab(self, inside: bool = False) -> None:
        """The chosen lesson's exercises, in a folder of its name (the last element of the tab; ``inside``: called
        in the tab's context already)."""
        title = self.choice.value
        if title == self._tab_lesson or self._gui is None or self._tab is None:
            return
        self._tab_lesson = title
        self._drop(box=False)
        if self._shelf is not None:
            self._shelf.remove()
        demo = next((d for d in self.lessons if d.title == title), None)
        self._shelf = None
        if demo is not None and demo.exercises:
            with contextlib.nullcontext() if inside else self._tab:
                self._shelf = self._gui.add_folder(demo.title, expand_by_default=True)
            with self._shelf:
                for exercise in demo.exercises:
                    self._card(self._gui, exercise.id)

    def show(self, key: str) -> bool:
        """Choose the lesson of exercise ``key`` in the *Exercises* tab (built) and draw its cards (under the hub's
        lock). False: no exercise ``key`` in this tab's lessons."""
        demo = next((d for d in self.lessons if any(e.id == key for e in d.exercises)), None)
        if demo is None or self.choice is None:
            return False
        if self.choice.value != demo.title:
            self.choice.value = demo.title  # echoed with client=None: _on_lesson ignores it
        self._fill_tab()
        return True

    @guarded(on_error=_failed)
    def _on_lesson(self, event: Any) -> None:
        if not self._user(event):
            return
        with self.view.hub.locked():
            self._fill_tab()
            self.view.client.flush()

    def lesson_box(self, gui: TabGui) -> None:
        """The folder under the lesson's text in *Demos* (inside that tab's context): the lesson's exercises."""
        self._box = gui.add_folder(BOX.template, expand_by_default=True)
        self._fill_box()

    def _card(self, gui: TabGui, key: str) -> None:
        self.cards[key] = [c for c in self.cards[key] if not c.gone] + [Card(gui, self.mine[key], self)]

    def _fill_box(self) -> None:
        index = self._lesson()
        if self._box is None or index == self._box_lesson:
            return
        self._box_lesson = index
        self._drop(box=True)
        exercises = self.lessons[index].exercises if 0 <= index < len(self.lessons) else ()
        with self._box:
            for exercise in exercises:
                self._card(self.view.gui, exercise.id)
                self.cards[exercise.id][-1].box = True
        self._box.visible = bool(exercises)

    def _drop(self, box: bool) -> None:
        """Take out the cards under the lesson's text (``box``) or those of the *Exercises* tab."""
        for key, cards in self.cards.items():
            for card in [c for c in cards if c.box == box]:
                card.remove()
            self.cards[key] = [c for c in cards if c.box != box and not c.gone]

    def _whoami(self) -> Html:
        if self.number is None:
            return Html("")
        line = say(self.view.lang, Phrase("You are Student {number} in the lecturer's table.", number=self.number))
        return Html(f'<div data-q="exercise-whoami" style="font-size:0.85em;color:#334155">{html.escape(line)}</div>')

    # -- drawing ---------------------------------------------------------------------------------------------------
    def draw(self, key: str | None = None) -> None:
        """Every card of ``key`` (default: of every exercise) again (under the hub's lock)."""
        lang = self.view.lang
        for name in (key,) if key is not None else tuple(self.cards):
            self.cards[name] = [c for c in self.cards[name] if not c.gone]
            for card in self.cards[name]:
                card.draw(self.mine[name], lang)
        whoami = self._whoami()
        if self.whoami is not None and self.whoami.content != whoami:
            self.whoami.content = whoami

    def render(self, frame: Snapshot) -> None:
        """The lesson changed in *Demos* (shown, or set by the lecture): its exercises under its text."""
        self._fill_box()

    def retell(self) -> None:
        """The tab's language changed: the prompts and results again, in it (under the hub's lock)."""
        self.draw()

    # -- who and what ----------------------------------------------------------------------------------------------
    def identify(self, identity: str) -> None:
        """The student is ``identity``: read their numbers and attempts (:meth:`refresh`) at the next quiet moment
        (:class:`~tpm_viz.classroom.later.Later`: a class reconnecting at once gets its mechanisms back first)."""
        self.identity = identity
        later = getattr(self.services, "later", None)
        if later is None:
            self.refresh()
        else:
            later.add(functools.partial(_call_if_alive, weakref.WeakMethod(self.refresh)))

    def refresh(self) -> None:
        """Read the student's prompts and attempts again, in the fair worker, then draw them."""
        desk, identity = self.services.exercises, self.identity
        if desk is None or identity is None or self.view.closed:
            return
        self.services.worker.submit(
            ("exercises", "state"), lambda: desk.states(identity, tuple(self.mine)), self._states, tab=self.view
        )

    def _states(self, result: object, error: Exception | None) -> None:
        with self.view.hub.locked():
            if self.view.closed:
                return
            if error is not None or not isinstance(result, tuple):
                for mine in self.mine.values():
                    mine.problem = _why(error)
            else:
                states, self.number = result
                for key, (seed, prompt, problem, attempts) in states.items():
                    mine = self.mine[key]
                    if mine.seed != seed:  # new numbers (a class seed, or back to their own): a fresh result line
                        mine.score = mine.feedback = mine.error = None
                    elif len(attempts) < len(mine.attempts):  # read before an answer this tab was told of: kept
                        attempts = mine.attempts
                    mine.seed, mine.prompt, mine.problem, mine.attempts = seed, prompt, problem, attempts
            self.draw()
            self.view.client.flush()

    # -- the cards' buttons ----------------------------------------------------------------------------------------
    def _user(self, event: Any) -> bool:
        return getattr(event, "client", None) is not None and not self.view.closed

    @guarded(on_error=_failed)
    def on_key(self, card: Card, event: Any) -> None:
        if not self._user(event):
            return
        with self.view.hub.locked():
            entered = card.entered()
        if entered:
            self._submit(card)

    @guarded(on_error=_failed)
    def on_submit(self, card: Card, event: Any) -> None:
        if self._user(event):
            self._submit(card)

    @guarded(on_error=_failed)
    def on_pose(self, card: Card, event: Any) -> None:
        if not self._user(event):
            return
        with self.view.hub.locked():
            p = self.view.session.state.pose.p
            card.write(f"{p[0] * 1e3:.2f}; {p[1] * 1e3:.2f}")
            self.view.client.flush()

    def _submit(self, card: Card) -> None:
        desk, mine = self.services.exercises, self.mine[card.id]
        with self.view.hub.locked():
            if desk is None or self.identity is None or mine.prompt is None or mine.grading or self.view.closed:
                return
            text, identity, heavy = card.text(), self.identity, mine.exercise.heavy
            if mine.left == 0:
                mine.error, mine.refused, mine.stamp = NO_ATTEMPTS, True, self._stamp()
            else:
                mine.grading = True
            self.draw(card.id)
            self.view.client.flush()
            if not mine.grading:
                return
        if heavy:
            submitted = self.services.worker.submit(
                ("exercises", card.id),
                lambda: desk.book.submit(identity, card.id, text),
                lambda result, error: self._answered(card.id, result, error),
                tab=self.view,
                dropped=lambda: self._answered(card.id, None, None),
            )
            if not submitted:
                self._answered(card.id, None, None)
            return
        try:
            result: object = desk.book.submit(identity, card.id, text)
        except Exception as exc:  # told to the tab; a bug is logged by the guard too
            self._answered(card.id, None, exc)
            if not isinstance(exc, TpmVizError):
                raise
            return
        self._answered(card.id, result, None)

    def _stamp(self) -> str:
        return f"{self.view.client.client_id}-{next(_STAMPS)}"

    def _answered(self, key: str, result: object, error: Exception | None) -> None:
        """A submission's outcome (``result`` a :class:`Submitted`; None with no ``error``: dropped unanswered)."""
        with self.view.hub.locked():
            if self.view.closed:
                return
            mine = self.mine[key]
            mine.grading, mine.stamp = False, self._stamp()
            if isinstance(result, Submitted):
                mine.attempts = result.attempts
                graded = result.grade
                if graded is None or graded.format_error is not None:
                    mine.error = result.refusal if graded is None else graded.format_error
                    mine.refused = graded is None
                else:
                    mine.score, mine.feedback, mine.error = graded.score, graded.feedback, None
                    if self.number is None:
                        self.number = self.services.exercises.number(self.identity)
            else:
                mine.error, mine.refused = _why(error), True
            self.draw(key)
            self.view.client.flush()
