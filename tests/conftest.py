"""Fixtures for the app tests: a served app on a free loopback port, a protocol-level client, headless Chromium.

- ``app``: a :class:`tpm_viz.ui.app.TpmApp` on ``127.0.0.1``, port 0 (a free one); stopped afterwards.
- ``ws_client``: a client that speaks viser's websocket protocol from Python (msgpack messages, subprotocol
  ``viser-v<version>``), registers with a camera message like a browser does, and can send the GUI and gizmo
  messages a browser would send. Tests of the wiring use it: no browser needed.
- ``browser``: a Playwright Chromium context (Debian's ``/usr/bin/chromium``, fresh profile); the test is skipped
  when Chromium or Playwright is missing.
"""

from __future__ import annotations

import os
import tempfile
import threading
import time

import pytest

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


WORKER_LOG_JS = """
(() => {
  // Wrap the websocket Web Worker: log every decoded incoming message and every outgoing one, with
  // performance.now() timestamps (ms), in window.__viserLog.
  const Orig = window.Worker;
  const log = (window.__viserLog = []);
  function Wrapped(url, opts) {
    const w = new Orig(url, opts);
    const post = w.postMessage.bind(w);
    w.postMessage = (data, transfer) => {
      if (data && data.type === "send" && data.message) {
        log.push({ dir: "out", t: performance.now(), type: data.message.type, uuid: data.message.uuid,
                   name: data.message.name });
      }
      return post(data, transfer);
    };
    w.addEventListener("message", (ev) => {
      const d = ev.data;
      if (d && d.type === "message_batch") {
        const t = performance.now();
        for (const m of d.messages) log.push({ dir: "in", t, type: m.type, uuid: m.uuid, name: m.name });
      }
    });
    return w;
  }
  Wrapped.prototype = Orig.prototype;
  window.Worker = Wrapped;
})();
"""
"""Init script for a page: a timestamped log of viser's websocket messages in ``window.__viserLog``."""


def wait_for(predicate, timeout: float = 10.0, interval: float = 0.01, what: str = "condition"):
    """Poll ``predicate`` until it returns a truthy value (returned) or fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


class ProtocolClient:
    """A browser stand-in at the websocket level (see the module docstring)."""

    def __init__(self, port: int) -> None:
        import msgspec
        import viser
        from websockets.sync.client import connect

        self._encode = msgspec.msgpack.encode
        self.ws = connect(
            f"ws://127.0.0.1:{port}", subprotocols=[f"viser-v{viser.__version__}"], max_size=None, compression=None
        )
        self.received = 0
        self.nodes: dict[tuple[str, str], dict] = {}
        """Scene nodes this tab was sent, ``(name, owner) -> message`` (owner "" = the broadcast scope)."""
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        self.send(
            type="ViewerCameraMessage",
            wxyz=(1.0, 0.0, 0.0, 0.0),
            position=(0.0, -1.0, 1.0),
            fov=1.0,
            near=0.01,
            far=100.0,
            image_height=720,
            image_width=1280,
            look_at=(0.0, 0.0, 0.0),
            up_direction=(0.0, 0.0, 1.0),
        )

    def _drain(self) -> None:
        import msgspec
        import zstandard

        decompress = zstandard.ZstdDecompressor().decompress
        while not self._stop.is_set():
            try:
                raw = self.ws.recv(timeout=0.2)
                self.received += 1
            except TimeoutError:
                continue
            except Exception:  # connection closed
                return
            size, compressed = int.from_bytes(raw[:8], "little"), int.from_bytes(raw[8:16], "little")
            for m in msgspec.msgpack.decode(decompress(raw[16 : 16 + compressed], max_output_size=size))["messages"]:
                if "owner" in m and "name" in m:  # a scene-node message (viser 1.1.1: stamped with its scope)
                    self._record(m)

    def _record(self, m: dict) -> None:
        key = (m["name"], m["owner"])
        if m["type"] == "RemoveSceneNodeMessage":
            self.nodes.pop(key, None)
        elif "props" in m:  # a node created (or re-created); its visibility follows in its own message
            self.nodes[key] = {"type": m["type"], "visible": True, "virtual": m.get("virtual", False)}
        elif m["type"] == "SetSceneNodeVisibilityMessage" and key in self.nodes:
            self.nodes[key]["visible"] = m["visible"]

    def shadows(self) -> set[str]:
        """Names this tab hides with an invisible node of its own over a broadcast node (viser's scope shadowing)."""
        own = {name for (name, owner), n in self.nodes.items() if owner != "" and not n["visible"] and not n["virtual"]}
        return {name for name in own if (name, "") in self.nodes} | {n for n in own if n == "/tpm"}

    def send(self, **message) -> None:
        """Send one message (a dict with its ``type``), msgpack-encoded like viser's client does."""
        self.ws.send(self._encode(message))

    def set_value(self, handle, value) -> None:
        """What the browser sends when the user changes a GUI input (or clicks a button: ``value=True``)."""
        self.send(type="GuiUpdateMessage", uuid=handle._impl.uuid, updates={"value": value})

    def click(self, button) -> None:
        self.set_value(button, True)

    def drag(self, gizmo, owner: str, positions, end: bool = True) -> None:
        """A gizmo drag through ``positions`` (x, y, z) [m], as start, updates and (optionally) end."""
        name = gizmo.name
        self.send(type="TransformControlsDragStartMessage", name=name, owner=owner)
        for pos in positions:
            self.send(
                type="TransformControlsUpdateMessage",
                name=name,
                wxyz=(1.0, 0.0, 0.0, 0.0),
                position=tuple(float(v) for v in pos),
                owner=owner,
            )
        if end:
            self.send(type="TransformControlsDragEndMessage", name=name, owner=owner)

    def close(self) -> None:
        self._stop.set()
        self.ws.close()
        self._reader.join(timeout=2.0)


@pytest.fixture
def app():
    """The app on a free loopback port (viser imported only by the tests that use it)."""
    from tpm_viz.ui.app import TpmApp, build_server

    server = build_server("127.0.0.1", 0)
    application = TpmApp(server)
    yield application
    application.stop()


@pytest.fixture
def connect(app):
    """``connect()`` opens a protocol client and returns ``(client, view)`` once the app built its view."""
    opened: list[ProtocolClient] = []

    def _connect():
        before = set(app.views)
        client = ProtocolClient(app.port)
        opened.append(client)
        new = wait_for(lambda: set(app.views) - before, what="the app to build a view for the client")
        view = app.views[next(iter(new))]
        wait_for(lambda: view.session.readout is not None, what="the first render")
        return client, view

    yield _connect
    for client in opened:  # one at a time: each tab's departure is processed before the next one leaves
        count = len(app.views)
        client.close()
        wait_for(lambda count=count: len(app.views) < count, what="the app to drop the closed tab")


@pytest.fixture
def browser():
    """A headless Chromium context with a fresh profile; skips when Chromium or Playwright is missing."""
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with tempfile.TemporaryDirectory() as profile, sync_api.sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            profile,
            executable_path=CHROMIUM,
            args=CHROMIUM_ARGS,
            headless=True,
            viewport={"width": 1400, "height": 860},
        )
        try:
            yield context
        finally:
            context.close()
