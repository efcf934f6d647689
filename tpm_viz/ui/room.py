"""The classroom around the app: who presents, tabs that come back, the session file and its download.

:class:`Room` is what :class:`~.app.TpmApp` calls when a tab connects (:meth:`Room.identify` before its view is
built, :meth:`Room.connected` after), leaves (:meth:`Room.leaving`) or logs in (:meth:`Room.promoted`), and what
the *Lecturer* folder (:mod:`.lecturer`) calls to save, open and hand over the session. Under the hub's lock like
every other change; no maths here.
"""

from __future__ import annotations

import sys
import time
import weakref
from collections.abc import Callable
from typing import Any, TypeVar

from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.away import UPLOAD_NOT_KEPT, Away
from tpm_viz.classroom.guard import guarded, log
from tpm_viz.classroom.network import is_loopback
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.ui.classroom import Classroom, identity, student_urls
from tpm_viz.ui.continuity import LectureStore, lecture_store, reload, restore, saved_of
from tpm_viz.ui.lecturer import LecturerPanel
from tpm_viz.viserkit.core import connection_request

__all__ = ["BACK", "BACK_WITHOUT_UPLOAD", "KEPT", "LOGGED_OUT", "Room"]

V = TypeVar("V")

BACK = T("Welcome back: your own copy from before the connection dropped is restored.")
BACK_WITHOUT_UPLOAD = T(
    "Welcome back: your own copy from before the connection dropped is restored, without its uploaded trajectory "
    "(the server keeps only so many for tabs that left): upload the CSV again."
)


def _back(record: dict[str, Any]) -> Phrase:
    """What a tab that got its own copy back is told (its upload may have been let go: :mod:`.away`)."""
    return BACK_WITHOUT_UPLOAD if record.get(UPLOAD_NOT_KEPT) else BACK


STUDENT = T("Students: you watch the presenter here, or work on your own copy.")
"""The login folder's line for a tab that is not the presenter's (:class:`~.login.LoginPanel`)."""
LOGGED_OUT = "You logged out as presenter: the shared mechanism is no longer yours to change."
KEPT = (
    "The connection dropped and you are now on the shared mechanism. Your own copy from before is kept for "
    "30 minutes: press 'Restore my own copy from before the drop'."
)


