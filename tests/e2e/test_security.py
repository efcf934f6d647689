"""Security of the served app: loopback by default, no share tunnel, no files, presenter mode, hostile messages.

Every server here listens on 127.0.0.1, port 0. Clients are protocol-level (``conftest.ProtocolClient``): they send
exactly what a browser, or a hostile script, can send over the websocket.
"""

from __future__ import annotations

import contextlib
import http.client
import io
import logging
import re
import socket
import threading
import time
import uuid
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest
from websockets.exceptions import ConnectionClosed

import tpm_viz.ui.app as app_module
from tests.support.fixtures import open_tab
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz import InputError
from tpm_viz.app.inputs import MAX_UPLOAD_BYTES
from tpm_viz.classroom.access import LOCKOUT_SECONDS, MAX_FAILURES, Access, AccessDenied
from tpm_viz.classroom.guard import ACTIVITY
from tpm_viz.classroom.session import Session
from tpm_viz.viserkit.probe import share_tunnel, tunnel_class, upload_states, widget_uuid

TOKEN = "s3cret-Token"
UI = Path(__file__).resolve().parents[2] / "tpm_viz" / "ui"


def _state(view):
    with view.hub.lock:
        return view.session.state


def _listening_addresses(port: int) -> set[str]:
    """Local addresses of the TCP sockets listening on ``port`` (from /proc/net/tcp and tcp6)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            local, state = line.split()[1], line.split()[3]
            address, port_hex = local.rsplit(":", 1)
            if state == "0A" and int(port_hex, 16) == port:  # 0A = LISTEN
                found.add(address)
    return found


# -- binding ----------------------------------------------------------------------------------------------------------
def test_default_host_is_loopback_and_no_warning_is_printed():
    err, out = io.StringIO(), io.StringIO()
    with redirect_stderr(err), redirect_stdout(out):
        app = app_module.main(port=0, block=False)
    try:
        assert _listening_addresses(app.port) == {"0100007F"}  # 127.0.0.1 only, nothing on 0.0.0.0 or ::
        assert "warning" not in err.getvalue()
        assert out.getvalue() == f"tpm-viz serving at http://127.0.0.1:{app.port}\n"
    finally:
        app.stop()


@pytest.mark.parametrize(("token", "who"), [(None, "presenter"), (TOKEN, "presenter")])
def test_non_loopback_host_prints_a_warning(monkeypatch, token, who):
    """Any non-loopback host is classroom mode: only the presenter changes the shared mechanism, token or not."""
    seen = {}

    class Fake:
        def __init__(self, server, **kwargs):
            seen.update(kwargs)
            self.port = 1234

    monkeypatch.setattr(app_module, "build_server", lambda host, port, *more: seen.setdefault("host", host))
    monkeypatch.setattr(app_module, "TpmApp", Fake)
    err, out = io.StringIO(), io.StringIO()
    with redirect_stderr(err), redirect_stdout(out):
        app_module.main(host="192.168.1.10", port=8080, block=False, presenter_token=token, addresses=lambda: [])
    assert "warning" in err.getvalue() and "192.168.1.10" in err.getvalue() and who in err.getvalue()
    assert seen["host"] == "192.168.1.10" and seen["presenter_token"] == token
    assert seen["classroom"] is not None and (token is None or seen["classroom"].token == token)


def test_command_lines_default_to_loopback_and_pass_the_token(monkeypatch):
    import tpm_viz.cli as cli
    import tpm_viz.cli.serve
    import tpm_viz.ui.app

    calls = []
    monkeypatch.setattr(tpm_viz.ui.app, "main", lambda **kw: calls.append(kw))
    monkeypatch.setattr(tpm_viz.cli.serve, "check_bind", lambda host, port: None)  # 10.0.0.5 is not this machine
    cli.main(["serve", "--port", "0"])
    cli.main(["serve", "--port", "0", "--host", "10.0.0.5", "--presenter-token", TOKEN])
    keys = ("host", "port", "presenter_token")
    assert [{k: c[k] for k in keys} for c in calls] == [
        {"host": "127.0.0.1", "port": 0, "presenter_token": None},
        {"host": "10.0.0.5", "port": 0, "presenter_token": TOKEN},
    ]
    assert calls[0]["classroom"] is False and calls[0]["fresh"] is False and calls[0]["session"] is not None
    # python app.py is the same command: it binds 127.0.0.1 unless --host says otherwise
    import runpy

    for argv, host in ((["app.py", "--port", "0"], "127.0.0.1"), (["app.py", "--host", "10.0.0.5"], "10.0.0.5")):
        monkeypatch.setattr("sys.argv", argv)
        with pytest.raises(SystemExit) as exit_:
            runpy.run_path(str(Path(__file__).resolve().parents[2] / "app.py"), run_name="__main__")
        assert exit_.value.code == 0 and calls[-1]["host"] == host


def test_a_blank_token_is_refused_before_serving():
    with pytest.raises(InputError):
        app_module.main(port=0, block=False, presenter_token="   ")


# -- share URL --------------------------------------------------------------------------------------------------------
def test_share_url_request_from_a_client_opens_no_outside_connection(app, connect, monkeypatch):
    tunnels, outside = [], []
    monkeypatch.setattr(tunnel_class(), "__init__", lambda self, *a, **k: tunnels.append(a))
    real_connect = socket.socket.connect

    def spy(sock, address):
        host = address[0] if isinstance(address, tuple) else str(address)
        if sock.family in (socket.AF_INET, socket.AF_INET6) and host not in ("127.0.0.1", "::1", "localhost"):
            outside.append(address)
            raise OSError("blocked by the test: no outside connection")
        return real_connect(sock, address)

    monkeypatch.setattr(socket.socket, "connect", spy)
    client, view = connect()
    for _ in range(3):
        client.send(type="ShareUrlRequest")
    client.send(type="ShareUrlDisconnect")
    client.set_value(view.panel.d[0], 150.0)  # handled after the requests above
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.15) < 1e-9, what="d1 after the share requests")
    time.sleep(0.3)  # the share handlers run in viser's thread pool
    assert tunnels == [] and outside == []
    assert share_tunnel(app.server) is None
    assert app.server.request_share_url() is None


# -- files ------------------------------------------------------------------------------------------------------------
TRAVERSALS = [
    "/../../../../etc/passwd",
    "/%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
    "/..%2f..%2f..%2f..%2fetc%2fpasswd",
    "/%252e%252e/%252e%252e/etc/passwd",
    "//etc/passwd",
    "/etc/passwd",
    "/....//....//etc/passwd",
    "/..\\..\\..\\..\\etc\\passwd",
    "/index.html/../../../../etc/passwd",
    "/etc/passwd%00.html",
    "/proc/self/environ",
    "/../../../../proc/self/cmdline",
    "/../../../../../../work/main/pyproject.toml",
    "/tpm_viz/ui/app.py",
    "/../tpm_viz/ui/app.py",
    "/.git/config",
    "/?path=/etc/passwd",
]


def _get(port: int, path: str) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    try:
        conn.putrequest("GET", path, skip_accept_encoding=True)  # the path goes out exactly as written
        conn.endheaders()
        resp = conn.getresponse()
        return resp.status, resp.read()
    except (http.client.HTTPException, OSError):
        return 0, b""  # the server closed the connection: nothing served either
    finally:
        conn.close()


def test_http_serves_the_page_and_nothing_else(app, connect):
    index_status, index = _get(app.port, "/")
    assert index_status == 200 and b"<html" in index.lower()
    secrets = [b"root:x:0:0", b"[project]", b"import viser", b"PATH=", b"repositoryformatversion", b"python"]
    for path in TRAVERSALS:
        status, body = _get(app.port, path)
        assert status == 404 or (path.startswith("/?") and body == index), (path, status)
        assert not any(s in body for s in secrets), path
    client, view = connect()  # still serving
    client.set_value(view.panel.d[0], 140.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.14) < 1e-9, what="the app after the requests")


def test_the_ui_package_touches_no_files():
    """Exports are sent from memory (``send_file_download``) and uploads are read from memory: no code in
    ``tpm_viz/ui`` opens, writes, lists or deletes files, or runs programs (the lecture's store does, in the classroom
    layer: ``store.open()`` is its method, not the built-in)."""
    pattern = re.compile(
        r"(?<![.\w])open\(|read_text\(|read_bytes\(|write_text\(|write_bytes\(|\bos\.(remove|unlink|system|listdir|walk)"
        r"|subprocess|shutil|glob\(|tempfile|savefig\([\"']"
    )
    for path in sorted(UI.glob("*.py")):
        hits = [line for line in path.read_text().splitlines() if pattern.search(line)]
        assert not hits, (path.name, hits)


# -- hostile messages -------------------------------------------------------------------------------------------------
def test_malformed_gui_updates_are_dropped_with_one_log_line(app, connect, caplog):
    client, view = connect()
    _other, other = connect()
    label = view.panel.d[0].label
    errors = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.WARNING, logger="tpm_viz.ui"):
        client.send(type="GuiUpdateMessage", uuid=widget_uuid(view.panel.d[0]), updates={"label": "hacked"})
        client.send(type="GuiUpdateMessage", uuid=widget_uuid(view.panel.d[0]), updates={"max": 1e9, "value": 5.0})
        client.set_value(view.panel.d[1], "abc")
        client.set_value(view.panel.f_ext.inputs["f_x"], 3.0)  # a typed field takes text
        client.set_value(view.panel.p.inputs["p1"], None)
        client.set_value(view.panel.d[1], float("nan"))  # no browser sends these; viser would cast "1e999" to inf
        client.set_value(view.panel.f_ext.inputs["f_x"], ("1e999", 0.0))
        client.send(type="GuiUpdateMessage", uuid=str(uuid.uuid4()), updates={"value": 1.0})
        client.set_value(view.panel.d[0], 160.0)
        wait_for(lambda: abs(_state(view).pose.d[0] - 0.16) < 1e-9, what="a good update after the bad ones")
    assert view.panel.d[0].label == label and view.panel.d[0].max == pytest.approx(300.0)
    assert "GUI update dropped" in caplog.text
    assert view.panel.f_ext.inputs["f_x"].value == "0" and np.isfinite(view.panel.d[1].value)
    assert ACTIVITY.snapshot()[1] == errors
    assert _state(other) is _state(view)


def test_garbage_bytes_close_only_that_connection(app, connect):
    client, view = connect()
    rogue = ProtocolClient(app.port)
    wait_for(lambda: len(app.views) == 2, what="the rogue tab")
    rogue.ws.send(b"\x00\xffnot msgpack at all")
    with contextlib.suppress(ConnectionClosed):  # the server may have closed it on the first frame already
        rogue.ws.send(b"\x93\x01\x02")
    wait_for(lambda: len(app.views) == 1, what="the rogue connection to be dropped")
    client.set_value(view.panel.d[0], 170.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.17) < 1e-9, what="the app to keep working")
    rogue.close()


def _start_upload(client: ProtocolClient, button, size: int, parts: int) -> str:
    transfer = str(uuid.uuid4())
    client.send(
        type="FileTransferStartUpload",
        source_component_uuid=widget_uuid(button),
        transfer_uuid=transfer,
        filename="big.csv",
        mime_type="text/csv",
        part_count=parts,
        size_bytes=size,
    )
    return transfer


def _part(client: ProtocolClient, button, transfer: str, index: int, content: bytes) -> None:
    client.send(
        type="FileTransferPart",
        source_component_uuid=widget_uuid(button),
        transfer_uuid=transfer,
        part_index=index,
        content=content,
    )


def test_uploads_are_limited_in_size(app, connect):
    client, view = connect()
    got = []
    button = view.client.gui.add_upload_button("test upload")
    button.on_upload(lambda event: got.append(event.target.value.content))
    states = upload_states(view.client)

    too_big = _start_upload(client, button, MAX_UPLOAD_BYTES + 1, 2)
    _part(client, button, too_big, 0, b"x" * 1000)
    liar = _start_upload(client, button, 10, 2)
    _part(client, button, liar, 0, b"y" * 100_000)  # more than it declared
    _part(client, button, liar, 1, b"y" * 100_000)
    good = _start_upload(client, button, 16, 2)
    _part(client, button, good, 0, b"t,p1,p2\n")
    _part(client, button, good, 1, b"0,0,0\n\n\n")
    wait_for(lambda: got, what="the good upload")
    assert got == [b"t,p1,p2\n0,0,0\n\n\n"]
    assert too_big not in states and liar not in states and not states


# -- presenter mode ---------------------------------------------------------------------------------------------------
@pytest.fixture
def presenter_app():
    """The app in presenter mode on a free loopback port."""
    from tpm_viz.ui.app import TpmApp, build_server

    application = TpmApp(build_server("127.0.0.1", 0), presenter_token=TOKEN)
    yield application
    application.stop()


@pytest.fixture
def pconnect(presenter_app):
    """Like conftest's ``connect``, for the presenter-mode app; tolerates tabs the test closed itself."""
    opened: list[ProtocolClient] = []
    yield lambda: open_tab(presenter_app, opened)
    for client in opened:
        client.close()
    wait_for(lambda: not presenter_app.views, what="every tab to leave")


