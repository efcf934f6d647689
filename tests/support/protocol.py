"""The one protocol-level test client, shared by the tests and the benchmarks: browser tabs without a browser.

:class:`ProtocolClient` is a synchronous tab for tests against an in-process app (it sends what a browser sends and
records the scene nodes it was sent); :class:`Tab` is an asyncio tab for the load and soak benchmarks.

:class:`ServerProcess` starts ``python app.py --port 0`` on 127.0.0.1 (optionally with a presenter token, a session
file and more options; by default a session file of its own in a temporary folder), reads the port from its first
printed line, measures its CPU time and resident memory from ``/proc/<pid>``, keeps its stderr
(the server log) in a temporary file and stops it by its own pid.

:class:`Tab` is one browser tab without a browser (websocket subprotocol ``viser-v<version>``, msgpack messages,
a camera message first): it learns its gizmo owner id and the uuids of the widgets it needs from the messages the
server sends, drags the gizmo, and timestamps every incoming platform position (decoded like viser's own client:
16-byte header, zstd-compressed msgpack). Latency = a drag update sent -> the platform update with that exact
position received.
"""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import msgspec
import viser
import zstandard
from websockets.asyncio.client import connect
from websockets.sync.client import connect as connect_sync

from tpm_viz.viserkit.probe import widget_uuid

