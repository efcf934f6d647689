"""Classroom state: one shared mechanism, private copies, one lock that serialises every change.

No viser here. A :class:`Session` holds one :class:`AppState` and the views (browser tabs) that show it; the
:class:`Hub` owns the shared session, hands out private copies, and runs every change under a single re-entrant
lock, so callbacks that arrive concurrently from viser's thread pool apply one after the other. Callbacks read
the *current* value of their widget inside the lock, so an older event that runs late applies the latest value
(latest value wins) instead of undoing a newer one.

Incoming widget values are untrusted (the browser does not range-check them): the readers of :mod:`.validate`
(re-exported here: :func:`read_vec2`, :func:`read_number`) check them and raise :class:`~tpm_viz.InputError`.
With a presenter token (:mod:`.access`) only the presenter's tabs may commit to the shared session.
A failure while drawing one tab is logged and does not stop the others (:mod:`.guard`).

A session's mechanism is drawn once per commit, in its ``scene`` (for the shared session one broadcast drawing that
every tab receives; for a private copy its tab's own drawing), then each view draws its own part (gizmo, panel).
"""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import AbstractContextManager
from typing import Any, Protocol

import numpy as np

from tpm_viz.app.inputs import read_number, read_vec2
from tpm_viz.app.readouts import Readout, Reference, evaluate, with_reference
from tpm_viz.app.state import AppState
from tpm_viz.classroom.access import Access
from tpm_viz.classroom.drags import DragQueue
from tpm_viz.classroom.guard import report
from tpm_viz.classroom.pacing import BUSY_NUMBERS_INTERVAL, LIVE_NUMBERS_INTERVAL, Pacer
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Lang, Phrase

__all__ = ["AppState", "Hub", "Session", "View", "read_number", "read_vec2"]


class Drawing(Protocol):
    """The 3D drawing of a session's mechanism (:class:`~tpm_viz.ui.scene.MechanismScene`)."""

    def update(self, frame: Snapshot) -> None:
        """Draw ``frame`` (a no-op if it is the frame last drawn)."""


class View(Protocol):
    """What the hub, the runs and the teaching tabs use of a browser tab (:class:`~tpm_viz.ui.client.ClientView`):
    the typed context of every sub-view. Nothing reaches into a view's private fields."""

    closed: bool
    hub: Hub
    lang: Lang
    """The tab's language: render its words with ``say(view.lang, phrase)`` (:mod:`tpm_viz.core.words`)."""

    def __hash__(self) -> int: ...  # views are dictionary keys (drag queues, presenter sets)

    session: Session
    client: Any
    """The tab's ``viser.ClientHandle`` (its own scene, GUI, downloads)."""
    gui: Any
    """The tab's GUI (a ``tpm_viz.ui.worded.TabGui``): every element made through it is shown in the tab's language."""

    def render(self, frame: Snapshot, *, dragging: bool) -> None:
        """Draw ``frame``; ``dragging`` is True while this tab's own gizmo is being dragged."""

    def refuse(self, text: str | Phrase | BaseException, resync: bool = True) -> None:
        """Tell this tab (only) that its input was refused, and why (an error: its phrase, in the tab's language)."""

    def run_changed(self) -> None:
        """The session's trajectory run changed (loaded, playing, paused): redraw the player."""

    def drag_ended(self) -> None:
        """This tab's drag was merged into another tab's commit and has ended: write its gizmo back."""

    def commit_drag(self, phase: str, position: np.ndarray) -> None:
        """Commit this tab's drag to ``position`` [m] (under the hub's lock; it may be merged from other tabs)."""

    def tell(self, text: str | Phrase) -> None:
        """Show ``text`` in this tab's message line (empty: clear it)."""


class Session:
    """One mechanism state and the views that show it (mutated only under the hub's lock)."""

    def __init__(self, state: AppState, shared: bool, scene: Drawing | None = None) -> None:
        self.state = state
        self.shared = shared
        self.scene = scene
        """Where the mechanism is drawn once per commit, or None (each view draws it)."""
        self.views: list[View] = []
        self.frame: Snapshot | None = None
        """The snapshot last drawn, None until the first draw."""
        self.play_token = 0  # a playing trajectory stops when this changes
        self.drags: DragQueue[View] = DragQueue()
        """Gizmo drags waiting to be committed (latest value wins across the tabs, :mod:`.drags`)."""

    @property
    def readout(self) -> Readout | None:
        """The readout of the state last drawn."""
        return None if self.frame is None else self.frame.readout