def _login(client: ProtocolClient, view, token: str) -> None:
    client.set_value(view.login.token, token)
    client.click(view.login.button)


def test_presenter_mode_students_are_refused_on_the_shared_mechanism_only(pconnect):
    student, sv = pconnect()
    presenter, pv = pconnect()
    _watcher, wv = pconnect()
    start = _state(pv)

    student.set_value(sv.panel.d[0], 200.0)
    note = sv.panel.move_note.handle  # next to the control, in the Move tab
    wait_for(lambda: "Refused" in note.content, what="the refusal")
    assert "only the presenter" in note.content
    wait_for(lambda: sv.panel.d[0].value == pytest.approx(130.0), what="the student's slider put back")
    student.drag(sv.scene.gizmo, str(sv.client.client_id), [(0.05, 0.02, 0.09)])
    wait_for(lambda: np.allclose(sv.scene.gizmo.position[:2], (0.0, 0.0)), what="the gizmo put back")
    for button in (sv.panel.home, sv.panel.switch_mode, sv.panel.apply, sv.panel.demo["direct"]):
        student.click(button)
    student.enter(sv.panel.params, {"l_a": "280"})
    wait_for(lambda: "only the presenter" in sv.panel.params.note.handle.content, what="refused under Apply")
    time.sleep(0.2)
    assert ACTIVITY.wait_idle()
    assert _state(pv) is start and _state(wv) is start  # nobody else's view changed
    assert pv.panel.message.content == "" and wv.panel.message.content == ""

    _login(presenter, pv, "not the token")
    wait_for(lambda: "wrong presenter token" in pv.panel.message.content, what="a wrong token refused")
    assert pv.login.token.value == ""  # cleared at once
    _login(presenter, pv, TOKEN)
    wait_for(lambda: "You are the presenter" in pv.login.status.content, what="the presenter login")
    assert pv.login.token.value == ""
    presenter.set_value(pv.panel.d[0], 210.0)
    wait_for(lambda: abs(_state(wv).pose.d[0] - 0.21) < 1e-9, what="the presenter's change reaching the watcher")
    assert _state(sv) is _state(pv)
    wait_for(lambda: "Presenter mode: you are allowed" in pv.panel.class_info.content, what="the presenter's line")
    wait_for(lambda: "only the presenter is allowed" in sv.panel.class_info.content, what="a student's line")

    student.set_value(sv.panel.own_copy, True)  # a student's own copy is theirs to change
    wait_for(lambda: not sv.session.shared, what="the student's own copy")
    student.set_value(sv.panel.d[1], 250.0)
    wait_for(lambda: abs(_state(sv).pose.d[1] - 0.25) < 1e-9, what="the student's private change")
    assert _state(pv).pose.d[1] == pytest.approx(0.13)


