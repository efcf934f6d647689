"""The one door to viser's private internals (viser 1.1.x). No other module of tpm-viz touches a private viser name.

tpm-viz needs these things viser's public API does not offer:

- the server's callback thread pool (``server._thread_executor``), to guard every callback (:mod:`.guard`);
- a tab's message handlers (``client._websock_connection``, ``gui._handle_gui_updates``,
  ``gui._handle_file_transfer_start/part``, ``gui._current_file_upload_states``, ``gui._gui_input_handle_from_uuid``),
  to drop malformed GUI updates and oversized uploads before viser handles them and hide its toasts (:mod:`.transport`);
- a GUI handle's current value without running its callbacks (``handle._impl.value``);
- a client-scoped gizmo's cross-client echo (``gizmo._impl_aux.sync_cb``), which costs CPU and reaches nobody;
- the share-URL tunnel, which any client can request: ``server.request_share_url`` is replaced by a no-op;
- the websocket server under viser (:class:`ServerDoor`, for :mod:`.limits`): each connection's message dispatch
  (``_handle_incoming_message``, wrapped to drop malformed messages), its outgoing backlog
  (``_client_state_from_id``), the raw connections (``_live_connections``, to refuse or drop a tab) and the
  websockets module viser serves with (:data:`ws_server`; :mod:`.limits` replaces the ``ServerProtocol`` it builds per
  connection: viser accepts 50 MiB frames and answers an over-long URL segment with HTTP 500), and viser's decoding of
  incoming messages (:func:`quiet_decoding`); a tab's GUI texts and the values it sends (:func:`reword`);
- outgoing messages: serialised once for every tab (:func:`share_serialization`), senders woken safely from any
  thread (``AsyncMessageBuffer``'s event: :func:`safe_wakeups`), windows sent with less work per tab (viser's
  ``_message_producer`` and ``AsyncMessageBuffer._window_loop``: :func:`lean_senders`).

:func:`check_viser` runs when the server is built: the installed viser must be the tested minor version
(:data:`TESTED`, pinned in ``pyproject.toml``) and every internal above must exist, else the app stops at start with
one line saying what to install, instead of serving blank pages. ``tests/system/test_security.py`` pins the
behaviour of each internal.
"""

from __future__ import annotations

import asyncio
import contextlib
import copy
import dataclasses
import functools
import threading
import uuid
import weakref
from collections.abc import Callable, Iterator
from typing import Any, cast, get_type_hints

import viser
from viser import _assignable_props_api, _messages
from viser.infra import _infra
from viser.infra._async_message_buffer import AsyncMessageBuffer

from tpm_viz.errors import TpmVizError
from tpm_viz.viserkit import wire
from tpm_viz.viserkit.wakeups import Wakeups, thread_safe_set
from tpm_viz.viserkit.windows import Frames, Tick, encoder, producer, window_loop
from tpm_viz.viserkit.wire import Malformed

ws_server = _infra.websockets.asyncio.server  # websockets' server, as viser imported it (not a tpm-viz dependency)

__all__ = ["TESTED", "ClientDoor", "IncompatibleViserError", "Malformed", "ServerDoor", "check_viser"]
__all__ += ["connection_request", "disable_share_url", "drop_gizmo_echo", "hook_handshakes", "lean_senders"]
__all__ += ["quiet_decoding", "reword"]
__all__ += ["safe_wakeups", "share_serialization", "thread_pool", "widget_uuid", "widget_value", "ws_server"]

TESTED = "1.1"
"""The viser minor version tpm-viz is tested with (``pyproject.toml`` pins ``viser>=1.1.1,<1.2``)."""

_SERVER_ATTRS = ("_thread_executor", "request_share_url", "_websock_server")
_WEBSOCK_ATTRS = ("_client_state_from_id", "_live_connections", "_background_event_loop", "_handle_incoming_message")
_GUI_METHODS = ("_handle_gui_updates", "_handle_file_transfer_start", "_handle_file_transfer_part")
_MESSAGES = ("GuiUpdateMessage", "FileTransferStartUpload", "FileTransferPart")


class IncompatibleViserError(TpmVizError):
    """The installed viser is not the version tpm-viz was tested with, or lacks an internal it relies on."""


