"""One tab cannot freeze or fill the server (issue 12): floods, non-reading tabs, big frames, unfinished uploads,
wrong-kind inputs, malformed messages, log floods, too many tabs, unservable URLs.

Every server listens on 127.0.0.1, port 0 (the ``app``/``connect`` fixtures, or :class:`ServerProcess` for the one
memory test, stopped by its own pid). Clients are protocol-level: they send what a hostile script can send.
"""

from __future__ import annotations

import asyncio
import base64
import concurrent.futures
import contextlib
import logging
import os
import socket
import statistics
import threading
import time
import uuid

import msgspec
import numpy as np
import pytest
import viser
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect as connect_sync

import tpm_viz.viserkit.transport as transport
from tests.e2e.test_security import _get
from tests.support.protocol import CAMERA, ProtocolClient, ServerProcess, Tab, decode_batch, wait_for
from tpm_viz.app.inputs import MAX_TEXT
from tpm_viz.classroom.guard import ACTIVITY, Faults
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.viserkit.limits import Gate, guard_of
from tpm_viz.viserkit.probe import upload_states, widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

UPLOAD_LABEL = "Upload CSV (t, p1, p2 in s, m)"


def _state(view):
    with view.hub.lock:
        return view.session.state


def _start_upload(client, button_uuid: str, size: int, parts: int) -> str:
    transfer = str(uuid.uuid4())
    client.send(
        type="FileTransferStartUpload",
        source_component_uuid=button_uuid,
        transfer_uuid=transfer,
        filename="x.csv",
        mime_type="text/csv",
        part_count=parts,
        size_bytes=size,
    )
    return transfer


def _part(client, button_uuid: str, transfer: str, index: int, content: bytes) -> None:
    client.send(
        type="FileTransferPart",
        source_component_uuid=button_uuid,
        transfer_uuid=transfer,
        part_index=index,
        content=content,
    )


