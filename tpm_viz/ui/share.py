"""Share links in the app: *Copy share link* (a tab's own state as a link and its QR code) and opening one.

- :class:`ShareDesk` (one per app): :meth:`ShareDesk.link` is the link (:mod:`tpm_viz.classroom.links`) of what a tab
  shows (:func:`~.continuity.saved_of`: parameters, pose, load, trajectory, player time, view options; an upload too
  large for a link is kept in this server's store by content hash) on the origin its page came from (a page opened
  on this computer in classroom mode: the students' URL, so that the QR code works on their phones).
  :meth:`ShareDesk.connected` opens the link a tab's page was asked with (``/?share=TOKEN``, carried from the page to
  its websocket by :class:`~.classroom.Handshakes`' short-lived cookie) on the tab's **own copy**
  (:func:`~.continuity.restore`), never on the shared mechanism, and says so in the tab's top line; a refused link
  (damaged, forged, another version, an upload this server does not hold) is one line there, in the tab's language,
  and the tab opens normally. The visitor keeps their own language.
- :class:`ShareBox`: the widgets in a tab: the button, the link in a text field to select and copy, its QR code.
"""

from __future__ import annotations

import html
import weakref
from collections.abc import Callable
from typing import Any
from urllib.parse import urlsplit

import segno
import viser

from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded, log
from tpm_viz.classroom.links import decode_link, encode_link, share_url
from tpm_viz.classroom.network import is_loopback
from tpm_viz.classroom.session import Hub
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Phrase, T
from tpm_viz.ui.classroom import PENDING, qr_data_uri, shared_token
from tpm_viz.ui.continuity import restore, saved_of
from tpm_viz.ui.fields import Note
from tpm_viz.ui.worded import TabGui

__all__ = ["ShareBox", "ShareDesk", "describe", "origin_of"]

Blobs = Any
"""The classroom store's blobs (``put_blob(bytes) -> digest``, ``get_blob(digest) -> bytes | None``) or None."""


def origin_of(headers: Any, urls: list[str] | None = None) -> str:
    """``scheme://host:port`` of the page a websocket handshake (``headers``) comes from: its ``Origin`` (what the
    browser shows, a proxy's public name included), else ``http://`` and its ``Host``; a loopback origin is replaced
    by the first of ``urls`` (the students' URLs of classroom mode) when there is one."""
    origin = None if headers is None else headers.get("Origin")
    try:
        parts = urlsplit(str(origin or "").strip())
        hostname = parts.hostname
    except ValueError:
        parts, hostname = urlsplit(""), None
    if parts.scheme in ("http", "https") and hostname:
        if urls and is_loopback(hostname):
            return urls[0].rstrip("/")
        return f"{parts.scheme}://{parts.netloc}"
    host = None if headers is None else headers.get("Host")
    return f"http://{str(host).strip()[:255]}" if host else "http://127.0.0.1"


def describe(saved: Saved) -> Phrase:
    """Which state a link carries, in one line (mm, s)."""
    state = saved.state
    p1, p2 = (float(x) * 1e3 for x in state.pose.p)
    run = (
        T("no trajectory")
        if saved.source is None
        else Phrase("trajectory {name} at t = {t:.3f} s", name=saved.source.label, t=float(state.trajectory.t))
    )
    return Phrase(
        "l_a = {l_a:.1f} mm, p = ({p1:.1f}, {p2:.1f}) mm, {run}", l_a=state.params.l_a * 1e3, p1=p1, p2=p2, run=run
    )


