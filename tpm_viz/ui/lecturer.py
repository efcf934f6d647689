"""The *Lecturer* folder of a presenter's tab: how students join, who may change the shared mechanism, and the
session as a file (*Save session* / *Open session*, :mod:`tpm_viz.classroom.sessionfile`).

Shown to a tab that may change the shared mechanism as its presenter: every tab when nobody holds the shared
mechanism (no presenter token, not classroom mode: e.g. a lecturer preparing a class at home), else the presenter's
tabs only. No logic here: the app (:class:`~.app.TpmApp`) does the work through the :class:`Lecture` it passes.
"""

from __future__ import annotations

import html
from typing import Any, Protocol
from urllib.parse import urlsplit

import viser

from tpm_viz.app.inputs import MAX_UPLOAD_BYTES
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.network import is_loopback
from tpm_viz.core import markup
from tpm_viz.core.markup import Html
from tpm_viz.core.words import T
from tpm_viz.ui.classroom import qr_data_uri
from tpm_viz.ui.worded import TabGui

__all__ = ["Lecture", "LecturerPanel", "join_html"]


class Lecture(Protocol):
    """What the lecturer's folder asks of the app."""

    def session_json(self) -> str:
        """The current session as a JSON document."""

    def open_session(self, view: Any, data: bytes) -> None:
        """Replace the shared mechanism by a session file's (refused with one line to ``view``)."""

    def hand_to_class(self, view: Any, open_: bool) -> None:
        """Let everybody change the shared mechanism (True) or only the presenter (False)."""

    def log_out(self, view: Any) -> None:
        """End ``view``'s presenter right (and any dropped presenter tab's way back from its address)."""


NOTICE = "<p style='margin:0;padding:0 0 4px;font-size:0.875em'><b>Session store</b>: {line}</p>"
"""The lecturer's line about the session store, its text escaped (:func:`tpm_viz.core.markup.html`)."""
LOOPBACK_ONLY = T("Served on this computer only: students cannot connect. Restart with --host 0.0.0.0.")


def join_html(urls: list[str], loopback: bool = False) -> Html:
    """The URLs students type and a QR code of the first one (HTML for the panel). ``loopback``: the server is bound
    to this computer only (``--classroom`` with ``--host 127.0.0.1``): the room's addresses are listed, but no
    student can connect to them, and the panel says so (as the terminal does)."""
    if not urls:
        return Html(
            "<p><b>No network address found</b>: connect this computer to the room's network "
            "(students use the same wifi), then restart the app.</p>"
        )
    links = "".join(f"<div style='font-size:1.1em'><b>{html.escape(u)}</b></div>" for u in urls)
    if loopback or all(is_loopback(urlsplit(u).hostname or "") for u in urls):
        links += f"<p style='color:#b91c1c'><b>{LOOPBACK_ONLY.template}</b></p>"
    image = f"<img alt='QR code of {html.escape(urls[0])}' src='{qr_data_uri(urls[0])}' style='width:180px'>"
    return Html(f"<div>Students open (same network):{links}{image}</div>")


class LecturerPanel:
    """The *Lecturer* folder of one tab."""

    def __init__(
        self, gui: TabGui, lecture: Lecture, view: Any, urls: list[str] | None, presenter: bool, loopback: bool = False
    ):
        """``loopback``: the server is bound to this computer only (the join box warns: :func:`join_html`)."""
        self._lecture, self._view = lecture, view
        self.folder = gui.add_folder("Lecturer", expand_by_default=urls is not None)
        with self.folder:
            self.join = gui.add_html(join_html(urls, loopback) if urls is not None else "")
            self.join.visible = urls is not None
            self.notice = gui.add_html("")
            self.notice.visible = False
            self.open_to_class = gui.add_checkbox(
                "Let the class change the shared mechanism",
                False,
                hint="Off: only you (the presenter) change it; students still have their own copy",
                visible=presenter,
            )
            self.save = gui.add_button("Save session (JSON)", icon=viser.Icon.DOWNLOAD)
            self.open = gui.add_upload_button(
                "Open session (JSON)", icon=viser.Icon.UPLOAD, mime_type=".json,application/json"
            )
            self.log_out = gui.add_button(
                "Log out as presenter",
                icon=viser.Icon.LOGOUT,
                hint="This tab becomes a student's; a dropped presenter tab no longer comes back as the presenter",
                visible=presenter,
            )
        self.open_to_class.on_update(self._on_open_to_class)
        self.log_out.on_click(self._on_log_out)
        self.save.on_click(self._on_save)
        self.open.on_upload(self._on_open)

    def show_notice(self, line: str) -> None:
        """One line about the session store (set aside, not saving, saving again); empty: hidden."""
        self.notice.content = markup.html(NOTICE, line=line) if line else Html("")
        self.notice.visible = bool(line)

    @guarded
    def _on_open_to_class(self, event) -> None:
        if getattr(event, "client", None) is not None:
            self._lecture.hand_to_class(self._view, bool(self.open_to_class.value))

    def remove(self) -> None:
        """Take the folder out of the tab (the presenter logged out)."""
        self.folder.remove()

    @guarded
    def _on_log_out(self, event: viser.GuiEvent) -> None:
        if getattr(event, "client", None) is not None:
            self._lecture.log_out(self._view)

    @guarded
    def _on_save(self, event) -> None:
        if getattr(event, "client", None) is not None:
            data = self._lecture.session_json().encode()
            self._view.client.send_file_download("tpm-viz-session.json", data, save_immediately=True)

    @guarded
    def _on_open(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        file = self.open.value
        content = getattr(file, "content", b"")
        if len(content) > MAX_UPLOAD_BYTES * 5:
            self._view.refuse("the session file is too large", resync=False)
            return
        self._lecture.open_session(self._view, content)
