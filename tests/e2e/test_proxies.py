"""Know who is local (issue 23): a reverse proxy on the laptop (a small TCP proxy on loopback that adds
X-Forwarded-For, tests/support/forwarding_proxy.py), ``--trusted-proxy``, the Host allow-list against DNS
rebinding, and malformed or duplicated headers (400, never 500).

"This computer" is 127.0.0.1 here; a client that binds 127.0.0.2 stands for another machine (the classroom's
``presenter_address`` is "exactly 127.0.0.1", since the whole 127/8 is loopback on the test machine).
"""

from __future__ import annotations

import logging
import socket
import threading
import time

import msgspec
import pytest
import viser
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect as connect_sync

from tests.support.forwarding_proxy import ForwardingProxy
from tests.support.pages import ADDRESSES, TOKEN, Page
from tests.support.protocol import CAMERA, wait_for
from tpm_viz.classroom.network import PROXIED, UNKNOWN, HostRules, Network, client_address, header_problem, host_name
from tpm_viz.cli import main as cli_main
from tpm_viz.core.errors import InputError
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import Classroom

HERE = "127.0.0.1"
OTHER = "127.0.0.2"


class Tab(Page):
    """A protocol-level tab that connects from ``source`` with extra ``headers`` (and a browser's Origin)."""

    def __init__(self, port: int, source: str = HERE, headers: dict | None = None) -> None:
        self.ws = connect_sync(
            f"ws://127.0.0.1:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            compression=None,
            origin=f"http://127.0.0.1:{port}",
            additional_headers=headers,
            source_address=(source, 0),
        )
        self.uuids, self.values, self.first_uuid, self.on_widget = {}, {}, {}, None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()
        self.ws.send(msgspec.msgpack.encode(CAMERA))


def _app(trusted=(), allowed=()):
    network = Network.of(trusted, allowed)
    room = Classroom(addresses=lambda: list(ADDRESSES), presenter_address=lambda host: host == HERE, token=TOKEN)
    rules = HostRules(network, addresses=lambda: list(ADDRESSES), bound=HERE)
    return TpmApp(build_server(HERE, 0, rules), classroom=room)


def _view_of_new_tab(app, make):
    """Open a tab with ``make()`` and return ``(tab, its view)`` once the classroom has placed it."""
    before = set(app.views)
    tab = make()
    wait_for(lambda: set(app.views) - before, what="the new tab's view")
    (client_id,) = set(app.views) - before
    view = app.views[client_id]
    wait_for(lambda: view in app.arrived, what="the classroom's part of the tab")
    return tab, view


@pytest.fixture
def opened():
    things: list = []
    yield things
    for thing in reversed(things):
        thing.stop() if isinstance(thing, TpmApp) else thing.close()


def test_without_trusted_proxy_a_proxy_on_the_laptop_makes_nobody_presenter(opened, caplog):
    app = _app()
    opened.append(app)
    proxy = ForwardingProxy(app.port)
    opened.append(proxy)
    with caplog.at_level(logging.WARNING, logger="tpm_viz.ui"):
        tabs = []
        for source in (HERE, OTHER, OTHER):  # before: every tab through the proxy was "on this computer"
            tab, view = _view_of_new_tab(app, lambda s=source: Tab(proxy.port, s))
            opened.append(tab)
            tabs.append(view)
            assert not app.access.is_presenter(view) and view.address == f"{PROXIED} 127.0.0.1"
        direct, lecturer = _view_of_new_tab(app, lambda: Tab(app.port, HERE))
        opened.append(direct)
        assert app.access.is_presenter(lecturer) and lecturer.address == HERE
    warned = [r for r in caplog.records if "reverse proxy?" in r.getMessage()]
    assert len(warned) == 1 and "--trusted-proxy 127.0.0.1" in warned[0].getMessage()


@pytest.mark.parametrize("style", ["xff", "forwarded"])
def test_with_trusted_proxy_the_students_address_is_read_and_only_the_laptop_presents(opened, style):
    app = _app(trusted=[HERE])
    opened.append(app)
    proxy = ForwardingProxy(app.port, style=style)
    opened.append(proxy)
    tab, student = _view_of_new_tab(app, lambda: Tab(proxy.port, OTHER))
    opened.append(tab)
    assert student.address == OTHER and not app.access.is_presenter(student)
    tab, lecturer = _view_of_new_tab(app, lambda: Tab(proxy.port, HERE))  # the lecturer's browser, through nginx
    opened.append(tab)
    assert lecturer.address == HERE and app.access.is_presenter(lecturer)