def check_viser(version: str | None = None) -> None:
    """Raise :class:`IncompatibleViserError` (one line: what to install) unless viser is the tested minor version
    and has every internal this module uses. ``version`` defaults to the installed one (a test passes another)."""
    version = viser.__version__ if version is None else version
    fix = f"install the tested version: pip install 'viser>={TESTED}.1,<{wire.next_minor(TESTED)}'"
    if version.split(".")[:2] != TESTED.split("."):
        raise IncompatibleViserError(f"viser {version} is installed but tpm-viz is tested with viser {TESTED}.x; {fix}")
    missing = [f"ViserServer.{a}" for a in _SERVER_ATTRS if not wire.has_attr_or_init(viser.ViserServer, a)]
    missing += [f"GuiApi.{m}" for m in _GUI_METHODS if not hasattr(viser.GuiApi, m)]
    missing += [f"_messages.{m}" for m in _MESSAGES if not hasattr(_messages, m)]
    missing += [f"WebsockServer.{a}" for a in _WEBSOCK_ATTRS if not wire.has_attr_or_init(viser.infra.WebsockServer, a)]
    missing += [
        f"viser.infra._infra.{f}" for f in ("_message_producer", "_append_aligned_buffers") if not hasattr(_infra, f)
    ]
    missing += [] if hasattr(AsyncMessageBuffer, "_window_loop") else ["AsyncMessageBuffer._window_loop"]
    if not hasattr(ws_server, "ServerProtocol"):
        missing.append("websockets.asyncio.server.ServerProtocol")
    if missing:
        raise IncompatibleViserError(f"viser {version} lacks {', '.join(missing)}; {fix}")


def thread_pool(server: viser.ViserServer) -> Any:
    """The executor viser runs plain ``def`` callbacks in."""
    return server._thread_executor


def disable_share_url(server: viser.ViserServer) -> None:
    """Make ``server.request_share_url`` a no-op: no outside tunnel, whatever a client asks."""
    server.request_share_url = lambda *_args, **_kwargs: None  # type: ignore[method-assign]


def widget_value(handle: Any) -> Any:
    """The current value of a GUI handle as viser stores it (no callback runs, no cast)."""
    return handle._impl.value


def widget_uuid(handle: Any) -> str:
    """The uuid of a GUI handle (its ``label for=`` in the page: :mod:`.login` masks the token field by it)."""
    return str(handle._impl.uuid)


def drop_gizmo_echo(gizmo: Any) -> None:
    """Drop viser's cross-client echo of a client-scoped gizmo's drags: it queues two messages per drag event
    addressed to every client but this one, i.e. to nobody (~5 % of the server's CPU with 30 tabs dragging)."""
    aux = getattr(gizmo, "_impl_aux", None)
    if aux is not None and hasattr(aux, "sync_cb"):
        aux.sync_cb = None


class ClientDoor:
    """A tab's message handling, for :mod:`.transport`: look up widgets and uploads, replace three handlers."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self._conn = client._websock_connection
        self._gui = client.gui
        self.gui_update: wire.GuiUpdate = cast(wire.GuiUpdate, self._gui._handle_gui_updates)
        """viser's own handler of ``GuiUpdateMessage`` (call it to let a message through)."""
        self.upload_start: wire.Upload = cast(wire.Upload, self._gui._handle_file_transfer_start)
        self.upload_part: wire.Upload = cast(wire.Upload, self._gui._handle_file_transfer_part)

    def widget(self, uuid: str) -> Any:
        """The GUI handle with this uuid, or None."""
        return self._gui._gui_input_handle_from_uuid.get(uuid)

    def upload_state(self, transfer_uuid: str) -> Any:
        """viser's state of an upload in progress (``transferred_bytes``, ``total_bytes``), or None."""
        return self._gui._current_file_upload_states.get(transfer_uuid)

    def drop_upload(self, transfer_uuid: str) -> None:
        """Forget an upload in progress (its buffered parts are freed)."""
        self._gui._current_file_upload_states.pop(transfer_uuid, None)

    def end_upload(self, button: str, transfer: str, size: int | None = None) -> None:
        """Hide the page's upload toast (a success, whatever the app says); ``size``: free its button too."""
        self._conn.queue_message(_messages.RemoveNotificationMessage(f"upload-{transfer}"))
        if size is not None:
            self._conn.queue_message(_messages.FileTransferPartAck(button, transfer, size, size))

    def replace(self, gui_update: wire.GuiUpdate, upload_start: wire.Upload, upload_part: wire.Upload) -> None:
        """Route this tab's GUI updates and upload messages to the given handlers instead of viser's."""
        pairs: tuple[tuple[Any, Any, Any], ...] = (
            (_messages.GuiUpdateMessage, self.gui_update, gui_update),
            (_messages.FileTransferStartUpload, self.upload_start, upload_start),
            (_messages.FileTransferPart, self.upload_part, upload_part),
        )
        for message_type, old, new in pairs:
            self._conn.unregister_handler(message_type, old)
            self._conn.register_handler(message_type, new)


