"""The patches act on tpm-viz's own server only: a plain ``viser.ViserServer`` started in the same process after it
behaves like unpatched viser, and ``Installed.remove()`` gives a server back its viser behaviour."""

from __future__ import annotations

import contextlib
import gc
import http.client

import viser
import websockets.asyncio.server
import websockets.server

from tests.support.protocol import wait_for
from tests.viserkit.test_patches import _broadcast_to, _closed, _count_serialisations, _open, _upload_part
from tpm_viz.viserkit.patches import count, registered
from tpm_viz.viserkit.probe import event_loop, shared_buffer


def _status(server, path: str) -> int:
    client = http.client.HTTPConnection("127.0.0.1", server.get_port(), timeout=30)
    client.request("GET", path)
    return client.getresponse().status


def _behaves_like_viser(server, tab, counts) -> None:
    """What viser 1.1.1 does, where tpm-viz's patches would do otherwise."""
    assert "request_share_url" not in vars(server)  # viser's own method
    assert shared_buffer(server).event_loop is event_loop(server)  # no coalesced wake-ups
    assert _status(server, "/" + "a" * 300) == 500  # no 414
    tabs = [tab(server) for _ in range(3)]
    _broadcast_to(server, tabs)
    assert max(counts.values()) == 3  # serialised once per tab
    tabs[0].ws.send(_upload_part(2 << 20))  # a 2 MiB frame is taken
    assert _open(tabs[0])
    tabs[1].send(type="GuiUpdateMessage", uuid="x")  # a message viser cannot build closes the connection
    wait_for(lambda: _closed(tabs[1]), what="viser to close the connection")


def test_a_plain_viser_server_beside_a_tpm_viz_server_is_untouched(serve, tab, monkeypatch):
    counts = _count_serialisations(monkeypatch)
    ours, _ = serve()
    plain = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        assert registered(ours) and not registered(plain)
        _behaves_like_viser(plain, tab, counts)
        counts.clear()
        mine = tab(ours)  # and tpm-viz's server still has its patches
        mine.ws.send(_upload_part(2 << 20))
        wait_for(lambda: _closed(mine), what="the frame limit")
        assert _status(ours, "/" + "a" * 300) == 414
    finally:
        with contextlib.suppress(Exception):
            plain.stop()


def test_remove_gives_the_server_back_its_viser_behaviour(serve, tab, monkeypatch):
    counts = _count_serialisations(monkeypatch)
    server, installed = serve()
    other, other_installed = serve()
    installed.remove()
    assert not registered(server) and registered(other)
    assert websockets.asyncio.server.ServerProtocol is not websockets.server.ServerProtocol  # still guarding other
    _behaves_like_viser(server, tab, counts)
    other_installed.remove()
    gc.collect()  # the servers of earlier tests, stopped, are forgotten (weakly registered)
    original = websockets.asyncio.server.ServerProtocol is websockets.server.ServerProtocol
    assert original is (count() == 0)  # the original is back once no tpm-viz server is left
