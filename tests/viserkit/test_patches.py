"""Each patch of ``viserkit.install`` shows its need (``tpm_viz/viserkit/PATCHES.md``): with it skipped, the symptom
appears as on plain viser 1.1.1; with it on, the symptom is gone. Every other patch stays on in both runs."""

from __future__ import annotations

import collections
import contextlib
import http.client
import math
import threading

import msgspec
import numpy as np
import pytest
from websockets.exceptions import ConnectionClosed

from tests.support.protocol import wait_for
from tpm_viz.classroom.guard import ACTIVITY
from tpm_viz.viserkit import patches
from tpm_viz.viserkit.adapter import install
from tpm_viz.viserkit.core import drop_gizmo_echo
from tpm_viz.viserkit.probe import (
    event_loop,
    gizmo_echoes,
    messages,
    props_api,
    share_tunnel,
    thread_pool,
    tunnel_class,
    widget_uuid,
)
from tpm_viz.viserkit.transport import harden

ON_OFF = pytest.mark.parametrize("on", [True, False], ids=["patched", "skipped"])


def _open(client) -> bool:
    """Whether the tab's connection still answers a ping."""
    with contextlib.suppress(ConnectionClosed, TimeoutError):
        return client.ws.ping().wait(10.0)
    return False


def _closed(client) -> bool:
    return client.ws.close_code is not None


def test_an_unknown_patch_name_is_refused(serve):
    server, _ = serve(patched=False)
    with pytest.raises(ValueError, match="unknown patches"):
        install(server, skip={"frame"})


@ON_OFF
def test_share_url(serve, monkeypatch, on):
    """Any client may ask viser for a share URL: viser then opens a tunnel to an outside relay."""
    opened = []

    def record(self, *args, **kwargs):
        opened.append(args)
        raise OSError("no tunnel in a test")

    monkeypatch.setattr(tunnel_class(), "__init__", record)
    server, _ = serve(skip=set() if on else {"share_url"})
    with contextlib.suppress(OSError):
        server.request_share_url()
    assert (opened == [] and share_tunnel(server) is None) if on else len(opened) == 1


@ON_OFF
def test_wakeups(serve, monkeypatch, on):
    """viser wakes its sender with one write to the event loop's self-pipe per message queued from a callback
    thread; safe wake-ups coalesce those of one loop turn into one."""
    server, _ = serve(skip=set() if on else {"wakeups"})
    loop, busy, free = event_loop(server), threading.Event(), threading.Event()
    loop.call_soon_threadsafe(lambda: (busy.set(), free.wait(30.0)))  # the loop is busy while the thread pushes
    assert busy.wait(30.0)
    writes = []
    real = loop.call_soon_threadsafe
    monkeypatch.setattr(loop, "call_soon_threadsafe", lambda *a, **k: (writes.append(a), real(*a, **k))[1])
    try:
        for k in range(50):
            server.scene.add_frame(f"/probe/{k}", show_axes=False)
    finally:
        free.set()
    assert len(writes) <= 2 if on else len(writes) >= 50


def _count_serialisations(monkeypatch) -> collections.Counter:
    """Counts, per message, viser's serialisation calls, whichever path makes them."""
    counts: collections.Counter = collections.Counter()
    viser_own = messages.Message.as_serializable_dict

    def counted(message, buffers=None):
        if str(getattr(message, "name", "")).startswith("/probe"):
            counts[id(message)] += 1
        return viser_own(message, buffers)

    monkeypatch.setattr(messages.Message, "as_serializable_dict", counted)
    monkeypatch.setattr(patches, "SERIALIZE", counted)
    return counts


def _broadcast_to(server, tabs: list) -> None:
    """One frame to every tab, once each tab has been sent everything before it (so that its window is that frame
    alone, the same window for every tab)."""
    server.scene.add_frame("/sync", show_axes=False)
    wait_for(lambda: all(("/sync", "") in t.nodes for t in tabs), what="every tab to be up to date")
    server.scene.add_frame("/probe", show_axes=False)
    wait_for(lambda: all(("/probe", "") in t.nodes for t in tabs), what="every tab to receive the frame")


@ON_OFF
def test_senders(serve, tab, monkeypatch, on):
    """viser encodes the same window of the shared buffer once per tab; the lean senders once for every tab."""
    counts = _count_serialisations(monkeypatch)
    server, _ = serve(skip={"serialization"} | (set() if on else {"senders"}))
    tabs = [tab(server) for _ in range(4)]
    _broadcast_to(server, tabs)
    assert max(counts.values()) == (1 if on else 4), counts


@ON_OFF
def test_serialization(serve, tab, monkeypatch, on):
    """viser serialises a broadcast message once per tab; shared serialisation once for every tab (the senders
    skipped here, so that each tab's window is encoded on its own)."""
    counts = _count_serialisations(monkeypatch)
    server, _ = serve(skip={"senders"} | (set() if on else {"serialization"}))
    tabs = [tab(server) for _ in range(4)]
    _broadcast_to(server, tabs)
    assert max(counts.values()) == (1 if on else 4), counts