class ServerDoor:
    """The websocket server under a viser server, for :mod:`.limits` (see the module docstring)."""

    def __init__(self, server: viser.ViserServer) -> None:
        self._ws: Any = server._websock_server

    @property
    def loop(self) -> asyncio.AbstractEventLoop | None:
        """The server's event loop (None before it starts)."""
        return cast("asyncio.AbstractEventLoop | None", self._ws._background_event_loop)

    def on_connect(self, cb: Callable[[int], None], wrap: wire.Wrapper) -> None:
        """Run ``cb(client_id)`` on the event loop for every new websocket connection, before any of its messages
        is handled, and route that connection's messages through ``wrap(dispatch)``."""

        async def connected(conn: Any) -> None:
            conn._handle_incoming_message = wrap(conn._handle_incoming_message)
            cb(conn.client_id)

        self._ws.on_client_connect(connected)

    def on_disconnect(self, cb: Callable[[int], None]) -> None:
        """Run ``cb(client_id)`` on the event loop when a websocket connection ends, after emptying its outgoing
        buffer (what a tab that stopped reading left queued is freed now, not when its handles are collected)."""

        async def disconnected(conn: Any) -> None:
            buffer = conn._state.message_buffer
            with buffer.buffer_lock:
                buffer.message_from_id.clear()
                buffer.id_from_redundancy_key.clear()
                buffer.ids_from_entity_state_key.clear()
            cb(conn.client_id)

        self._ws.on_client_disconnect(disconnected)

    def wrap_server_dispatch(self, wrap: wire.Wrapper) -> None:
        """Route the messages handled at the server level (server-scoped widgets and scene) through ``wrap``."""
        self._ws._handle_incoming_message = wrap(self._ws._handle_incoming_message)

    def live(self) -> list[int]:
        """Ids of the open websocket connections."""
        return list(self._ws._live_connections)

    def backlog(self, client_id: int, count_bytes_below: int) -> tuple[int, int]:
        """``(messages, bytes)`` queued for this connection and not yet written to its socket; the bytes (payloads
        of files, text, arrays) are only added up when there are fewer than ``count_bytes_below`` messages."""
        state, connection = self._ws._client_state_from_id.get(client_id), self._ws._live_connections.get(client_id)
        if state is None or connection is None:
            return 0, 0
        messages = list(state.message_buffer.message_from_id.values())
        if len(messages) >= count_bytes_below:
            return len(messages), -1
        transport = connection.transport  # the frame being written (up to one window of 128 messages)
        written = transport.get_write_buffer_size() if transport is not None else 0
        return len(messages), written + sum(map(wire.message_bytes, messages))

    def notify(self, client_id: int, title: str, body: str) -> None:
        """Show a red notification in that tab (a connection not yet registered as a viser client included)."""
        state = self._ws._client_state_from_id.get(client_id)
        if state is None:
            return
        props = _messages.NotificationProps(
            title=title, body=body, loading=False, with_close_button=True, auto_close_seconds=None, color="red"
        )
        state.message_buffer.push(_messages.NotificationShowMessage(uuid=str(uuid.uuid4()), props=props))
        state.message_buffer.flush()

    def close(self, client_id: int, code: int, reason: str) -> None:
        """Close this connection with a closing handshake (from any thread)."""
        connection, loop = self._ws._live_connections.get(client_id), self.loop
        if connection is not None and loop is not None and not loop.is_closed():
            asyncio.run_coroutine_threadsafe(connection.close(code, reason), loop)

    def abort(self, client_id: int) -> None:
        """Drop this connection at once, without a closing handshake (a tab that does not read; from any thread)."""
        connection, loop = self._ws._live_connections.get(client_id), self.loop
        if connection is not None and loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(connection.transport.abort)


_DESERIALIZE = _messages.Message.deserialize.__func__  # type: ignore[attr-defined]
_SERIALIZE = _messages.Message.as_serializable_dict
_WINDOW_LOOP = AsyncMessageBuffer._window_loop  # viser's own (tests compare :mod:`.windows` with it)
_BIG_MESSAGE = 64 << 10
"""Incoming messages larger than this [bytes] must be upload parts (nothing else a browser sends is that big): a
big map or list in any other message would hold the event loop while it is decoded."""