class Hub:
    """The shared session and the private copies; :meth:`commit` is the only way state changes."""

    def __init__(
        self,
        state: AppState,
        reference: Reference | None = None,
        access: Access | None = None,
        scene: Drawing | None = None,
    ) -> None:
        self.lock = threading.RLock()
        """Re-entrant; outside the classroom layer it is taken through :meth:`locked` only."""
        self.shared = Session(state, shared=True, scene=scene)
        self.reference = reference
        self.access = access if access is not None else Access()
        """Who may commit to the shared session (everybody unless a presenter token is set)."""
        self.on_membership: Callable[[], None] | None = None
        self.arrivals = itertools.count()
        """Numbers gizmo events in arrival order (they arrive on the event loop, one at a time)."""
        self.pacer = Pacer()
        """How often a dragged own copy may be redrawn (:mod:`tpm_viz.classroom.pacing`): every drag commit if the
        server
        keeps up, less often when thirty students drag their own copies at once."""
        self.drag_pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="tpm-viz-drag")
        """Where drags of a session shown by many tabs are committed: two threads (they serialise on the lock); a
        plain executor, not ``loop.run_in_executor``, so that finishing a drag does not wake the event loop."""

    def locked(self) -> AbstractContextManager[bool]:
        """The one context in which a view reads or draws the shared state and the private copies, and calls
        :meth:`commit` (re-entrant: a callback under it may call code that takes it again)."""
        return self.lock

    def evaluate(self, state: AppState, live: bool = False) -> Readout:
        """All numbers for ``state``: closed form and reference (Pinocchio) forces. ``live`` (an intermediate frame
        of a drag or a playback) leaves the reference out: :meth:`frame` adds it lazily, for the dashboards that
        are actually redrawn (4 Hz mid-drag, once a second on a busy server), so every displayed force has both
        numbers beside it."""
        return evaluate(state.params, state.pose, state.load, None if live else self.reference)

    def frame(self, state: AppState, dragging: bool = False) -> Snapshot:
        """The :class:`~tpm_viz.classroom.snapshot.Snapshot` of ``state`` with the data every view draws, computed
        and checked
        before anything changes: raises :class:`~tpm_viz.InputError` if a drawn number is not finite."""
        frame = Snapshot(state, self.evaluate(state, live=dragging), in_drag=dragging)
        if dragging and self.reference is not None:  # both models, computed when displayed (the kinematics once)
            live, reference = frame.readout, self.reference
            frame.complete_readout = lambda: with_reference(live, state.params, state.pose, state.load, reference)
        positions, wxyzs = frame.links
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(wxyzs))):
            raise InputError("this pose cannot be drawn (non-finite geometry); the last good state stays")
        return frame  # its texts print a dash for any non-finite number (tpm_viz.classroom.text.num)

    def authorize(self, view: View, session: Session) -> None:
        """Raise :class:`~tpm_viz.classroom.access.AccessDenied` unless ``view`` may change ``session``."""
        self.access.check(view, session)

    def join(self, view: View, private: bool, session: Session | None = None, scene: Drawing | None = None) -> Session:
        """Attach ``view`` to the shared session, or to a new private copy of ``session``'s state drawn in
        ``scene``: sets ``view.session``, then draws it. A tab joins once it is fully built (and switches by
        leaving and joining again).

        The caller then calls :meth:`membership_changed`."""
        with self.lock:
            source = session if session is not None else self.shared
            if private:
                target = Session(source.state, shared=False, scene=scene)
                target.frame = source.frame  # same state: same drawing
            else:
                target = self.shared
            target.views.append(view)
            view.session = target
            self._draw(target, [view], origin=None, dragging=False)
        return target

    def leave(self, view: View, session: Session) -> None:
        """Detach ``view`` from ``session`` (a tab closed or switched)."""
        with self.lock:
            if view in session.views:
                session.views.remove(view)
            session.drags.drop(view)
        self.membership_changed()

    def commit(self, session: Session, state: AppState, origin: View | None = None, dragging: bool = False) -> None:
        """Make ``state`` current in ``session`` and draw it in every view, ``origin`` first.

        Refused (nothing changes) if ``origin`` may not change ``session`` (the one permission check of a tab's
        change) or the state cannot be drawn. A view that fails to draw is logged and skipped; the others are
        drawn."""
        with self.lock:
            if origin is not None:
                self.authorize(origin, session)
            frame = self.frame(state, dragging)
            frame.follow(session.frame, LIVE_NUMBERS_INTERVAL)
            if dragging and not session.shared and self.pacer.interval(time.monotonic()) > 0:
                frame.numbers_every = BUSY_NUMBERS_INTERVAL  # a busy server: the mechanism first, numbers later
            session.state, session.frame = state, frame
            self._draw(session, list(session.views), origin, dragging)

    def _draw(self, session: Session, views: list[View], origin: View | None, dragging: bool) -> None:
        if session.frame is None:
            session.frame = self.frame(session.state, dragging)
        frame = session.frame
        if session.scene is not None:
            try:
                session.scene.update(frame)  # once for every view of the session
            except Exception as exc:  # e.g. the only tab of a private copy went away mid-push
                report(exc, f"drawing {type(session.scene).__name__}")
        if origin in views:
            views.remove(origin)
            views.insert(0, origin)
        for view in views:
            try:
                view.render(frame, dragging=dragging and view is origin)
            except Exception as exc:  # one broken tab (e.g. gone mid-push) must not stop the others
                report(exc, f"drawing {type(view).__name__}")

    def shared_viewers(self) -> int:
        """How many tabs show the shared mechanism."""
        return len(self.shared.views)

    def membership_changed(self) -> None:
        """Tell the app that tabs joined, left or switched sessions (it updates the classroom line)."""
        if self.on_membership is not None:
            self.on_membership()
