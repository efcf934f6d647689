"""The keyboard, server side: keys the page script sent (:mod:`tpm_viz.viserkit.page`) move this tab's mechanism.

Keys (``KeyboardEvent.code``, the same on every layout), each a step of :data:`STEP_MM`, with Shift
:data:`BIG_STEP_MM`:

- ← → ↑ ↓: the platform along x and y (a drag's move: :func:`~tpm_viz.app.transitions.drag`, clamped inverse
  kinematics, committed with :meth:`~tpm_viz.classroom.session.View.commit_drag`);
- Q / A: slider 1 forward / back, W / S: slider 2 (the slider's move: :func:`~tpm_viz.app.transitions.drive`).

Each tab gets a nonce (:func:`secrets.token_urlsafe`, 128 bits) in a hidden element of its panel when it connects
(:meth:`Keyboard.join`); a key request names it, so a key moves only that tab's mechanism (its own copy, or the
shared one with the same permission as a drag: a student without the right is refused, in the tab's language).
A request with a nonce no tab holds is refused (403), as is one from another site's page (``Origin``); each tab
may send :data:`KEY_RATE` keys a second (a burst of :data:`KEY_BURST`; more: 429), and its keys are applied in
order, one drain at a time in the hub's drag pool, never on the event loop.
"""

from __future__ import annotations

import html
import http
import secrets
import threading
import time
import weakref
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import viser

from tpm_viz.app import transitions
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.session import View
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html
from tpm_viz.core.words import T
from tpm_viz.viserkit.page import QUEUED, RECONNECT_NOW, key_request

__all__ = ["BIG_STEP_MM", "KEY_BURST", "KEY_RATE", "MOVES", "STEP_MM", "Keyboard", "keyboard_of"]

STEP_MM = 1.0
"""One key press [mm]: the platform's or the slider's step."""
BIG_STEP_MM = 10.0
"""One key press with Shift [mm]."""
KEY_RATE = 20.0
"""Keys a tab may send per second, on average (a held key repeats about 30 times a second: the rest wait in the
page's queue or are dropped)."""
KEY_BURST = 2 * QUEUED
"""Keys a tab may send at once."""

MOVES: dict[str, tuple[str, int, float]] = {
    "ArrowRight": ("platform", 0, +1.0),
    "ArrowLeft": ("platform", 0, -1.0),
    "ArrowUp": ("platform", 1, +1.0),
    "ArrowDown": ("platform", 1, -1.0),
    "KeyQ": ("slider", 0, +1.0),
    "KeyA": ("slider", 0, -1.0),
    "KeyW": ("slider", 1, +1.0),
    "KeyS": ("slider", 1, -1.0),
}
"""Key -> (what moves, its axis or slider index, direction)."""

LABEL = T(
    "3D view of the mechanism. Arrow keys move the platform, Q and A slider 1, W and S slider 2; with Shift the "
    "steps are 10 mm instead of 1 mm. In presentation mode P folds and unfolds the panel."
)
"""The 3D view's name for assistive technology (the page script reads it from the tab's hidden element)."""


CLOSE = T("Close")
"""The name of viser's close buttons (notifications, modals), which have none."""
SETTINGS = T("Settings")
"""The name of viser's settings button (an icon only)."""


def _marker(nonce: str) -> Html:
    """The hidden element of a tab's panel: its nonce, and the words the page script gives the 3D view, the close
    buttons and its *Reconnect now* button (English here; in the tab's language on the wire, :mod:`.language`)."""
    words = "".join(f'<span data-w="{key}">{html.escape(str(text))}</span>' for key, text in WORDS.items())
    words += "".join(f'<span data-en="{html.escape(str(text))}">{html.escape(str(text))}</span>' for text in VISER)
    return Html(f'<div data-tpmviz-keys="{nonce}" hidden>{words}</div>')


WORDS = {"view": LABEL, "close": CLOSE, "settings": SETTINGS, "reconnect": RECONNECT_NOW}
"""The words of the hidden element, by key (``data-w``): the 3D view's name, viser's close and settings buttons, and
the *Reconnect now* button the page script shows while the tab is disconnected (:mod:`tpm_viz.viserkit.page`)."""

VISER = (
    CLOSE,
    SETTINGS,
    T("Collapse panel area"),
    T("Collapse column"),
    T("Expand column"),
    T("Minimize panel"),
    T("Expand panel"),
    T("Minimize panels"),
    T("Expand panels"),
    T("Collapse"),
    T("Expand"),
    T("Minimize"),
    T("Expand plot"),
    T("Expand image"),
    T("Collapse panel {name}"),
    T("Expand panel {name}"),
    T("Edit props for {name}"),
    T("Software WebGL rendering detected"),
    T(
        "WebGL is running in software mode, not on your GPU. Performance may be degraded. If this is unexpected, "
        "check that hardware acceleration is enabled in your browser settings."
    ),
)
"""viser's own English names (``aria-label``, ``title``, tooltip texts, the software-WebGL notice; ``{name}``: a
panel's or a node's name) that the page script shows in the tab's language (each as ``<span data-en="English">shown
</span>`` of the hidden element)."""