class _UploadPart(_infra.msgspec.Struct, forbid_unknown_fields=True):
    """The one big message a browser sends, decoded strictly (fails at the first unexpected field)."""

    type: str
    source_component_uuid: str | None
    transfer_uuid: str
    part_index: int
    content: bytes


def quiet_decoding(on_garbage: Callable[[str], object]) -> None:
    """Make viser's decoding of incoming messages forgiving (process-wide, once): a message whose fields cannot be
    cast (``float("a")`` in a position, a missing field) becomes a :class:`Malformed` instead of an exception that
    closes the connection with a traceback in the log; bytes that are not a message at all (not msgpack, no known
    type) still close the connection, quietly (``on_garbage(text)`` is told)."""
    if getattr(_messages.Message, "_tpm_viz_quiet", False):
        return

    def deserialize(cls: Any, raw: bytes) -> Any:
        if len(raw) > _BIG_MESSAGE:
            try:
                big = _infra.msgspec.msgpack.decode(raw, type=_UploadPart)
            except _infra.msgspec.MsgspecError:
                big = None
            if big is None or big.type != "FileTransferPart":
                on_garbage(f"connection closed: a message of {len(raw)} bytes that is not an upload part")
                raise _infra.websockets.exceptions.ConnectionClosedError(None, None)
        try:
            return _DESERIALIZE(cls, raw)
        except (_infra.msgspec.DecodeError, KeyError, AttributeError) as exc:
            on_garbage(f"connection closed: not a viser message ({type(exc).__name__})")
            raise _infra.websockets.exceptions.ConnectionClosedError(None, None) from None
        except (ValueError, TypeError, IndexError) as exc:
            return Malformed(f"{type(exc).__name__}: {str(exc)[:120]}")

    _messages.Message.deserialize = classmethod(deserialize)  # type: ignore[method-assign,assignment]
    _messages.Message._tpm_viz_quiet = True  # type: ignore[attr-defined]


def safe_wakeups() -> None:
    """Wake viser's senders safely and once per loop turn (process-wide; before the server is built; :mod:`.wakeups`):
    each ``AsyncMessageBuffer`` sees its loop through one shared :class:`~.wakeups.Wakeups` (its self-pipe writes
    coalesced), and its message event's ``set`` is safe from the callback threads."""
    if getattr(AsyncMessageBuffer, "_tpm_viz_safe", False):
        return
    init = AsyncMessageBuffer.__init__
    shared: weakref.WeakKeyDictionary[Any, Wakeups] = weakref.WeakKeyDictionary()

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        loop = self.event_loop
        self.event_loop = shared.get(loop) or shared.setdefault(loop, Wakeups(loop))
        self.message_event.set = thread_safe_set(self.message_event, self.event_loop)

    AsyncMessageBuffer.__init__ = __init__  # type: ignore[method-assign]
    AsyncMessageBuffer._tpm_viz_safe = True  # type: ignore[attr-defined]


def lean_senders() -> None:
    """Send the tabs their windows with less work per tab (process-wide, once, before the server is built;
    :mod:`.windows`): a window of the shared buffer encoded once for every tab, one pause timer per buffer."""
    if getattr(AsyncMessageBuffer, "_tpm_viz_lean", False):
        return
    init, zstd = AsyncMessageBuffer.__init__, _infra.zstandard.ZstdCompressor(level=1)  # used on the loop only
    encode = encoder(_infra.msgspec.msgpack.encode, zstd.compress, _infra._append_aligned_buffers)

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        self.tick = Tick(self.event_loop, self.window_duration_sec)
        self.frames = Frames(encode) if self.persistent_messages else None  # only the shared buffer's are shared
        self.flush_event.set = self.tick.after(self.flush_event.set)  # viser sets it on the loop

    AsyncMessageBuffer.__init__ = __init__  # type: ignore[method-assign]
    AsyncMessageBuffer._window_loop = window_loop  # type: ignore[assignment,method-assign]
    _infra._message_producer = producer(encode)
    AsyncMessageBuffer._tpm_viz_lean = True  # type: ignore[attr-defined]


