"""A tab that arrives from an LMS launch (``tpm-viz serve --lti``): who it is, whether it presents, what it opens.

:meth:`Launched.arrive` runs before the tab's view is built: it takes the launch its page brought
(:func:`~.classroom.launch_nonce`, spent once: :class:`~tpm_viz.classroom.launches.Tickets`) and makes the tab's
identity the LMS user's (``u:...``: the same own copy and records from every launch and device). A tab that
reconnects without a ticket (a wifi blip, a restart) is found again by its browser (``Tickets.recall``): it
keeps its LMS user and grades, never the presenter's right (that comes back only as :mod:`tpm_viz.classroom.away`
allows). :meth:`Launched.connected` runs after the classroom's part: an Instructor's launch makes the tab the
presenter (:meth:`~tpm_viz.classroom.access.Access.grant`), any other a student; the tab says which and the course;
a link to a lesson opens it (the presenter's on the shared mechanism, a student's on their own copy) and a link to
an exercise is handed to ``Launched.open_exercise`` (:meth:`tpm_viz.ui.graded.Graded.open_exercise`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tpm_viz.classroom.guard import log
from tpm_viz.classroom.launches import Launch, Role, Tickets
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.ui.classroom import launch_nonce
from tpm_viz.viserkit.core import connection_request

__all__ = ["SPENT", "Launched"]

SPENT = T(
    "This tab was opened with a launch link that was used already or has expired: open tpm-viz again from the course."
)
Who = tuple[str | None, str, Any]


class Launched:
    """The launches of one app (``app``: its ``server``, ``hub``, ``access``, ``room``)."""

    def __init__(self, app: Any, tickets: Tickets) -> None:
        self.app, self.tickets = app, tickets
        self.open_exercise: Callable[[Any, Launch], None] | None = None
        """Opens a launch's exercise in a tab (set by :mod:`tpm_viz.ui.graded`; None: the tab says it is not here)."""
        self.arrived = 0
        """Tabs that arrived with a launch (tests)."""

    def arrive(self, client: Any, who: Who) -> tuple[Who, Launch | None, bool]:
        """``(who, launch, fresh)`` of a connecting tab: its identity becomes the LMS user's if it brought a launch
        (``fresh``) or its browser had one (a reconnection); ``launch`` None and ``fresh`` True: a spent ticket."""
        request = connection_request(self.app.server, client.client_id)
        came, launch = self.tickets.take(launch_nonce(None if request is None else request[1]))
        browser = who[0] if who[0] is not None and who[0].startswith("c:") else None
        if came and launch is not None and browser is not None:
            self.tickets.remember(browser, launch)
        if not came and browser is not None:
            launch = self.tickets.recall(browser)
        if launch is None:
            return who, None, came
        return (launch.key, who[1], who[2]), launch, came

    def connected(self, view: Any, launch: Launch | None, fresh: bool) -> None:
        """Apply a tab's launch once its view is built (under the hub's lock, except the lesson it opens)."""
        view.launch = launch
        if launch is None:
            if fresh:
                with self.app.hub.locked():
                    view.tell(SPENT)
            return
        if not fresh:
            return
        self.arrived += 1
        presenter = launch.role is Role.PRESENTER
        with self.app.hub.locked():
            if launch.lang:
                view.words.set(Lang.parse(launch.lang, default=view.lang))
            if presenter:
                self.app.access.grant(view)
            if presenter:
                status = Phrase(
                    "**You are the presenter** of {course} (launched from the course).", course=launch.course
                )
                line = Phrase("You are the presenter of {course}.", course=launch.course)
            else:
                status = Phrase("Student of {course}: you watch the presenter, or work on your own copy.",
                                course=launch.course)  # fmt: skip
                line = Phrase("You joined {course} as a student.", course=launch.course)
            if view.login is not None:
                view.login.show(say(view.lang, status))
            view.tell(line)
            view.client.flush()
        if presenter:
            self.app.room.promoted(view)
            self.app.hub.membership_changed()
        log.info("client %s arrived from the LMS as a %s", view.client.client_id, launch.role.value)
        if launch.lesson is not None:
            self._lesson(view, launch.lesson, presenter)
        if launch.exercise is not None:
            self._exercise(view, launch)

    def _lesson(self, view: Any, number: int, presenter: bool) -> None:
        """Open lesson ``number`` (1-based): on the shared mechanism for the presenter, else on an own copy."""
        demos = view.teaching.demos
        if not 1 <= number <= len(demos.lessons):
            with self.app.hub.locked():
                view.tell(Phrase("The course's link names lesson {n}, which this tpm-viz does not have.", n=number))
            return
        if not presenter:
            with self.app.hub.locked():
                if view.session.shared:
                    view.switch(True)
                    view.panel.own_copy.value = True  # echoed with client=None: ignored
        demos.show(number - 1)

    def _exercise(self, view: Any, launch: Launch) -> None:
        if self.open_exercise is not None:
            self.open_exercise(view, launch)
            return
        with self.app.hub.locked():
            view.tell(Phrase("The course's link names the exercise {id}: exercises are not in this tpm-viz yet.",
                             id=launch.exercise))  # fmt: skip