def test_student_drags_never_swallow_the_presenters(presenter_app, pconnect, monkeypatch):
    """Drags on the shared mechanism are merged (latest value wins) only among tabs allowed to change it: with five
    tabs (drags applied in the pool, merged) a student tugging all along never makes a presenter's drag vanish."""
    presenter, pv = pconnect()
    student, sv = pconnect()
    for _ in range(3):
        pconnect()  # watchers
    committed = []
    commit = presenter_app.hub.commit

    def spy(session, state, *args, **kwargs):
        commit(session, state, *args, **kwargs)
        committed.append(tuple(np.round(state.pose.p, 9)))

    monkeypatch.setattr(presenter_app.hub, "commit", spy)
    _login(presenter, pv, TOKEN)
    wait_for(lambda: "You are the presenter" in pv.login.status.content, what="the presenter login")
    p_owner, s_owner = str(pv.client.client_id), str(sv.client.client_id)
    stop = threading.Event()

    def pull() -> None:  # a student tugging at the shared platform all along
        k = 0
        while not stop.is_set():
            student.drag(sv.scene.gizmo, s_owner, [(-0.05, 0.04 * np.sin(k / 5), 0.09)], end=False)
            k += 1
            time.sleep(0.01)

    thread = threading.Thread(target=pull)
    thread.start()
    try:
        targets = [(0.01 * k, 0.005 * k, 0.09) for k in range(1, 9)]
        for target in targets:  # each waits for its commit (on a busy machine two drags 60 ms apart may merge)
            presenter.drag(pv.scene.gizmo, p_owner, [target], end=False)
            want = tuple(np.round(target[:2], 9))
            wait_for(lambda want=want: want in committed, what=f"the presenter's drag to {want} applied")
        presenter.drag(pv.scene.gizmo, p_owner, [targets[-1]])
        wait_for(lambda: np.allclose(_state(pv).pose.p, targets[-1][:2]), what="the presenter's last drag")
    finally:
        stop.set()
        thread.join()
    student.drag(sv.scene.gizmo, s_owner, [], end=True)
    assert ACTIVITY.wait_idle()
    np.testing.assert_allclose(_state(sv).pose.p, targets[-1][:2])
    assert not [p for p in committed if p[0] == -0.05]  # the student's tug (p1 = -50 mm) was never applied
    assert "only the presenter" in sv.panel.message.content and pv.panel.message.content == ""


