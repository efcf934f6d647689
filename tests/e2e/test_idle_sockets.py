"""One student cannot lock the class out with idle websockets (issue 35, item 3): 200 handshakes from one address
that never sent their first message filled the connection limit, and every other tab, the lecturer's included, was
refused for 30-60 s.

The attack: raw TCP connections from 127.0.0.2, each with a websocket handshake and never a message, up to and past
the per-address cap; meanwhile a student's tab from 127.0.0.3 opens and works and the lecturer's tab (this machine,
127.0.0.1) opens as the presenter; the idle sockets are dropped once the first-message deadline passes. A server
whose students' share is full still lets the lecturer in. Every wait is on a state, with a bound.
"""

from __future__ import annotations

import base64
import contextlib
import os
import socket

import msgspec
import pytest
import viser
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect as connect_sync

from tests.support.pages import TOKEN, Page, views_of
from tests.support.protocol import CAMERA, decode_batch, wait_for
from tpm_viz.cli.serve import MAX_TABS, TABS_PER_ADDRESS
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import Classroom
from tpm_viz.viserkit.limits import DEFAULT_MAX_CONNECTIONS, DEFAULT_MAX_PER_ADDRESS, guard_of, set_admission

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

LECTURER, IDLE, STUDENT = "127.0.0.1", "127.0.0.2", "127.0.0.3"


class IdleSocket:
    """A websocket that opens (raw TCP from ``source``, the handshake of viser's page) and never sends a message."""

    def __init__(self, port: int, source: str) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=30, source_address=(source, 0))
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall(
            (
                f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n"
                f"Sec-WebSocket-Protocol: viser-v{viser.__version__}\r\n\r\n"
            ).encode()
        )
        head = b""
        while b"\r\n\r\n" not in head and len(head) < 65536:
            chunk = self.sock.recv(4096)
            if not chunk:
                break
            head += chunk
        assert head.startswith(b"HTTP/1.1 101"), head[:200]
        self.sock.setblocking(False)
        self.ended = False

    def closed(self) -> bool:
        """Whether the server closed it (whatever it sent is read and dropped: never a message back)."""
        for _ in range(10_000):
            try:
                if not self.sock.recv(1 << 16):
                    self.ended = True
                    break
            except BlockingIOError:
                break
            except OSError:  # reset
                self.ended = True
                break
        return self.ended

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self.sock.close()


def _classroom_app(max_connections: int = DEFAULT_MAX_CONNECTIONS) -> TpmApp:
    """Classroom mode on 127.0.0.1; only 127.0.0.1 is this machine (the others stand for students' devices)."""
    on_this_machine = LECTURER.__eq__
    room = Classroom(
        addresses=lambda: [], presenter_address=on_this_machine, lecturer_address=on_this_machine, token=TOKEN
    )
    return TpmApp(build_server("127.0.0.1", 0), classroom=room, max_connections=max_connections)


def _held_by(guard, address: str) -> int:
    return sum(1 for a in guard.accepted.values() if a == address)


def _notification(ws) -> str:
    """The first notification a (silent) tab is sent, ``title: body``."""
    for _ in range(1000):
        for m in decode_batch(ws.recv(timeout=30)):
            if m["type"] == "NotificationShowMessage":
                return f"{m['props']['title']}: {m['props']['body']}"
    raise AssertionError("no notification")


def test_the_numbers_are_the_documented_ones():
    assert TABS_PER_ADDRESS == DEFAULT_MAX_PER_ADDRESS < DEFAULT_MAX_CONNECTIONS // 2  # well under the total
    assert MAX_TABS == DEFAULT_MAX_CONNECTIONS


def test_idle_sockets_of_one_address_leave_room_for_the_class_and_the_lecturer_and_are_dropped():
    app = _classroom_app()
    guard = guard_of(app.server)
    guard.limits.first_message_seconds = 600.0  # held while the others open; the deadline is shortened below
    cap, idle, pages = guard.limits.max_per_address, [], []
    try:
        for _ in range(cap + 10):
            idle.append(IdleSocket(app.port, IDLE))
        wait_for(lambda: guard.admission.refusals["crowded"] == 10, what="the sockets past the cap refused")
        assert _held_by(guard, IDLE) == cap
        wait_for(lambda: sum(s.closed() for s in idle) == 10, timeout=60, what="the refused sockets closed")
        refused = connect_sync(  # one more, as a browser would see it: told why, in its language
            f"ws://127.0.0.1:{app.port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            additional_headers={"Accept-Language": "ko-KR,ko;q=0.9"},
            sock=socket.create_connection(("127.0.0.1", app.port), 30, (IDLE, 0)),
        )
        assert f"최대 {cap}개" in _notification(refused)
        refused.close()

        pages.append(Page(app.port, source=STUDENT))  # a student's tab opens and works
        (student,) = views_of(app, 1)
        pages[0].set("Work on my own copy", True)
        wait_for(lambda: not student.session.shared, what="the student's own copy")
        pages.append(Page(app.port))  # the lecturer's tab, on this machine: the presenter
        wait_for(lambda: len(app.views) == 2, what="the lecturer's tab")
        lecturer = next(v for v in views_of(app, 2) if v is not student)
        wait_for(lambda: app.access.is_presenter_tab(lecturer), what="the presenter")
        assert _held_by(guard, IDLE) == cap  # all of that while the idle sockets held their address's places

        guard.limits.first_message_seconds = 1.0  # the deadline passes: every idle socket is dropped
        wait_for(lambda: all(s.closed() for s in idle), timeout=60, what="the idle sockets dropped")
        wait_for(lambda: _held_by(guard, IDLE) == 0, what="their places freed")
        assert guard.admission.dropped_idle == cap and len(app.views) == 2  # the tabs that spoke stay
    finally:
        for s in idle:
            s.close()
        for page in pages:
            page.close()
        app.stop()


def test_when_the_students_share_is_full_the_lecturer_still_gets_in():
    app = _classroom_app(max_connections=20)  # 5 places kept for the lecturer (a quarter), 15 for students
    guard = guard_of(app.server)
    guard.limits.first_message_seconds = 600.0
    set_admission(app.server, max_per_address=8)
    idle, pages = [], []
    try:
        for address, count in (("127.0.0.2", 8), ("127.0.0.4", 7)):
            idle += [IdleSocket(app.port, address) for _ in range(count)]
        wait_for(lambda: len(guard.accepted) == 15, what="the students' share taken")
        late = IdleSocket(app.port, "127.0.0.5")  # a student with no socket yet: the server is full for students
        wait_for(lambda: guard.admission.refusals["full"] == 1, what="the late student refused")
        wait_for(late.closed, timeout=60, what="the late student closed")
        for _ in range(2):  # the lecturer's projector tab and laptop tab
            pages.append(Page(app.port))
        views = views_of(app, 2)
        assert len(views) == 2 and any(app.access.is_presenter_tab(v) for v in views)
        ws = connect_sync(  # another student's browser: told, then closed
            f"ws://127.0.0.1:{app.port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            sock=socket.create_connection(("127.0.0.1", app.port), 30, ("127.0.0.6", 0)),
        )
        ws.send(msgspec.msgpack.encode(CAMERA))
        assert "at most 20 tabs" in _notification(ws)
        with pytest.raises(ConnectionClosed) as closed:
            for _ in range(1000):
                ws.recv(timeout=30)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1013
    finally:
        for s in idle:
            s.close()
        for page in pages:
            page.close()
        app.stop()