def share_serialization() -> None:
    """Make each outgoing message's wire dict once, not once per tab (process-wide): a broadcast update reaching 150
    tabs was serialised 150 times (a fifth of the server's time, ``bench_load.py --mode hall --profile``). Queued
    messages are not changed (viser fills them first; :func:`reword` changes copies, which a copied entry does not
    match: it holds its message's id); array buffers are shared, their placeholders renumbered per window."""
    if getattr(_messages.Message, "_tpm_viz_shared", False):
        return
    hints = functools.cache(get_type_hints)  # a handle's property types once per props class (a sixth of a storm)
    _assignable_props_api.AssignablePropsBase._prop_hints = property(lambda h: hints(type(h._impl.props)))  # type: ignore
    _messages.Message.as_serializable_dict = wire.shared_serializer(_SERIALIZE)  # type: ignore[method-assign]
    _messages.Message._tpm_viz_shared = True  # type: ignore[attr-defined]


# -- handshakes (ui/classroom.py: same-origin check, the browser's identity cookie) ----------------------------------
_HANDSHAKE_LOCK = threading.Lock()


@contextlib.contextmanager
def hook_handshakes(hook: wire.Handshake) -> Iterator[None]:
    """While a ``ViserServer`` is built inside this block, every HTTP request and websocket handshake of the server
    it starts goes through ``hook`` first (viser passes its page server to websockets' ``serve(process_request=)``;
    ``ViserServer()`` returns once ``serve`` was entered, so the block covers it)."""
    with _HANDSHAKE_LOCK:
        original = ws_server.serve
        ws_server.serve = wire.hooked_serve(original, hook)  # type: ignore[assignment]
        try:
            yield
        finally:
            ws_server.serve = original


def connection_request(server: viser.ViserServer, client_id: int) -> tuple[Any, Any] | None:
    """``(client address as classroom.Handshakes read it, headers)`` of a tab's websocket handshake, or None."""
    connection = server._websock_server._live_connections.get(client_id)
    if connection is None or connection.request is None:
        return None
    client, remote = getattr(connection, "tpm_viz_client", None), tuple(connection.remote_address or ("", 0))
    return (remote if client is None else (client, *remote[1:])), connection.request.headers


# -- words on the wire (ui/language.py) ------------------------------------------------------------------------------
_TEXTS = ("label", "hint", "content", "_markdown", "options", "_tab_labels", "title", "series", "axes")


def reword(client: viser.ClientHandle, out: Callable[[str, Any, str], Any], back: Callable[[str, Any], Any]) -> Any:
    """GUI texts go out as ``out(uuid, texts, kind)`` returns them (kind new, update, gone; texts: props in
    :data:`_TEXTS`, an option's ``value``), values in by ``back(uuid, value)``. -> ``(send(uuid, texts), headers)``"""
    conn, request = client._websock_connection, connection_request(client._viser_server, client.client_id)
    queue, dispatch = conn.queue_message, conn._handle_incoming_message

    def queue_message(message: Any) -> None:
        uuid_, props = getattr(message, "uuid", ""), getattr(message, "props", None)
        if isinstance(message, _messages.GuiUpdateMessage) and isinstance(message.updates, dict):
            message = copy.copy(message)
            message.updates = out(uuid_, message.updates, "update")
        elif isinstance(message, _messages.GuiRemoveMessage):
            out(uuid_, None, "gone")
        elif isinstance(message, _messages._CreateGuiComponentMessage) and dataclasses.is_dataclass(props):
            choice = {"value": getattr(message, "value", "")} if hasattr(props, "options") else {}
            texts = out(uuid_, {k: getattr(props, k) for k in _TEXTS if hasattr(props, k)} | choice, "new")
            message = copy.copy(message)
            message.__dict__.update({"value": texts.pop("value")} if choice else {})
            message.props = dataclasses.replace(cast(Any, props), **texts)
        queue(message)

    async def handle(client_id: Any, message: Any) -> None:
        u = getattr(message, "updates", None)  # a malformed one (an id that is a list) goes on: transport drops it
        if isinstance(message, _messages.GuiUpdateMessage) and isinstance(message.uuid, str) and isinstance(u, dict):
            message.updates = {**u, "value": back(message.uuid, u["value"])} if "value" in u else u
        await dispatch(client_id, message)

    conn.queue_message, conn._handle_incoming_message = queue_message, handle  # type: ignore[method-assign]
    return lambda uuid_, texts: queue_message(_messages.GuiUpdateMessage(uuid_, texts)), request and request[1]