def test_a_student_cannot_claim_to_be_the_laptop(opened):
    app = _app(trusted=[HERE])
    opened.append(app)
    proxy = ForwardingProxy(app.port)
    opened.append(proxy)
    spoof = {"X-Forwarded-For": HERE, "Forwarded": f"for={HERE}"}
    tab, direct = _view_of_new_tab(app, lambda: Tab(app.port, OTHER, spoof))  # not from the trusted proxy
    opened.append(tab)
    assert not app.access.is_presenter(direct) and direct.address == f"{PROXIED} {OTHER}"
    tab, through = _view_of_new_tab(app, lambda: Tab(proxy.port, OTHER, spoof))  # the proxy appends the real one
    opened.append(tab)
    assert not app.access.is_presenter(through) and through.address == OTHER


# -- Host allow-list and header sanity ------------------------------------------------------------------------------
def _raw(port: int, head: str) -> int:
    """The status code of a raw HTTP request ``head`` (header lines, CRLF-joined, without the blank line)."""
    with socket.create_connection((HERE, port), timeout=30) as sock:
        sock.sendall(head.encode("latin-1") + b"\r\n\r\n")
        data = b""
        while b"\r\n" not in data:
            chunk = sock.recv(4096)
            if not chunk:
                break
            data += chunk
    return int(data.split(b" ", 2)[1])


def _upgrade(port: int, *lines: str) -> str:
    return "\r\n".join(
        [
            "GET / HTTP/1.1",
            "Upgrade: websocket",
            "Connection: Upgrade",
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
            "Sec-WebSocket-Version: 13",
            f"Sec-WebSocket-Protocol: viser-v{viser.__version__}",
            *lines,
        ]
    )


@pytest.fixture(scope="module")
def served():
    app = _app(allowed=["tpm.example.edu"])
    yield app
    app.stop()


@pytest.mark.parametrize(
    "host",
    ["127.0.0.1:{port}", "localhost:{port}", "[::1]:{port}", "LOCALHOST", "192.0.2.7:{port}", "tpm.example.edu"],
)
def test_the_page_answers_to_this_machines_names_and_the_allowed_ones(served, host):
    assert _raw(served.port, f"GET / HTTP/1.1\r\nHost: {host.format(port=served.port)}") == 200


@pytest.mark.parametrize("host", ["rebind.example", "rebind.example:{port}", "203.0.113.9:{port}", "tpm.example.com"])
def test_any_other_host_gets_403_on_the_page_and_the_websocket(served, host):
    host = host.format(port=served.port)
    assert _raw(served.port, f"GET / HTTP/1.1\r\nHost: {host}") == 403
    assert _raw(served.port, _upgrade(served.port, f"Host: {host}", f"Origin: http://{host}")) == 403


def test_a_dns_rebinding_handshake_is_refused(served):
    """Host and Origin both ``rebind.example``: same-origin, and refused all the same."""
    with pytest.raises(InvalidStatus) as refused:
        connect_sync(  # the browser resolved rebind.example to 127.0.0.1: the socket goes there, the names stay
            f"ws://rebind.example:{served.port}",
            sock=socket.create_connection((HERE, served.port), timeout=30),
            subprotocols=[f"viser-v{viser.__version__}"],
            origin=f"http://rebind.example:{served.port}",
        )
    assert refused.value.response.status_code == 403


