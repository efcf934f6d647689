"""The first minute: a short guide at the top of a new browser's panel (what to drag, what the banner and the
singularity buttons are, the colours of the 3D view), dismissed in one click (*Got it*) and not shown again to the
same browser.

A browser is known by the identity the server issued it (its signed ``tpmviz_id`` cookie, hashed:
:func:`tpm_viz.ui.classroom.identity`; a browser that blocks cookies by its address and user agent). Who dismissed the
guide is kept in memory (at most :data:`REMEMBERED` browsers, the least recently seen forgotten first) and, when the
lecture has a store (``tpm-viz serve --session``), as one small entry per browser in it (the store's public
``imported`` / ``mark_imported``, under a hash of the identity: :func:`entry`), so a restart does not show it again.
A store that cannot be written (a full disk) costs only that: the memory still knows.
"""

from __future__ import annotations

import hashlib
import threading
import weakref
from collections import OrderedDict
from typing import Any

from tpm_viz.classroom.guard import guarded, log

__all__ = ["REMEMBERED", "SOURCE", "Guides", "entry"]

REMEMBERED = 4096
"""Browsers whose dismissal is kept in memory (the oldest forgotten first): bounded for a hostile network."""
SOURCE = "first-visit guide dismissed"
"""What the store's entry says it is (its ``source``)."""


def entry(identity: str) -> str:
    """The store's key of a browser's dismissal: SHA-256 (hex) of ``guide:`` and its hashed identity."""
    return hashlib.sha256(f"guide:{identity}".encode("utf-8", "replace")).hexdigest()


class Guides:
    """Which browsers dismissed the guide (``lecture``: the app's :class:`~tpm_viz.classroom.lecture.LectureStore`,
    whose ``store`` is None when nothing is kept). Thread-safe."""

    def __init__(self, lecture: Any = None) -> None:
        self._lecture = lecture
        self._seen: OrderedDict[str, None] = OrderedDict()
        self._lock = threading.Lock()
        self.greeted: weakref.WeakSet[Any] = weakref.WeakSet()
        """The tabs :meth:`greet` has finished with (tests wait for it)."""

    def _store(self) -> Any:
        return getattr(self._lecture, "store", None)

    def seen(self, identity: str | None) -> bool:
        """Whether this browser dismissed the guide before (None, not a browser: no)."""
        if identity is None:
            return False
        with self._lock:
            if identity in self._seen:
                self._seen.move_to_end(identity)  # the least recently seen is forgotten first
                return True
        store = self._store()
        try:
            known = store is not None and bool(store.imported(entry(identity)))
        except Exception as exc:  # an unreadable store: show the guide again rather than fail the page
            log.warning("the guide's entry could not be read: %s", exc)
            return False
        if known:
            self._keep(identity)
        return known

    def remember(self, identity: str | None) -> None:
        """This browser dismissed the guide: in memory, and in the store if there is one."""
        if identity is None:
            return
        self._keep(identity)
        store = self._store()
        if store is None:
            return
        try:
            store.mark_imported(entry(identity), SOURCE)
        except Exception as exc:  # a full disk: the memory still knows until the server stops
            log.warning("the guide's entry could not be kept: %s", exc)

    def _keep(self, identity: str) -> None:
        with self._lock:
            self._seen[identity] = None
            self._seen.move_to_end(identity)
            while len(self._seen) > REMEMBERED:
                self._seen.popitem(last=False)

    def greet(self, view: Any, identity: str | None) -> None:
        """A tab's view is built: show it the guide unless its browser dismissed it; *Got it* hides it in this tab
        and remembers the browser."""
        panel = view.panel
        panel.guide_done.on_click(lambda event: self._done(view, identity, event))
        if not self.seen(identity):
            with view.hub.locked():
                panel.guide.visible = True
                view.client.flush()
        self.greeted.add(view)

    @guarded
    def _done(self, view: Any, identity: str | None, event: Any) -> None:
        self.remember(identity)
        with view.hub.locked():
            if view.closed:
                return
            view.panel.guide.visible = False
            view.client.flush()