ROOT = Path(__file__).resolve().parents[2]
CLK_TCK = os.sysconf("SC_CLK_TCK")
GIZMO_Z = 0.09
PLATFORM_NODES = ("/tpm/platform", "/own/platform")
"""The shared platform (broadcast, owner "") and a private copy's (this tab's own scope)."""
CAMERA = dict(
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
"""The first message of every tab: viser registers a client when its camera arrives."""


class ServerProcess:
    """``python app.py --port 0`` on loopback, in a child process."""

    def __init__(
        self,
        presenter_token: str | None = None,
        session: Path | None = None,
        args: tuple[str, ...] = (),
        root: Path | None = None,
    ) -> None:
        """``session``: the session file (default: a new one in a temporary folder, never the user's);
        ``args``: more command-line options (e.g. ``--fresh``); ``root``: the checkout whose ``app.py`` runs
        (default: this one; a benchmark measures another, e.g. the code before a change)."""
        root = ROOT if root is None else Path(root)
        self.log = tempfile.NamedTemporaryFile(prefix="tpm-viz-server-", suffix=".log", delete=False)
        if session is None:
            session = Path(tempfile.mkdtemp(prefix="tpm-viz-session-")) / "session.json"
        self.session = session
        cmd = [sys.executable, str(root / "app.py"), "--host", "127.0.0.1", "--port", "0", "--session", str(session)]
        if presenter_token:
            cmd += ["--presenter-token", presenter_token]
        cmd += list(args)
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.log, text=True, cwd=root)
        line = self.proc.stdout.readline().strip()
        if not line.startswith("tpm-viz serving at http://127.0.0.1:"):
            self.stop()
            raise RuntimeError(f"the server did not start: {line!r}; log in {self.log.name}")
        self.port = int(line.rsplit(":", 1)[1])
        self.pid = self.proc.pid

    def cpu_seconds(self) -> float:
        """User + system CPU time of the server so far [s] (``/proc/<pid>/stat``, all threads)."""
        fields = Path(f"/proc/{self.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / CLK_TCK

    def rss_mb(self) -> float:
        """Resident memory of the server [MB] (``/proc/<pid>/status``)."""
        for line in Path(f"/proc/{self.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
        return float("nan")

    def log_problems(self) -> list[str]:
        """Lines of the server log that report an exception or an error."""
        text = Path(self.log.name).read_text(errors="replace")
        keys = ("Traceback", "ERROR", "Error:", "Exception")
        return [line for line in text.splitlines() if any(k in line for k in keys)]

    def stop(self) -> None:
        """Stop the server (SIGTERM to its own pid, then SIGKILL after 10 s)."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=10)
        self.proc.stdout.close()
        self.log.close()


def machine_busy_seconds() -> float:
    """CPU time [s] all processes of the machine have used so far (``/proc/stat``: everything but idle, iowait and
    the time the hypervisor gave to other machines, :func:`stolen_seconds`)."""
    fields = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    return (sum(fields[:7]) - fields[3] - fields[4]) / CLK_TCK


def stolen_seconds() -> float:
    """CPU time [s] this virtual machine was ready to run but the hypervisor ran another (``/proc/stat``, steal):
    a benchmark run with much of it measured a busy host, not the app."""
    return int(Path("/proc/stat").read_text().splitlines()[0].split()[8]) / CLK_TCK


_local = threading.local()  # a zstd decompressor is not thread-safe: one per reading thread
_encode = msgspec.msgpack.encode


def decode_batch(raw: bytes) -> list[dict]:
    """The messages of one server -> client websocket frame."""
    return decode_frame(raw)[0]


def decode_frame(raw: bytes) -> tuple[list[dict], float | None]:
    """The messages of one server -> client websocket frame and the server's ``time.perf_counter()`` when it encoded
    them (on Linux the same clock in every process of the machine)."""
    size, compressed = int.from_bytes(raw[:8], "little"), int.from_bytes(raw[8:16], "little")
    if not hasattr(_local, "zstd"):
        _local.zstd = zstandard.ZstdDecompressor()
    inner = _local.zstd.decompress(raw[16 : 16 + compressed], max_output_size=size)
    frame = msgspec.msgpack.decode(inner)
    return frame["messages"], frame.get("timestampSec")


def key(x: float, y: float) -> tuple[int, int]:
    """A drag target as an exact lookup key (0.1 µm)."""
    return round(x * 1e7), round(y * 1e7)


class Tab:
    """One protocol-level tab (see the module docstring)."""

    def __init__(self, port: int, name: str = "tab") -> None:
        self.port, self.name = port, name
        self.owner: str | None = None
        self.uuids: dict[str, str] = {}  # widget label -> uuid
        self.sent: dict[tuple[int, int], float] = {}  # drag target -> send time (perf_counter), until received
        self.log: dict[tuple[int, int], float] = {}  # every drag target sent -> send time (kept)
        self.watch: dict[tuple[int, int], float] | None = None  # another tab's ``log``: this tab times its sends
        self._seen: set[tuple[int, int]] = set()
        self.latencies: list[float] = []
        self.in_server: list[float] = []  # of each latency: send -> the server encoded the frame (same order)
        self.received = 0
        self.ready = asyncio.Event()
        self.ws = None
        self._reader: asyncio.Task | None = None

    async def open(self, timeout: float = 30.0) -> None:
        self.ws = await connect(
            f"ws://127.0.0.1:{self.port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            compression=None,
            open_timeout=timeout,
        )
        self._reader = asyncio.create_task(self._read())
        await self.send(**CAMERA)
        await asyncio.wait_for(self.ready.wait(), timeout)

    async def send(self, **message) -> None:
        await self.ws.send(_encode(message))

    async def _read(self) -> None:
        try:
            async for raw in self.ws:
                now = time.perf_counter()
                self.received += 1
                messages, encoded = decode_frame(raw)
                for m in messages:
                    kind = m["type"]
                    if kind == "SetPositionMessage" and m["name"] in PLATFORM_NODES and m["owner"] in (self.owner, ""):
                        k = key(m["position"][0], m["position"][1])
                        sent = self.sent.pop(k, None)
                        if sent is None and self.watch is not None and k in self.watch and k not in self._seen:
                            self._seen.add(k)
                            sent = self.watch[k]
                        if sent is not None:
                            self.latencies.append(now - sent)
                            self.in_server.append((encoded if encoded is not None else now) - sent)
                    elif kind == "TransformControlsMessage" and m["name"] == "/gizmo":
                        self.owner = m["owner"]
                    elif kind.startswith("Gui") and "uuid" in m and isinstance(m.get("props"), dict):
                        label = m["props"].get("label")
                        if label:
                            self.uuids[label] = m["uuid"]
                if self.owner is not None and "Work on my own copy" in self.uuids:
                    self.ready.set()
        except Exception:  # connection closed
            return

    async def set_value(self, label: str, value) -> None:
        """What the browser sends when the widget labelled ``label`` changes (a button: ``value=True``)."""
        for _ in range(1000):  # widgets added after the first ones (e.g. the presenter login) arrive later
            if label in self.uuids:
                break
            await asyncio.sleep(0.01)
        await self.send(type="GuiUpdateMessage", uuid=self.uuids[label], updates={"value": value})

    async def drag(self, x: float, y: float, phase: str = "update") -> None:
        """One gizmo message: ``start``, ``update`` (timed) or ``end``."""
        if phase == "start":
            await self.send(type="TransformControlsDragStartMessage", name="/gizmo", owner=self.owner)
        elif phase == "end":
            await self.send(type="TransformControlsDragEndMessage", name="/gizmo", owner=self.owner)
        else:
            self.sent[key(x, y)] = self.log[key(x, y)] = time.perf_counter()
            await self.send(
                type="TransformControlsUpdateMessage",
                name="/gizmo",
                wxyz=(1.0, 0.0, 0.0, 0.0),
                position=(float(x), float(y), GIZMO_Z),
                owner=self.owner,
            )

    async def close(self) -> None:
        if self.ws is not None:
            await self.ws.close()
        if self._reader is not None:
            await asyncio.wait([self._reader], timeout=5.0)


AFTER_WAITS: list = []
"""Called, in order, when a :func:`wait_for` is met (:func:`tests.support.fixtures.whole_steps` puts one here: every
live hub's lock taken and given back, so that the locked step that wrote the awaited value has written the rest)."""


def wait_for(predicate, timeout: float = 30.0, interval: float = 0.01, what: str = "condition"):
    """Poll ``predicate`` until it returns a truthy value (returned) or fail after ``timeout`` seconds (a bound,
    not a speed: 30 s holds while a second full run loads the machine, where 10 s did not always). Once met, each
    of :data:`AFTER_WAITS` is called."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            for after in list(AFTER_WAITS):
                after()
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


class ProtocolClient:
    """A browser stand-in at the websocket level (see the module docstring)."""

    def __init__(self, port: int, source: str | None = None) -> None:
        """``source``: the loopback address to connect from (e.g. ``127.0.0.2``: another device)."""
        sock = None if source is None else socket.create_connection(("127.0.0.1", port), 30, (source, 0))
        self.ws = connect_sync(
            f"ws://127.0.0.1:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            compression=None,
            sock=sock,
        )
        self.received = 0
        self.nodes: dict[tuple[str, str], dict] = {}
        """Scene nodes this tab was sent, ``(name, owner) -> message`` (owner "" = the broadcast scope)."""
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        self.send(**CAMERA)

    def _drain(self) -> None:
        while not self._stop.is_set():
            try:
                raw = self.ws.recv(timeout=0.2)
                self.received += 1
            except TimeoutError:
                continue
            except Exception:  # connection closed
                return
            now = time.perf_counter()
            for m in decode_batch(raw):
                self.take(m, now)

    def take(self, m: dict, now: float) -> None:
        """One decoded message, received at ``now`` (``time.perf_counter``), on the reader thread: subclasses
        record more (call this one for the scene nodes)."""
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
        self.ws.send(_encode(message))

    def set_value(self, handle, value) -> None:
        """What the browser sends when the user changes a GUI input (or clicks a button: ``value=True``)."""
        self.send(type="GuiUpdateMessage", uuid=widget_uuid(handle), updates={"value": value})

    def click(self, button) -> None:
        self.set_value(button, True)

    def enter(self, box, texts: dict | None = None) -> None:
        """Type ``texts`` (field key -> text) into a typed box (``tpm_viz.ui.fields.TypedBox``), as a browser sends
        them (the whole text at each keystroke: here the last one), then press Enter in it (the form's submit)."""
        for key, text in (texts or {}).items():
            self.set_value(box.inputs[key], text)
        self.send(type="GuiFormSubmitMessage", uuid=widget_uuid(box.form))

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