class Room:
    """Classroom mode, continuity and persistence of one app (``app``: its ``server``, ``hub``, ``access``,
    ``services``, ``views``)."""

    def __init__(self, app: Any, classroom: Classroom | None = None, store: LectureStore | None = None) -> None:
        self.app = app
        self.classroom = classroom
        self.store = store if store is not None else lecture_store(None)
        self.away = Away()
        self.lesson_step = 0
        self.urls: list[str] | None = None
        self.notice = ""
        """The last line about the store (set aside, not saving, saving again): in every lecturer's panel."""
        self._keys: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()
        self._lecturers: weakref.WeakKeyDictionary[Any, LecturerPanel] = weakref.WeakKeyDictionary()
        self.ready: weakref.WeakSet[Any] = weakref.WeakSet()
        """The tabs :meth:`connected` has finished with (tests wait for it)."""
        self._back: weakref.WeakKeyDictionary[Any, dict[str, Any]] = weakref.WeakKeyDictionary()
        """Tabs that are back (built by :meth:`build`) -> the record they left, until :meth:`connected`."""
        self.lecturer_hooks: list[Callable[[Any, LecturerPanel], None]] = []
        """Called with each tab given a *Lecturer* folder and the folder (under the hub's lock): more in it."""

    # -- start and stop ---------------------------------------------------------------------------------------------
    def start(self) -> None:
        """Read the store (the lecture and the tabs that were away; its notices go to the lecturer's panel) and save
        from now on."""
        if self.classroom is not None:
            self.urls = student_urls("0.0.0.0", self.app.port, self.classroom.addresses())
        doc, tabs = self.store.load()
        if doc is not None:
            try:
                self._apply_shared(doc, origin=None)
            except TpmVizError as exc:
                self.store.notices.append(f"the saved lecture: {exc}; starting with the defaults")
                print(f"warning: {self.store.notices[-1]}", file=sys.stderr, flush=True)
        self.away.restore(tabs)
        self.notice = self.store.notices[-1] if self.store.notices else ""
        self.store.start(self.document, self.say)

    def stop(self) -> None:
        self.store.stop()

    def say(self, line: str, problem: bool) -> None:
        """A line about saving: on the terminal once, and in every lecturer's panel until the next one."""
        print(f"warning: {line}" if problem else line, file=sys.stderr, flush=True)
        self.notice = line
        with self.app.hub.locked():
            for panel in list(self._lecturers.values()):
                panel.show_notice(line)

    # -- tabs -------------------------------------------------------------------------------------------------------
    def identify(self, client: Any) -> tuple[str | None, str, Any]:
        """``(identity, source address, camera)`` of a connecting tab, read before its view moves the camera."""
        request = connection_request(self.app.server, client.client_id)
        remote, headers = request if request is not None else (("?", 0), None)
        host = remote[0] if isinstance(remote, (tuple, list)) and remote else "?"
        try:
            camera = tuple(client.camera.position) + tuple(client.camera.wxyz)
        except Exception:  # no camera yet
            camera = None
        return identity(remote, headers, self.store.keys), str(host), camera

    def build(self, who: tuple[str | None, str, Any], make: Callable[[Saved | None], V]) -> V:
        """Build a connecting tab's view with ``make(saved)``: a browser known by its cookie (or an LMS user,
        :mod:`.launched`) that left an own copy (:meth:`identify`'s ``who``) is built on that copy from its first
        draw (``saved``), any other on the shared mechanism (None). What it left is taken back here, and kept again
        if the build fails."""
        key, host, camera = who
        known = key is not None and key.startswith(("c:", "u:"))  # a signed cookie, or an LMS user (.launched)
        record = self.away.take(key, camera) if known and key is not None else None  # its own lock
        own = record is not None and record["private"] and record["saved"] is not None
        try:
            view = make(record["saved"] if own and record is not None else None)
        except BaseException:
            if record is not None:  # not lost: the next tab of this browser finds it (never as the presenter)
                self.away.park(key or "", record["private"], record["saved"], record.get("camera"), address=host)
            raise
        if record is not None:
            self._back[view] = record
        return view

    def source(self, view: Any) -> str | None:
        """The address a tab connected from (the key of the presenter-login limits)."""
        return getattr(view, "address", None)

    def connected(self, view: Any, who: tuple[str | None, str, Any]) -> None:
        """A tab's view is built (by :meth:`build`): presenter or not, and what it had before a drop (a browser known
        by its cookie gets it back by itself; one that blocks cookies is offered its own copy)."""
        key, host, _camera = who
        if key is not None:
            self._keys[view] = key
        view.address = host
        hub = self.app.hub
        with hub.locked():
            record = self._back.pop(view, None)
            here = self.classroom is not None and self.classroom.presenter_address(host)
            back = self.away.presenter(record, host)  # same address, within 2 minutes: never the cookie alone
            if self.app.access.enabled and (here or back):
                self.app.access.grant(view)  # this computer, or the presenter's device back after a drop
                if view.login is not None:
                    here_or_back = T("**You are the presenter** (this computer).")
                    if not here:
                        here_or_back = T("**You are the presenter**: welcome back.")
                    view.login.show(say(Lang.EN, here_or_back))  # shown in the tab's language by its handle
            if self.lecturer(view):
                self._add_lecturer(view)
            self._set_lesson_step(view)
            view.panel.restore.on_click(lambda event, view=view: self._on_restore(event, view))
            if record is not None:
                restore(view, record["saved"], record["private"] and record["saved"] is not None, built=True)
                if record["private"]:
                    view.tell(_back(record))
            elif key is not None and self.away.offer(key) is not None:
                view.panel.restore.visible = True
                view.tell(KEPT)
            view.client.flush()
            self.ready.add(view)

    def leaving(self, view: Any) -> None:
        """A tab is closing (or its connection dropped): keep what it had for 30 minutes (its data, not the tab:
        the lecturer panel refers to the view, so it must go with it or the weak keys would never die)."""
        self._lecturers.pop(view, None)
        key = self._keys.pop(view, None)
        if key is None or view.closed:
            return
        with self.app.hub.locked():
            try:
                camera = tuple(view.client.camera.position) + tuple(view.client.camera.wxyz)
            except Exception:
                camera = None
            private = not view.session.shared
            presenter = self.app.access.is_presenter_tab(view)
            self.away.park(key, private, saved_of(view), camera, presenter=presenter, address=view.address)

    @guarded
    def _on_restore(self, event, view: Any) -> None:
        if getattr(event, "client", None) is None or view.closed:
            return
        key = self._keys.get(view)
        with self.app.hub.locked():
            record = None if key is None else self.away.offer(key)
            view.panel.restore.visible = False
            if key is None or record is None or not self.away.claim(key, record):
                view.tell("That copy is no longer kept (30 minutes passed, or another tab took it back).")
                return
            restore(view, record["saved"], True)
            view.tell(_back(record))

    # -- presenter ----------------------------------------------------------------------------------------------------
    def lecturer(self, view: Any) -> bool:
        """Whether ``view`` gets the *Lecturer* folder: its presenter, or anyone when nobody holds the mechanism."""
        access = self.app.access
        return access.is_presenter_tab(view) if access.enabled else True

    def reads_results(self, view: Any) -> bool:
        """Whether ``view`` may read the class's exercise results and fix the class seed: the presenter in presenter
        mode; without it (every tab has the *Lecturer* folder), only a tab on the serving machine, so that a student
        never reads another's answers."""
        access = self.app.access
        if access.enabled:
            return bool(access.is_presenter_tab(view))
        local = self.classroom.lecturer_address if self.classroom is not None else is_loopback
        return local(str(getattr(view, "address", "") or ""))

    def promoted(self, view: Any) -> None:
        """``view`` logged in as the presenter."""
        self.away.end_presenters()  # a new presenter: no dropped tab comes back as one
        if view not in self._lecturers:
            self._add_lecturer(view)

    def log_out(self, view: Any) -> None:
        """*Log out as presenter*: ``view`` is a student's tab from now on (its *Lecturer* folder goes), and no
        presenter tab that dropped from its address comes back as the presenter."""
        access = self.app.access
        with self.app.hub.locked():
            if view.closed or not access.is_presenter_tab(view):
                return
            access.logout(view)
            self.away.end_presenters(address=getattr(view, "address", None))
            panel = self._lecturers.pop(view, None)
            if panel is not None:
                panel.remove()
            if view.login is not None:
                view.login.show(say(Lang.EN, STUDENT))  # shown in the tab's language by its handle
            view.tell(LOGGED_OUT)
            view.client.flush()
            log.info("client %s logged out as presenter", view.client.client_id)
        self.app.hub.membership_changed()

    def _add_lecturer(self, view: Any) -> None:
        bound = is_loopback(str(self.app.server.get_host()))  # --classroom on 127.0.0.1: nobody can join
        panel = LecturerPanel(view.gui, self, view, self.urls, presenter=self.app.access.enabled, loopback=bound)
        panel.show_notice(self.notice)
        self._lecturers[view] = panel
        for hook in self.lecturer_hooks:
            hook(view, panel)

    def hand_to_class(self, view: Any, open_: bool) -> None:
        """The presenter lets the class change the shared mechanism, or takes it back."""
        access = self.app.access
        with self.app.hub.locked():
            if not access.is_presenter_tab(view):
                view.refuse("only the presenter can hand the shared mechanism to the class", resync=False)
                return
            access.open_to_class = open_
            for panel in self._lecturers.values():
                if panel.open_to_class.value != open_:
                    panel.open_to_class.value = open_
            log.info("the shared mechanism is %s", "open to the class" if open_ else "the presenter's again")
        self.app.hub.membership_changed()

    # -- the session as a document ---------------------------------------------------------------------------------
    def document(self) -> Document:
        """The shared mechanism, the lesson step and every tab's own copy (away or still here)."""
        app, hub = self.app, self.app.hub
        with hub.locked():
            runs = app.services.runs
            ps = runs.of(hub.shared)
            source = ps.run.source if ps.run is not None else ps.loading
            shared = Saved(hub.shared.state, source, hub.shared.state.trajectory.t)
            for view in list(hub.shared.views):  # a tab still connecting shows step 0 until connected() sets it
                if view in self.ready and app.access.is_presenter(view):
                    self.lesson_step = int(getattr(view.teaching.demos, "index", self.lesson_step))
                    break
            tabs = self.away.snapshot()
            now = time.time()
            for view in list(app.views.values()):
                key = self._keys.get(view)
                if key is not None and not view.closed:
                    record = {
                        "private": not view.session.shared,
                        "saved": saved_of(view),
                        "left_at": now,
                        "presenter": app.access.is_presenter_tab(view),
                        "address": getattr(view, "address", ""),
                    }
                    tabs.setdefault(key, []).append(record)
        return Document(shared, self.lesson_step, tabs)

    def session_json(self) -> str:
        """The session for *Save session*: the shared mechanism and the lesson step (no students' copies)."""
        doc = self.document()
        return sessionfile.dumps(Document(doc.shared, doc.lesson_step))

    def open_session(self, view: Any, data: bytes) -> None:
        """*Open session*: the shared mechanism becomes the file's (refused with one line to this tab only)."""
        hub = self.app.hub
        with hub.locked():
            try:
                hub.authorize(view, hub.shared)
                choice = getattr(getattr(view.teaching, "demos", None), "choice", None)
                doc = sessionfile.loads(data, steps=None if choice is None else len(choice.options))
                self._apply_shared(doc, origin=view)
            except TpmVizError as exc:
                view.refuse(exc, resync=False)
                return
            view.tell("Session opened.")

    def _apply_shared(self, doc: Document, origin: Any) -> None:
        hub, runs = self.app.hub, self.app.services.runs
        shared = hub.shared
        with hub.locked():
            shared.play_token += 1
            runs.unload(shared)
            hub.commit(shared, doc.shared.state, origin=origin)
            reload(runs, shared, doc.shared)
            self.lesson_step = doc.lesson_step
            for view in list(shared.views):
                self._set_lesson_step(view)

    def _set_lesson_step(self, view: Any) -> None:
        demos = getattr(getattr(view, "teaching", None), "demos", None)
        choice = getattr(demos, "choice", None)
        if demos is None or choice is None or not 0 <= self.lesson_step < len(choice.options):
            return
        demos.index = self.lesson_step
        choice.value = choice.options[self.lesson_step]