def open_silent_tab(port: int, rcvbuf: int = 4096) -> socket.socket:
    """A websocket tab that sends its camera message, then never reads (a raw socket with a small receive buffer)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    sock.connect(("127.0.0.1", port))
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(
        f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: viser-v{viser.__version__}"
        "\r\n\r\n".encode()
    )
    head = b""
    while b"\r\n\r\n" not in head:
        head += sock.recv(1)
    assert head.startswith(b"HTTP/1.1 101"), head
    payload = msgspec.msgpack.encode(CAMERA)
    mask = os.urandom(4)
    length = len(payload)
    header = bytes([0x82]) + (
        bytes([0x80 | length]) if length < 126 else bytes([0x80 | 126]) + length.to_bytes(2, "big")
    )
    sock.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))
    return sock


# -- bounded work per tab -------------------------------------------------------------------------------------------
class _Event:
    def __init__(self, client_id: int) -> None:
        self.client_id = client_id


def test_the_gate_runs_a_tabs_calls_one_at_a_time_coalesced_and_capped():
    pool = concurrent.futures.ThreadPoolExecutor(8)
    gate = Gate(pool.submit, max_per_tab=3)
    ran: list[int] = []
    release = threading.Event()

    def slow(event):
        release.wait(5.0)
        ran.append(event.client_id)

    for _ in range(500):  # one tab clicks the same slow action 500 times
        gate.submit(slow, _Event(1))
    assert gate.pending(1) == 2  # one running, one waiting; the rest merged into the waiting one
    others = [lambda e, k=k: ran.append(100 + k) for k in range(5)]
    for fn in others:  # other callbacks of the same tab wait behind the running one: 3 waiting at most
        gate.submit(fn, _Event(1))
    assert gate.pending(1) == 1 + 3 and gate.dropped == 3
    done = threading.Event()
    gate.submit(lambda e: done.set(), _Event(2))  # another tab is not held up
    assert done.wait(2.0)
    gate.submit(lambda: ran.append(-1))  # not a tab's event: straight to the pool
    wait_for(lambda: -1 in ran, what="a task that is not a tab's")
    release.set()
    wait_for(lambda: gate.pending(1) == 0, what="the flooding tab's calls to finish")
    pool.shutdown(wait=True)
    assert ran == [-1, 1, 1, 100, 101] and gate.merged == 498


def test_clicks_in_3d_each_wait_their_turn_and_are_capped():
    """A click in the 3D view carries its own point (a Shift+click waypoint): clicks that arrive while one runs are
    not merged into the latest, they run in turn, still at most ``max_per_tab`` waiting."""
    pool = concurrent.futures.ThreadPoolExecutor(4)
    gate = Gate(pool.submit, max_per_tab=3)
    points: list[float] = []
    release = threading.Event()

    def on_click(event):
        release.wait(5.0)
        points.append(event.ray_origin[0])

    for x in range(6):
        gate.submit(on_click, viser.SceneClickEvent(None, 1, (float(x), 0.0, 1.0), (0.0, 0.0, -1.0), (0.5, 0.5), None))
    assert gate.pending(1) == 1 + 3 and gate.dropped == 2 and gate.merged == 0
    release.set()
    wait_for(lambda: gate.pending(1) == 0, what="the clicks to run")
    pool.shutdown(wait=True)
    assert points == [0.0, 1.0, 2.0, 3.0]


def test_an_export_flood_runs_at_most_twice_and_other_tabs_stay_responsive(app, connect, monkeypatch):
    flooder, fv = connect()
    other, ov = connect()
    other.set_value(ov.panel.own_copy, True)  # the other tab works on its own copy
    wait_for(lambda: not ov.session.shared, what="the other tab's own copy")
    player = fv.teaching.player
    flooder.set_value(player.choice, "line (Fig. 4)")
    wait_for(lambda: player.runs.of(fv.session).run is not None, what="the trajectory run")
    exports: list[float] = []
    download = player._download

    def slow_download(name, data):
        exports.append(time.monotonic())
        time.sleep(0.2)  # a slow export (the PNG takes ~0.24 s)
        download(name, data)

    monkeypatch.setattr(player, "_download", slow_download)
    waits = []
    for k in range(20):
        for _ in range(50):  # 1 000 clicks in all
            flooder.click(player.export_csv)
        target = 0.100 + 0.001 * k
        sent = time.perf_counter()
        other.set_value(ov.panel.d[0], target * 1e3)
        wait_for(lambda t=target: abs(_state(ov).pose.d[0] - t) < 1e-9, timeout=5.0, what="the other tab's slider")
        waits.append(time.perf_counter() - sent)
    assert ACTIVITY.wait_idle(10.0)
    assert 1 <= len(exports) <= 2 * 20  # at most one running + one waiting at any time: ~1 per 0.2 s
    assert len(exports) < 1000 / 10
    assert statistics.median(waits) < 1.0, waits  # a bound, not a speed (bench_worker_flood.py measures the p95)


# -- bounded memory -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bad_round", [False, True], ids=["", "after a failed watchdog round"])
def test_a_tab_that_stops_reading_is_dropped(app, connect, monkeypatch, bad_round):
    guard = guard_of(app.server)
    guard.limits.max_backlog_bytes, guard.limits.backlog_grace = 2 << 20, 1.0
    if bad_round:  # one round fails (as a dict changed by the loop once made it): the watchdog goes on
        over, failed = guard._over, []

        def once(client_id):
            if not failed:
                failed.append(client_id)
                raise RuntimeError("dictionary changed size during iteration")
            return over(client_id)

        monkeypatch.setattr(guard, "_over", once)
    _client, other = connect()
    silent = open_silent_tab(app.port)
    view = wait_for(lambda: next((v for v in app.views.values() if v is not other), None), what="the silent tab")
    started = time.monotonic()
    for _ in range(40):  # 40 MiB of downloads pushed to a tab that does not read
        if view.closed:
            break
        view.client.send_file_download("x.bin", os.urandom(1 << 20))
        time.sleep(0.05)
    wait_for(lambda: view.closed, timeout=10.0, what="the silent tab to be dropped")
    assert time.monotonic() - started < 8.0 and guard.aborted >= 1
    assert set(app.views) == {other.client.client_id}
    silent.close()


def test_frames_over_1_mib_close_only_that_connection(app, connect):
    client, view = connect()
    rogue = ProtocolClient(app.port)
    wait_for(lambda: len(app.views) == 2, what="the rogue tab")
    rogue.ws.send(msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": "x", "updates": {"v": "y" * (2 << 20)}}))
    wait_for(lambda: len(app.views) == 1, what="the rogue connection to be closed")
    mapper = ProtocolClient(app.port)  # a big map (100 KiB, 25 000 keys) is not an upload part: closed, not decoded
    wait_for(lambda: len(app.views) == 2, what="the second rogue tab")
    mapper.send(type="GuiUpdateMessage", uuid="x", updates={str(i): 0 for i in range(25_000)})
    wait_for(lambda: len(app.views) == 1, what="the big map's connection to be closed")
    mapper.close()
    button = view.client.gui.add_upload_button("test upload")
    got = []
    button.on_upload(lambda event: got.append(len(event.target.value.content)))
    transfer = _start_upload(client, widget_uuid(button), 1 << 20, 2)  # what a browser sends: 512 KiB parts
    _part(client, widget_uuid(button), transfer, 0, b"a" * (512 << 10))
    _part(client, widget_uuid(button), transfer, 1, b"b" * (512 << 10))
    wait_for(lambda: got == [1 << 20], what="a 1 MiB upload in two 512 KiB parts")
    rogue.close()


def test_unfinished_uploads_are_bounded_and_freed(app, connect, monkeypatch):
    monkeypatch.setattr(transport, "UPLOAD_TIMEOUT", 0.5)
    client, view = connect()
    states = upload_states(view.client)
    button = widget_uuid(view.teaching.player.upload)
    for _ in range(50):
        transfer = _start_upload(client, button, 1 << 20, 4)
        _part(client, button, transfer, 0, b"x" * 1000)
    wait_for(lambda: len(states) == transport.MAX_UPLOADS, what="the uploads in flight")
    time.sleep(0.3)
    assert len(states) <= transport.MAX_UPLOADS
    wait_for(lambda: not states, timeout=5.0, what="the unfinished uploads to time out")


def test_too_many_tabs_are_told_and_closed():
    application = TpmApp(build_server("127.0.0.1", 0), max_connections=2)
    clients = []
    try:
        clients = [ProtocolClient(application.port) for _ in range(2)]
        wait_for(lambda: len(application.views) == 2, what="two tabs")
        ws = connect_sync(
            f"ws://127.0.0.1:{application.port}", subprotocols=[f"viser-v{viser.__version__}"], max_size=None
        )
        ws.send(msgspec.msgpack.encode(CAMERA))
        texts = []
        try:
            while True:
                for m in decode_batch(ws.recv(timeout=15.0)):
                    if m["type"] == "NotificationShowMessage":
                        texts.append(m["props"]["title"] + ": " + m["props"]["body"])
        except Exception as exc:  # closed by the server
            closed = exc
        assert any("at most 2 tabs" in t for t in texts), texts
        assert getattr(closed, "rcvd", None) is not None and closed.rcvd.code == 1013
        assert len(application.views) == 2
        clients.pop().close()
        guard = guard_of(application.server)
        assert guard is not None
        wait_for(lambda: len(guard.accepted) == 1, what="the closed tab's place freed")  # not before: refused again
        clients.append(ProtocolClient(application.port))  # a place is free again
        wait_for(lambda: len(application.views) == 2 and len(application.server.get_clients()) == 2, what="a new tab")
    finally:
        for c in clients:
            c.close()
        application.stop()


# -- inputs of the right kind ---------------------------------------------------------------------------------------
def test_updates_must_match_the_widget_kind(app, connect):
    client, view = connect()
    player, panel = view.teaching.player, view.panel
    text = view.client.gui.add_text("test text", "")
    before = _state(view)
    client.set_value(player.choice, "not an option")
    client.set_value(player.speed, "1000×")
    client.set_value(panel.own_copy, "yes")  # a checkbox takes a boolean
    client.set_value(panel.d[0], "150")  # a number, not text
    client.set_value(panel.d[1], True)
    client.set_value(panel.home, "click")  # a button click is True
    client.set_value(text, "x" * (MAX_TEXT + 1))
    client.set_value(player.upload, {"name": "a", "content": b"x"})
    transfer = _start_upload(client, widget_uuid(panel.d[0]), 10, 1)  # an upload aimed at the d1 slider
    _part(client, widget_uuid(panel.d[0]), transfer, 0, b"0123456789")
    client.set_value(text, "ok")
    wait_for(lambda: text.value == "ok", what="a good text after the bad updates")
    assert ACTIVITY.wait_idle()
    assert player.choice.value in player.choice.options and player.speed.value in player.speed.options
    assert panel.own_copy.value is False and isinstance(panel.d[0].value, float)
    assert _state(view) is before


def test_a_malformed_gizmo_message_never_reaches_a_redraw(app, connect, caplog):
    client, view = connect()
    _other, other = connect()
    owner = str(view.client.client_id)
    errors = ACTIVITY.snapshot()[1]
    bad = [
        {"position": (0.01, 0.02)},
        {"position": ("a", 0.0, 0.09)},
        {"position": (float("nan"), 0.0, 0.09)},
        {"wxyz": (1.0, 0.0, 0.0)},
        {"wxyz": None},
        {"owner": 5},
        {"name": ["/gizmo"]},
    ]
    with caplog.at_level(logging.WARNING):
        for fields in bad:
            message = {"name": "/gizmo", "wxyz": (1.0, 0.0, 0.0, 0.0), "position": (0.0, 0.0, 0.09), "owner": owner}
            client.send(type="TransformControlsUpdateMessage", **{**message, **fields})
        for kind, fields in [  # wrong-typed messages of other kinds
            ("TransformControlsDragStartMessage", {"name": 3, "owner": owner}),
            ("ViewerCameraMessage", {**CAMERA, "position": "here"}),
            ("GuiUpdateMessage", {"uuid": 7, "updates": {"value": 1}}),
            ("FileTransferPart", {"source_component_uuid": 1, "transfer_uuid": 2, "part_index": "0", "content": 3}),
            (
                "ScenePointerMessage",
                {"event_type": "click", "ray_origin": None, "ray_direction": 1, "screen_pos": [], "modifier": None},
            ),
        ]:
            client.send(**{**fields, "type": kind})
        client.drag(view.scene.gizmo, owner, [(0.03, 0.01, 0.09)])
        wait_for(lambda: np.allclose(_state(view).pose.p, (0.03, 0.01)), what="a good drag after the bad ones")
        for _ in range(20):  # every later redraw works
            client.drag(view.scene.gizmo, owner, [(0.02, -0.01, 0.09)])
        wait_for(lambda: np.allclose(_state(other).pose.p, (0.02, -0.01)), what="the redraws")
    assert ACTIVITY.wait_idle() and ACTIVITY.snapshot()[1] == errors
    assert "Task exception was never retrieved" not in caplog.text and "Traceback" not in caplog.text
    assert "message dropped" in caplog.text
    assert len([r for r in caplog.records if r.name == "tpm_viz.ui"]) <= 3  # one line per second and kind


# -- quiet logs -----------------------------------------------------------------------------------------------------
def test_faults_are_logged_once_per_second_per_tab_and_kind(caplog):
    now = [0.0]
    faults = Faults(clock=lambda: now[0])
    with caplog.at_level(logging.WARNING, logger="tpm_viz.ui"):
        for k in range(1000):
            now[0] = k * 0.01  # 1 000 faults in 10 s from one tab, one kind
            faults(1, "gui", "GUI update dropped")
            faults(2, "gui", "GUI update dropped")
        faults(1, "login", "wrong presenter token")
    lines = [r.getMessage() for r in caplog.records]
    assert faults.lines == len(lines) == 2 * 10 + 1 and faults.suppressed == 2 * 990
    assert "(+99 more in the last 1.0 s)" in lines[2]
    faults.forget(1)
    assert all(key[0] != 1 for key in faults._last)


def test_a_flood_of_bad_messages_is_a_few_log_lines(app, connect, caplog):
    client, view = connect()
    with caplog.at_level(logging.WARNING, logger="tpm_viz.ui"):
        started = time.monotonic()
        for _ in range(500):
            client.set_value(view.panel.d[0], "abc")
            client.send(type="TransformControlsUpdateMessage", name="/gizmo", wxyz=(1, 0, 0, 0), position=(0, 0))
        client.set_value(view.panel.d[0], 155.0)
        wait_for(lambda: abs(_state(view).pose.d[0] - 0.155) < 1e-9, what="a good update after the flood")
        elapsed = time.monotonic() - started
    lines = [r for r in caplog.records if r.name == "tpm_viz.ui"]
    assert len(lines) <= 2 * (elapsed + 1), [r.getMessage() for r in lines]


# -- HTTP -----------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("path", "status"),
    [
        ("/" + "a" * 300, 414),
        ("/assets/" + "b" * 256 + ".js", 404),
        ("/no/such/file.js", 404),
        ("/%ff%fe", 404),
        ("/assets", 404),
        ("/" + "c/" * 500, 404),
    ],
)
def test_unserved_paths_are_404_or_414_never_500(app, path, status):
    assert _get(app.port, path)[0] == status
    assert _get(app.port, "/")[0] == 200


# -- memory after a flood (a real server process) -------------------------------------------------------------------
def test_memory_returns_near_the_baseline_after_an_upload_flood():
    server = ServerProcess()
    try:

        async def flood() -> None:
            tab = Tab(server.port)
            await tab.open()
            for _ in range(200):
                await tab.set_value(UPLOAD_LABEL, None)  # dropped: an upload button takes no value
            button = tab.uuids[UPLOAD_LABEL]
            for _ in range(300):  # uploads started, one 512 KiB part sent, never finished
                transfer = str(uuid.uuid4())
                head = {"source_component_uuid": button, "transfer_uuid": transfer}
                await tab.send(
                    type="FileTransferStartUpload",
                    **head,
                    filename="a.csv",
                    mime_type="",
                    part_count=2,
                    size_bytes=1 << 20,
                )
                await tab.send(type="FileTransferPart", **head, part_index=0, content=b"x" * (512 << 10))
            for _ in range(3):  # big frames: each closes the connection that sends it (1009: message too big)
                big = Tab(server.port)
                await big.open()
                with contextlib.suppress(ConnectionClosed):
                    await big.ws.send(os.urandom(8 << 20))
                await asyncio.wait_for(big._reader, 10.0)
                assert big.ws.close_code == 1009
            await tab.close()

        async def warm_up() -> None:  # one tab in and out: the baseline is a server that has served a tab
            tab = Tab(server.port)
            await tab.open()
            await tab.close()

        asyncio.run(warm_up())
        baseline = server.rss_mb()
        asyncio.run(flood())  # unbounded, its uploads and frames would hold well over 150 MiB
        wait_for(lambda: server.rss_mb() - baseline < 50.0, timeout=30.0, what="memory back near the baseline")
        assert not [line for line in server.log_problems() if "Traceback" in line]
    finally:
        server.stop()