def test_presenter_login_is_rate_limited_per_address(presenter_app, pconnect):
    guesser, gv = pconnect()
    for k in range(
        MAX_FAILURES
    ):  # one at a time: repeated clicks queued behind a running one merge (viserkit/limits.py)
        calls = ACTIVITY.snapshot()[0]
        _login(guesser, gv, f"guess-{k}")
        wait_for(lambda calls=calls: ACTIVITY.snapshot()[0] > calls and gv.login.token.value == "", what="a try")
        assert ACTIVITY.wait_idle()
    wait_for(lambda: "wrong presenter token" in gv.panel.message.content, what="the refusals")
    time.sleep(0.2)
    _login(guesser, gv, TOKEN)  # even the right token is refused during the lockout
    wait_for(lambda: "too many" in gv.panel.message.content, what="the lockout")
    assert not presenter_app.access.is_presenter(gv)
    other, ov = pconnect()  # another tab from the same address is locked out too (reconnecting does not reset)
    _login(other, ov, TOKEN)
    wait_for(lambda: "too many" in ov.panel.message.content, what="the lockout of the same address")
    assert not presenter_app.access.is_presenter(ov)


def test_access_rules_without_a_server():
    now = [0.0]
    access = Access(TOKEN, clock=lambda: now[0])
    tab, other = object.__new__(type("Tab", (), {})), object.__new__(type("Tab", (), {}))
    shared, private = Session(None, shared=True), Session(None, shared=False)
    assert access.enabled and not access.may_change(tab, shared) and access.may_change(tab, private)
    with pytest.raises(AccessDenied):
        access.check(tab, shared)
    for _ in range(MAX_FAILURES):
        assert not access.login(tab, "x")
    with pytest.raises(InputError, match="too many"):
        access.login(tab, TOKEN)
    now[0] += LOCKOUT_SECONDS + 1
    assert access.login(tab, TOKEN) and access.may_change(tab, shared)
    assert not access.login(other, None) and not access.login(other, TOKEN * 100)
    access.logout(tab)
    assert not access.may_change(tab, shared)
    everyone = Access(None)
    assert not everyone.enabled and everyone.may_change(tab, shared) and everyone.login(tab, "")