class ShareDesk:
    """The share links of one app: ``hub`` (its lock), ``blobs()`` (the store's blobs now, or None: an upload too
    large for a link is then refused), ``urls()`` (the students' URLs, or None outside classroom mode)."""

    def __init__(
        self, hub: Hub, blobs: Callable[[], Blobs], urls: Callable[[], list[str] | None], links: Any = PENDING
    ) -> None:
        self.hub, self.blobs, self.urls, self.links = hub, blobs, urls, links
        self._origins: weakref.WeakKeyDictionary[Any, str] = weakref.WeakKeyDictionary()
        self.opened = 0
        """Links opened in a tab (tests and logs)."""
        self.refused = 0
        """Links refused (damaged, forged, another version, an upload kept elsewhere)."""
        self.ready: weakref.WeakSet[Any] = weakref.WeakSet()
        """The tabs :meth:`connected` has finished with (tests wait for it)."""

    def connected(self, view: Any, request: tuple[Any, Any] | None) -> None:
        """A tab's view is built and its classroom part done: remember its page's origin and open the link its page
        was asked with, if any (``request``: ``(address, headers)`` of its websocket handshake)."""
        headers = None if request is None else request[1]
        self._origins[view] = origin_of(headers, self.urls())
        view.shares = self  # what its *Copy share link* buttons ask
        token = shared_token(headers, self.links)
        if token is not None:
            self.open_link(view, token)
        self.ready.add(view)

    def open_link(self, view: Any, token: str) -> bool:
        """Give ``view`` its own copy of the state ``token`` carries and say so; a refusal is one line. -> opened"""
        blobs = self.blobs()
        try:  # outside the hub's lock: inflating and checking a large upload must not hold up the other tabs
            saved = decode_link(token, None if blobs is None else blobs.get_blob)
        except TpmVizError as exc:
            with self.hub.locked():
                self.refused += 1
                log.info("client %s: share link refused (%s)", view.client.client_id, exc)
                if not view.closed:
                    view.tell(Phrase("This tab was opened with a share link that is refused: {why}", why=reason(exc)))
                    view.client.flush()
            return False
        with self.hub.locked():
            if view.closed:
                return False
            mine = Saved(saved.state, saved.source, saved.playing_t, saved.show, view.lang.value)
            restore(view, mine, private=True)  # the visitor's own copy; the shared mechanism is not touched
            self.opened += 1
            view.tell(
                Phrase(
                    "Opened a share link on your own copy ({state}); the shared mechanism is unchanged.",
                    state=describe(mine),
                )
            )
            view.client.flush()
        return True

    def link(self, view: Any) -> str:
        """The link of what ``view`` shows now (refused in one line: an upload too large with no store here)."""
        with self.hub.locked():
            saved = saved_of(view)
            origin = self._origins.get(view) or "http://127.0.0.1"
        blobs = self.blobs()
        return share_url(origin, encode_link(saved, None if blobs is None else blobs.put_blob))


def qr_html(url: str) -> Html:
    """The QR code of ``url`` for the panel, or one line when it is too long for one (the link is still there)."""
    try:
        image = qr_data_uri(url)
    except segno.DataOverflowError:
        return Html(
            f"<p>{html.escape(str(T('The link is too long for a QR code: copy it from the field above.')))}</p>"
        )
    return Html(f"<img alt='{html.escape(str(T('QR code of the share link')))}' src='{image}' style='width:200px'>")


class ShareBox:
    """*Copy share link* in one tab (``view``: its :class:`~.client.ClientView`, whose ``shares`` is the app's
    :class:`ShareDesk` once it is connected)."""

    def __init__(self, view: Any, gui: TabGui) -> None:
        self.view = view
        self.button = gui.add_button(
            "Copy share link",
            icon=viser.Icon.SHARE,
            color="gray",
            hint="A link (and its QR code) that opens what this tab shows on the visitor's own copy",
        )
        self.text = gui.add_text(
            "Share link", "", visible=False, hint="Select the link and copy it (Ctrl+C); it opens this state"
        )
        self.qr = gui.add_html("")
        self.note = Note(gui)
        """The link's refusal (an upload too large with no store), or what the link opens, under the QR code."""
        self.button.on_click(self._on_click)

    @guarded
    def _on_click(self, event) -> None:
        view = self.view
        desk = getattr(view, "shares", None)
        if getattr(event, "client", None) is None or view.closed or desk is None:
            return
        try:
            url = desk.link(view)
        except TpmVizError as exc:
            with view.hub.locked():
                view.refuse(exc, resync=False, where=self.note)
            return
        with view.hub.locked():
            if view.closed:
                return
            self.text.value = url
            self.text.visible = True
            self.qr.content = qr_html(url)
            self.note.notes = (
                T("Whoever opens this link gets this state on their own copy; the shared mechanism is not changed."),
            )
            self.note.tell(None, view.lang)
            view.client.flush()