@dataclass
class _Tab:
    """One tab's keys: its view, its token bucket, the keys not applied yet."""

    view: View
    tokens: float = float(KEY_BURST)
    at: float = field(default_factory=time.monotonic)
    pending: deque[tuple[str, bool]] = field(default_factory=lambda: deque(maxlen=KEY_BURST))
    scheduled: bool = False

    def take(self, now: float) -> bool:
        """One token of the bucket, if there is one."""
        self.tokens = min(float(KEY_BURST), self.tokens + (now - self.at) * KEY_RATE)
        self.at = now
        if self.tokens < 1.0:
            return False
        self.tokens -= 1.0
        return True


class Keyboard:
    """The keys of one server's tabs (the ``Handshakes`` hook of :mod:`.classroom` answers :meth:`answer`)."""

    def __init__(self) -> None:
        self._tabs: dict[str, _Tab] = {}
        self._nonces: dict[int, str] = {}  # id(view) -> nonce
        self._lock = threading.Lock()
        self.refused = 0
        """Key requests refused (forged nonce, another site, malformed, too many)."""

    def join(self, view: Any) -> str:
        """Give ``view`` (a :class:`~tpm_viz.ui.client.ClientView`) its nonce, in a hidden element of its panel."""
        nonce = secrets.token_urlsafe(16)
        view.gui.add_html(_marker(nonce))
        with self._lock:
            self._tabs[nonce] = _Tab(view)
            self._nonces[id(view)] = nonce
        return nonce

    def nonce_of(self, view: Any) -> str | None:
        """The nonce of ``view``'s tab (None: not joined, or gone)."""
        with self._lock:
            return self._nonces.get(id(view))

    def spend(self, nonce: str, same_site: bool) -> Any | None:
        """The view of the tab holding ``nonce`` if the request may be answered: from this site, and a token of
        the tab's bucket (a key's rate: :mod:`~tpm_viz.ui.seen` asks too); None otherwise (counted as refused)."""
        with self._lock:
            tab = self._tabs.get(nonce) if same_site else None
            if tab is None or not tab.take(time.monotonic()):
                self.refused += 1
                return None
            return tab.view

    def leave(self, view: Any) -> None:
        """``view``'s tab went away: its nonce is no longer accepted."""
        with self._lock:
            nonce = self._nonces.pop(id(view), None)
            if nonce is not None:
                self._tabs.pop(nonce, None)

    def answer(self, path: str, same_site: bool) -> tuple[http.HTTPStatus, str] | None:
        """The HTTP answer to a request for ``path`` (None: not a key request). ``same_site``: the request did not
        come from another site's page (its ``Origin``, if any, is this server)."""
        try:
            request = key_request(path)
        except ValueError as exc:
            self.refused += 1
            return http.HTTPStatus.BAD_REQUEST, f"{exc}\n"
        if request is None:
            return None
        with self._lock:
            tab = self._tabs.get(request.nonce) if same_site else None
            if tab is None:
                self.refused += 1
                return http.HTTPStatus.FORBIDDEN, "unknown key nonce\n"
            if not tab.take(time.monotonic()):
                self.refused += 1
                return http.HTTPStatus.TOO_MANY_REQUESTS, "too many keys\n"
            tab.pending.append((request.code, request.shift))
            if tab.scheduled:
                return http.HTTPStatus.ACCEPTED, "queued\n"
            tab.scheduled = True
        try:
            tab.view.hub.drag_pool.submit(self._drain, tab)
        except RuntimeError:  # the server is stopping
            return http.HTTPStatus.SERVICE_UNAVAILABLE, "stopping\n"
        return http.HTTPStatus.ACCEPTED, "queued\n"

    @guarded
    def _drain(self, tab: _Tab) -> None:
        """Apply ``tab``'s pending keys in order (in the drag pool, under the hub's lock)."""
        view = tab.view
        with view.hub.locked():
            with self._lock:
                keys = list(tab.pending)
                tab.pending.clear()
                tab.scheduled = False
            for code, shift in keys:
                if view.closed:
                    return
                try:
                    self._apply(view, code, shift)
                except TpmVizError as exc:  # a student on the presenter's mechanism: told in the tab's language
                    view.refuse(exc, resync=False)
                    return

    @staticmethod
    def _apply(view: Any, code: str, shift: bool) -> None:
        """One key: the platform through a drag's commit, a slider through the slider's (under the hub's lock)."""
        what, axis, sign = MOVES[code]
        step = sign * (BIG_STEP_MM if shift else STEP_MM)
        state = view.session.state
        if what == "platform":
            position = np.array(state.pose.p, dtype=float)
            position[axis] += step * 1e-3
            view.commit_drag("end", position)
        else:
            d_mm = float(state.pose.d[axis]) * 1e3 + step
            view.commit_key(transitions.drive(state, axis, min(max(d_mm, 0.0), state.params.stroke * 1e3)))


_KEYBOARDS: weakref.WeakKeyDictionary[viser.ViserServer, Keyboard] = weakref.WeakKeyDictionary()


def keyboard_of(server: viser.ViserServer, keyboard: Keyboard | None = None) -> Keyboard:
    """The keyboard of ``server``: ``keyboard`` if given (``build_server`` passes its ``Handshakes``'), else the one
    given before, else a new one (a server built elsewhere: no page script reaches it)."""
    if keyboard is not None:
        _KEYBOARDS[server] = keyboard
        return keyboard
    return _KEYBOARDS.setdefault(server, Keyboard())
