"""A protocol-level tab that knows its widgets by label (for the classroom tests): what a browser sends and the
widget values it was sent. Widgets with the same label (the Player's and the Control tab's "Time t (s)") are known
by the first one."""

from __future__ import annotations

import socket
import threading

import msgspec
import pytest
import viser
from websockets.sync.client import connect as connect_sync

from tests.support.protocol import CAMERA, decode_batch, wait_for
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import Classroom

__all__ = ["ADDRESSES", "TOKEN", "Page", "classroom_app", "views_of"]

TOKEN = "class-Token-7"
ADDRESSES = ["192.0.2.7", "127.0.0.1", "198.51.100.20"]


class Page:
    """A protocol-level tab that knows its widgets by label (uuid and current value)."""

    def __init__(
        self,
        port: int,
        origin: str | None = None,
        cookie: str | None = None,
        accept_language: str | None = None,
        source: str | None = None,
    ) -> None:
        """``source``: the loopback address to connect from (e.g. ``127.0.0.2``: another device)."""
        headers = {}
        if cookie:
            headers["Cookie"] = cookie
        if accept_language:
            headers["Accept-Language"] = accept_language
        self.ws = connect_sync(
            f"ws://127.0.0.1:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            compression=None,
            origin=origin,
            additional_headers=headers or None,
            sock=None if source is None else socket.create_connection(("127.0.0.1", port), 10, (source, 0)),
        )
        self.uuids: dict[str, str] = {}
        self.values: dict[str, object] = {}
        self.first_uuid: dict[str, float] = {}
        self.on_widget = None  # called with (label, uuid) on the reader thread when a widget arrives
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()
        self.send(**CAMERA)

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                raw = self.ws.recv(timeout=0.2)
            except TimeoutError:
                continue
            except Exception:
                return
            for m in decode_batch(raw):
                self.take(m)

    def take(self, m: dict) -> None:
        """One decoded message from the server (on the reader thread)."""
        props = m.get("props")
        if m["type"].startswith("Gui") and isinstance(props, dict) and props.get("label"):
            self.uuids.setdefault(props["label"], m["uuid"])  # the first of a label (Player before Control)
            self.values[m["uuid"]] = m.get("value")
            if self.on_widget is not None:
                self.on_widget(props["label"], m["uuid"])
        elif m["type"] == "GuiUpdateMessage" and "value" in m.get("updates", {}):
            self.values[m["uuid"]] = m["updates"]["value"]

    def send(self, **message) -> None:
        self.ws.send(msgspec.msgpack.encode(message))

    def set(self, label: str, value) -> None:
        uuid = wait_for(lambda: self.uuids.get(label), what=f"widget {label!r}")
        self.send(type="GuiUpdateMessage", uuid=uuid, updates={"value": value})

    def value(self, label: str):
        return self.values.get(self.uuids.get(label, ""))

    def close(self) -> None:
        self._stop.set()
        self.ws.close()
        self._thread.join(timeout=2.0)


def views_of(app, n: int):
    """The views of the first ``n`` tabs of ``app``, once each was drawn."""
    wait_for(lambda: len(app.views) >= n, what=f"{n} views")
    views = list(app.views.values())
    for view in views:
        wait_for(lambda view=view: view.session.readout is not None, what="the first render")
        wait_for(lambda view=view: view in app.arrived, what="the classroom's part of the tab, and the rest")
    return views


@pytest.fixture
def classroom_app():
    """Classroom mode on 127.0.0.1: the first tab is the presenter (a stand-in for "opened on this computer")."""
    first = []

    def presenter(host: str) -> bool:
        first.append(host)
        return len(first) == 1

    room = Classroom(addresses=lambda: list(ADDRESSES), presenter_address=presenter, token=TOKEN)
    app = TpmApp(build_server("127.0.0.1", 0), classroom=room)
    yield app
    app.stop()