def test_without_a_token_there_is_no_login_and_everyone_shares():
    from tpm_viz.ui.app import TpmApp, build_server

    application = TpmApp(build_server("127.0.0.1", 0))
    try:
        c1 = ProtocolClient(application.port)
        c2 = ProtocolClient(application.port)
        wait_for(lambda: len(application.views) == 2, what="two tabs")
        v1, v2 = application.views.values()
        wait_for(lambda: v1.session.readout is not None and v2.session.readout is not None, what="first renders")
        assert v1.login is None
        c1.set_value(v1.panel.d[0], 220.0)
        wait_for(lambda: abs(_state(v2).pose.d[0] - 0.22) < 1e-9, what="a change shared by everyone")
        for c in (c1, c2):
            c.close()
    finally:
        application.stop()


def test_a_tab_gone_mid_login_does_not_break_the_others(presenter_app, pconnect):
    client, view = pconnect()
    _login(client, view, TOKEN)
    wait_for(lambda: presenter_app.access.is_presenter(view), what="login")
    client.close()
    wait_for(lambda: view.closed, what="the tab to close")
    assert not presenter_app.access.is_presenter(view)
    other, ov = pconnect()
    other.set_value(ov.panel.d[0], 180.0)
    note = ov.panel.move_note.handle
    wait_for(lambda: "only the presenter" in note.content, what="presenter rights gone with the tab")
    assert threading.active_count() < 200
