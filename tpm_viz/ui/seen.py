"""What a tab's page saw, server side (:mod:`tpm_viz.viserkit.seen` tells it): a finger, and the panel's tab opened.

- ``touch``: the tab's drag handle becomes the touch handle (:meth:`~tpm_viz.ui.tabscene.TabScene.set_touch`: a
  square of constant screen size, drags geared to at most 1 mm per CSS px). A phone whose user agent does not say so
  (a browser in desktop mode, a touch laptop, Chromium's touch emulation) got viser's 6-7 px gizmo before.
- ``tabs:<name>,...``: the marked tabs of the panel shown now: :meth:`~tpm_viz.ui.teaching.tabs.Teaching.shown`
  puts the drawing of a tab just opened in front of the scene (the Planner shows its path and forces, not the Control
  lab's run).

A request names the tab's nonce and takes a token of the tab's key bucket (:meth:`~tpm_viz.ui.keyboard.Keyboard
.spend`); it is applied in the hub's drag pool under the hub's lock, never on the event loop.
"""

from __future__ import annotations

import http
import threading
import weakref
from typing import Any

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.errors import TpmVizError
from tpm_viz.ui.keyboard import Keyboard
from tpm_viz.viserkit.seen import seen_request

__all__ = ["Sightings"]


class Sightings:
    """The answers to the page's ``seen`` requests of one server (the ``Handshakes`` hook of :mod:`.classroom`)."""

    def __init__(self, keyboard: Keyboard) -> None:
        self.keyboard = keyboard
        self._counts: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()
        self._lock = threading.Lock()

    def answer(self, path: str, same_site: bool) -> tuple[http.HTTPStatus, str] | None:
        """The HTTP answer to a request for ``path`` (None: not a ``seen`` request). ``same_site``: the request did
        not come from another site's page."""
        try:
            request = seen_request(path)
        except ValueError as exc:
            return http.HTTPStatus.BAD_REQUEST, f"{exc}\n"
        if request is None:
            return None
        view = self.keyboard.spend(request.nonce, same_site)
        if view is None:
            return http.HTTPStatus.FORBIDDEN, "unknown nonce, or too many requests\n"
        try:
            view.hub.drag_pool.submit(self._apply, view, request.what, request.count)
        except RuntimeError:  # the server is stopping
            return http.HTTPStatus.SERVICE_UNAVAILABLE, "stopping\n"
        return http.HTTPStatus.ACCEPTED, "seen\n"

    @guarded
    def _apply(self, view: Any, what: str, count: int) -> None:
        """Apply what the page saw (in the drag pool, under the hub's lock). The open tabs are applied unless the
        page told newer ones already (their ``count`` is lower: the pool may answer two requests out of order); a
        coarse pointer always (it never changes back, and the open tabs told right after it must not hide it)."""
        with view.hub.locked():
            if view.closed:
                return
            if what == "touch":
                view.scene.set_touch(True)
            elif what.startswith("tabs:"):
                with self._lock:
                    if count <= self._counts.get(view, -1):
                        return
                    self._counts[view] = count
                try:
                    view.teaching.shown(frozenset(name for name in what[5:].split(",") if name))
                except TpmVizError:  # nothing to show there for this tab (e.g. a student on the shared mechanism)
                    pass
            view.client.flush()