@pytest.mark.parametrize(
    "lines",
    [
        ["Host: 127.0.0.1", "Host: rebind.example"],
        ["Host: 127.0.0.1", "Origin: http://127.0.0.1", "Origin: http://evil.example"],
        ["Host: 127.0.0.1", "Cookie: a=1", "Cookie: b=2"],
        ["Host: bad host name"],
        ["Host: 127.0.0.1:99999"],
        ["Host: 127.0.0.1", "Origin: http://[::1"],
        ["Host: 127.0.0.1", "Origin: http://a b.example"],
        ["Host: 127.0.0.1", "Accept-Encoding: gzip", "Accept-Encoding: br"],
    ],
    ids=[
        "host-twice",
        "origin-twice",
        "cookie-twice",
        "host-space",
        "host-port",
        "origin-bracket",
        "origin-space",
        "enc",
    ],
)
def test_malformed_or_duplicated_headers_get_400_never_500(served, lines):
    assert _raw(served.port, "\r\n".join(["GET / HTTP/1.1", *lines])) == 400
    assert _raw(served.port, _upgrade(served.port, *lines)) == 400


def test_a_flood_of_refused_requests_is_a_few_log_lines(caplog):
    app = _app(allowed=["tpm.example.edu"])  # its own server: no earlier refusal inside the last second
    try:
        with caplog.at_level(logging.WARNING, logger="tpm_viz.ui"):
            start = time.monotonic()
            for _ in range(200):
                assert _raw(app.port, "GET / HTTP/1.1\r\nHost: rebind.example") == 403
            elapsed = time.monotonic() - start
    finally:
        app.stop()
    refused = [r for r in caplog.records if "refused a request" in r.getMessage()]
    assert 1 <= len(refused) <= 1 + elapsed  # the first refusal, then one line a second at most


# -- the rules without a server ---------------------------------------------------------------------------------------
def test_client_address_rules():
    trusted = Network.of(["127.0.0.1", "10.0.0.0/24"])
    none = Network()
    assert client_address("127.0.0.1", ["192.0.2.5"], [], trusted) == "192.0.2.5"
    assert client_address("127.0.0.1", ["127.0.0.1, 192.0.2.5, 10.0.0.3"], [], trusted) == "192.0.2.5"
    assert client_address("127.0.0.1", ["1.1.1.1", "192.0.2.5:4711"], [], trusted) == "192.0.2.5"
    assert client_address("127.0.0.1", [], ['for="[2001:db8::17]:4711";proto=https'], trusted) == "2001:db8::17"
    assert client_address("127.0.0.1", [], ["for=192.0.2.1, for=_hidden"], trusted) == UNKNOWN
    assert client_address("127.0.0.1", ["not an address"], [], trusted) == UNKNOWN
    assert client_address("127.0.0.1", [], [], trusted) == UNKNOWN  # a trusted proxy that named nobody
    assert client_address("127.0.0.1", ["10.0.0.2"], [], trusted) == "10.0.0.2"  # only proxies: the first
    assert client_address("::ffff:127.0.0.1", ["192.0.2.5"], [], trusted) == "192.0.2.5"
    assert client_address("192.0.2.9", ["127.0.0.1"], [], trusted) == "192.0.2.9"  # not a proxy: ignored
    assert client_address("127.0.0.1", ["192.0.2.5"], [], none) == f"{PROXIED} 127.0.0.1"
    assert client_address("127.0.0.1", [], [], none) == "127.0.0.1"


def test_host_and_header_rules():
    assert host_name("LocalHost:8080") == "localhost" and host_name("[::1]:80") == "::1"
    assert host_name("tpm.example.edu.") == "tpm.example.edu"
    for bad in ("", "a b", "[::1", "x:y", "127.0.0.1:70000", "a/b", "é.example"):
        assert host_name(bad) is None, bad
    headers = {"host": ["127.0.0.1"], "origin": ["null"]}
    assert header_problem(lambda name: headers.get(name.lower(), [])) is None
    assert "twice" in header_problem(lambda name: {"host": ["a", "b"]}.get(name.lower(), []))
    with pytest.raises(InputError, match="--trusted-proxy 'nope'"):
        Network.of(["nope"])
    with pytest.raises(InputError, match="--allowed-host"):
        Network.of([], ["bad name!"])


@pytest.mark.parametrize(
    ("flag", "value"), [("--trusted-proxy", "not-an-address"), ("--allowed-host", "a b"), ("--trusted-proxy", "")]
)
def test_bad_network_flags_are_one_line_and_exit_2(tmp_path, capsys, flag, value):
    argv = ["serve", "--port", "0", "--fresh", "--session", str(tmp_path / "s.json"), flag, value]
    assert cli_main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and flag in err