@ON_OFF
def test_casts(serve, tab, monkeypatch, on):
    """viser asks ``np.allclose`` whether each new node's pose changed, and builds four ``npt.NDArray`` aliases for
    each property write; the casts patch does the same checks on plain floats and prebuilt aliases (a returning tab's
    own copy: ~40 nodes, its panel ~400 writes)."""
    server, _ = serve(skip=set() if on else {"casts"})
    tab(server)
    (client,) = server.get_clients().values()
    calls = collections.Counter()
    allclose, aliases = np.allclose, props_api.npt

    class Aliases:
        """numpy.typing as viser's props module sees it, counting ``NDArray[...]``."""

        class NDArray:
            def __class_getitem__(cls, kind):
                calls["alias"] += 1
                return aliases.NDArray[kind]

    monkeypatch.setattr(np, "allclose", lambda *a, **k: (calls.update(["allclose"]), allclose(*a, **k))[1])
    monkeypatch.setattr(props_api, "npt", Aliases)
    frame = client.scene.add_frame("/probe", show_axes=False, position=(0.1, 0.2, 0.0))
    frame.position = (0.3, 0.2, 0.0)
    button = client.gui.add_button("Probe")
    button.label = "Probe again"
    assert tuple(frame.position) == (0.3, 0.2, 0.0) and button.label == "Probe again"
    assert (calls["allclose"], calls["alias"]) == (0, 0) if on else calls["allclose"] >= 3 and calls["alias"] >= 4


@ON_OFF
def test_callbacks(serve, on):
    """A callback's exception in viser's pool goes into a future nobody reads; guarded, it is logged and counted."""
    server, _ = serve(skip=set() if on else {"callbacks", "limits"})
    errors = ACTIVITY.snapshot()[1]

    def broken() -> None:
        raise RuntimeError("a callback failed")

    future = thread_pool(server).submit(broken)
    if on:
        assert future.result(30.0) is None and ACTIVITY.snapshot()[1] == errors + 1
    else:
        with pytest.raises(RuntimeError):
            future.result(30.0)


@ON_OFF
def test_limits(serve, tab, on):
    """One tab's clicks run on as many pool threads as it sends; with the limits, one at a time."""
    server, installed = serve(skip=set() if on else {"limits"})
    running, most, free = [0], [0], threading.Event()
    lock = threading.Lock()
    button = server.gui.add_button("Slow")

    @button.on_click
    def _(_event) -> None:
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        free.wait(30.0)
        with lock:
            running[0] -= 1

    client = tab(server)
    (cid,) = server.get_clients()
    try:
        for _ in range(3):
            client.send(type="GuiUpdateMessage", uuid=widget_uuid(button), updates={"value": True})
        if on:
            wait_for(lambda: installed.guard.gate.pending(cid) == 2, what="one click running, one waiting")
            assert most[0] == 1
        else:
            wait_for(lambda: most[0] >= 2, what="two clicks running at once")
    finally:
        free.set()


def _upload_part(size: int) -> bytes:
    message = {"type": "FileTransferPart", "source_component_uuid": None, "transfer_uuid": "t", "part_index": 0}
    return msgspec.msgpack.encode(message | {"content": b"x" * size})


@ON_OFF
def test_frames(serve, tab, on):
    """viser takes websocket frames up to 50 MiB and answers a URL segment too long for the file system with HTTP
    500; limited, a frame over 1 MiB closes the connection (1009) and the URL gets 414."""
    server, _ = serve(skip=set() if on else {"frames"})
    client = tab(server)
    client.ws.send(_upload_part(2 << 20))
    if on:
        wait_for(lambda: _closed(client), what="the connection to be closed")
        assert client.ws.close_code == 1009
    else:
        assert _open(client)
    http_client = http.client.HTTPConnection("127.0.0.1", server.get_port(), timeout=30)
    http_client.request("GET", "/" + "a" * 300)
    assert http_client.getresponse().status == (414 if on else 500)


@ON_OFF
def test_decoding(serve, tab, on):
    """A message viser cannot build (a missing field) raises in its reader: the connection is closed with a
    traceback in the log; decoded quietly, it is dropped and the tab stays."""
    server, _ = serve(skip=set() if on else {"decoding"})
    client = tab(server)
    client.send(type="GuiUpdateMessage", uuid="x")
    if on:
        assert _open(client)
    else:
        wait_for(lambda: _closed(client), what="the connection to be closed")


@ON_OFF
def test_transport(serve, tab, on):
    """viser takes any number a tab sends as a slider's value (NaN included: its callbacks run); filtered, only a
    finite value of the widget's kind gets through."""
    server, _ = serve(skip=set() if on else {"transport"})
    made, seen = [], []

    def connected(client) -> None:
        harden(client)
        slider = client.gui.add_slider("Speed", 0.0, 10.0, 1.0, 5.0)  # a tab's own widget, as the app's are
        slider.on_update(lambda _event: seen.append(slider.value))
        made.append(slider)

    server.on_client_connect(connected)
    client = tab(server)
    (slider,) = wait_for(lambda: made, what="the tab's slider")
    client.send(type="GuiUpdateMessage", uuid=widget_uuid(slider), updates={"value": math.nan})
    client.send(type="GuiUpdateMessage", uuid=widget_uuid(slider), updates={"value": 7.0})
    wait_for(lambda: slider.value == 7.0 and len(seen) >= (1 if on else 2), what="the good value's callback")
    assert len(seen) == (1 if on else 2), seen


@ON_OFF
def test_handshakes(serve, on):
    """viser answers every request itself; hooked, the app sees each one first (here: refuses one path)."""

    def hook(connection, request, viser_response):
        return connection.respond(403, "refused\n") if request.path == "/refused" else viser_response()

    server, _ = serve(handshake=hook if on else None)
    http_client = http.client.HTTPConnection("127.0.0.1", server.get_port(), timeout=30)
    http_client.request("GET", "/refused")
    assert (http_client.getresponse().status == 403) is on


@ON_OFF
def test_gizmo_echo(serve, tab, on):
    """viser echoes a client-scoped gizmo's drags to every other tab (none: the gizmo is this tab's own)."""
    server, _ = serve(skip=set() if on else {"gizmo_echo"})
    tab(server)
    (client,) = server.get_clients().values()
    gizmo = client.scene.add_transform_controls("/gizmo")
    drop_gizmo_echo(gizmo)
    assert gizmo_echoes(gizmo) is not on
