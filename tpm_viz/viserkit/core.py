"""The one door to viser's private internals on one server (viser 1.1.x); :mod:`.patches` holds the few patches
that act through a class, :mod:`.adapter` installs both.

tpm-viz needs these things viser's public API does not offer:

- the server's callback thread pool (``server._thread_executor``), to guard every callback (:mod:`.guard`);
- a tab's message handlers (``client._websock_connection``, ``gui._handle_gui_updates``,
  ``gui._handle_file_transfer_start/part``, ``gui._current_file_upload_states``, ``gui._gui_input_handle_from_uuid``),
  to drop malformed GUI updates and oversized uploads before viser handles them and hide its toasts (:mod:`.transport`);
- a GUI handle's current value without running its callbacks (``handle._impl.value``);
- a client-scoped gizmo's cross-client echo (``gizmo._impl_aux.sync_cb``), which costs CPU and reaches nobody;
- the share-URL tunnel, which any client can request: ``server.request_share_url`` is replaced by a no-op;
- the websocket server under viser (:class:`ServerDoor`, for :mod:`.limits` and :mod:`.adapter`): each connection's
  message dispatch (``_handle_incoming_message``, wrapped to drop malformed messages), its message buffers (the
  shared one and each tab's: :mod:`.patches` puts the senders' patches on them), its outgoing backlog
  (``_client_state_from_id``), the raw connections (``_live_connections``, to refuse or drop a tab);
- a tab's camera pointed in one step (:func:`point_camera`: viser's two setters compute its orientation twice and
  ask ``np.allclose`` four times, a tenth of a reconnect storm's CPU);
- a tab's handshake headers (:func:`client_request`), a tab's label (:func:`relabel_tab`: viser's ``GuiTabHandle`` has
  no setter) and whether a handle was removed with its container (:func:`removed`), for :mod:`tpm_viz.ui.worded`.

:func:`check_viser` runs when the server is built: the installed viser must be the tested minor version
(:data:`TESTED`, pinned in ``pyproject.toml``) and every internal above must exist, else the app stops at start with
one line saying what to install, instead of serving blank pages. ``tests/viserkit/`` shows what each patch is for.
"""

from __future__ import annotations

import asyncio
import time
import uuid
from collections.abc import Callable
from typing import Any, cast

import numpy as np
import viser
import websockets
from viser import _messages
from viser.infra import _infra
from viser.infra._async_message_buffer import AsyncMessageBuffer

from tpm_viz.core.errors import TpmVizError
from tpm_viz.viserkit import casts, wire
from tpm_viz.viserkit.patches import skipped
from tpm_viz.viserkit.wire import Malformed

ws_server = _infra.websockets.asyncio.server  # websockets' server, as viser imported it (not a tpm-viz dependency)

__all__ = [
    "TESTED",
    "TESTED_WEBSOCKETS",
    "ClientDoor",
    "IncompatibleViserError",
    "Malformed",
    "ServerDoor",
    "check_viser",
]
__all__ += ["client_request", "connection_request", "disable_share_url", "drop_gizmo_echo", "enable_share_url"]
__all__ += ["point_camera", "relabel_tab", "removed", "thread_pool", "widget_uuid", "widget_value", "ws_server"]

TESTED = "1.1"
"""The viser minor version tpm-viz is tested with (``pyproject.toml`` pins ``viser>=1.1.1,<1.2``)."""

TESTED_WEBSOCKETS = ("15", "16")
"""The websockets major versions tpm-viz is tested with (``pyproject.toml`` pins ``websockets>=15,<17``): viserkit
replaces its ``ServerProtocol`` for the whole process."""

_SERVER_ATTRS = ("_thread_executor", "request_share_url", "_websock_server")
_WEBSOCK_ATTRS: tuple[str, ...] = (
    "_client_state_from_id",
    "_live_connections",
    "_background_event_loop",
    "_handle_incoming_message",
)
_WEBSOCK_ATTRS += ("_client_connect_cb", "_client_disconnect_cb")
_GUI_METHODS = ("_handle_gui_updates", "_handle_file_transfer_start", "_handle_file_transfer_part")
_MESSAGES: tuple[str, ...] = ("GuiUpdateMessage", "FileTransferStartUpload", "FileTransferPart")
_MESSAGES += ("SetCameraPositionMessage", "SetCameraLookAtMessage")


class IncompatibleViserError(TpmVizError):
    """The installed viser is not the version tpm-viz was tested with, or lacks an internal it relies on."""


def check_viser(version: str | None = None, websockets_version: str | None = None) -> None:
    """Raise :class:`IncompatibleViserError` (one line: what to install) unless viser is the tested minor version,
    websockets a tested major, and viser has every internal this module uses. The versions default to the installed
    ones (a test passes others)."""
    version = viser.__version__ if version is None else version
    ws_version = websockets.__version__ if websockets_version is None else websockets_version
    fix = f"install the tested version: pip install 'viser>={TESTED}.1,<{wire.next_minor(TESTED)}'"
    if version.split(".")[:2] != TESTED.split("."):
        raise IncompatibleViserError(f"viser {version} is installed but tpm-viz is tested with viser {TESTED}.x; {fix}")
    if ws_version.split(".")[0] not in TESTED_WEBSOCKETS:
        low, high = TESTED_WEBSOCKETS[0], int(TESTED_WEBSOCKETS[-1]) + 1
        raise IncompatibleViserError(
            f"websockets {ws_version} is installed but tpm-viz is tested with websockets "
            f"{'/'.join(TESTED_WEBSOCKETS)}.x; install a tested version: pip install 'websockets>={low},<{high}'"
        )
    missing = [f"ViserServer.{a}" for a in _SERVER_ATTRS if not wire.has_attr_or_init(viser.ViserServer, a)]
    missing += [f"GuiApi.{m}" for m in _GUI_METHODS if not hasattr(viser.GuiApi, m)]
    missing += [f"_messages.{m}" for m in _MESSAGES if not hasattr(_messages, m)]
    missing += [f"WebsockServer.{a}" for a in _WEBSOCK_ATTRS if not wire.has_attr_or_init(viser.infra.WebsockServer, a)]
    missing += [
        f"viser.infra._infra.{f}"
        for f in ("_message_producer", "_message_consumer", "_append_aligned_buffers")
        if not hasattr(_infra, f)
    ]
    missing += [] if hasattr(AsyncMessageBuffer, "_window_loop") else ["AsyncMessageBuffer._window_loop"]
    missing += casts.missing()
    missing += [] if hasattr(viser.CameraHandle, "_update_wxyz") else ["CameraHandle._update_wxyz"]
    if not hasattr(ws_server, "ServerProtocol"):
        missing.append("websockets.asyncio.server.ServerProtocol")
    if missing:
        raise IncompatibleViserError(f"viser {version} lacks {', '.join(missing)}; {fix}")


def thread_pool(server: viser.ViserServer) -> Any:
    """The executor viser runs plain ``def`` callbacks in."""
    return server._thread_executor


def disable_share_url(server: viser.ViserServer) -> None:
    """Make ``server.request_share_url`` a no-op: no outside tunnel, whatever a client asks (this server only)."""
    server.request_share_url = lambda *_args, **_kwargs: None  # type: ignore[method-assign]


def enable_share_url(server: viser.ViserServer) -> None:
    """Undo :func:`disable_share_url`: viser's own ``request_share_url`` again."""
    server.__dict__.pop("request_share_url", None)


def widget_value(handle: Any) -> Any:
    """The current value of a GUI handle as viser stores it (no callback runs, no cast)."""
    return handle._impl.value


def widget_uuid(handle: Any) -> str:
    """The uuid of a GUI handle (its ``label for=`` in the page: :mod:`.login` masks the token field by it)."""
    return str(handle._impl.uuid)


def drop_gizmo_echo(gizmo: Any) -> None:
    """Drop viser's cross-client echo of a client-scoped gizmo's drags: it queues two messages per drag event
    addressed to every client but this one, i.e. to nobody (~5 % of the server's CPU with 30 tabs dragging)."""
    owner = getattr(getattr(getattr(gizmo, "_impl", None), "api", None), "_owner", None)
    if skipped(owner, "gizmo_echo"):
        return
    aux = getattr(gizmo, "_impl_aux", None)
    if aux is not None and hasattr(aux, "sync_cb"):
        aux.sync_cb = None


class ClientDoor:
    """A tab's message handling, for :mod:`.transport`: look up widgets and uploads, replace three handlers."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self._conn = client._websock_connection
        self._gui = client.gui
        self._client_id = client.client_id
        self.server: viser.ViserServer = client._viser_server
        """The tab's server (its upload budget: :func:`~.uploads.budget_of`)."""
        self.gui_update: wire.GuiUpdate = cast(wire.GuiUpdate, self._gui._handle_gui_updates)
        """viser's own handler of ``GuiUpdateMessage`` (call it to let a message through)."""
        self.upload_start: wire.Upload = cast(wire.Upload, self._gui._handle_file_transfer_start)
        self.upload_part: wire.Upload = cast(wire.Upload, self._gui._handle_file_transfer_part)

    def address(self) -> str:
        """The client address of the tab (as :class:`~tpm_viz.ui.classroom.Handshakes` read it), or ``""``."""
        request = connection_request(self.server, self._client_id)
        if request is None:
            return ""
        address = request[0]
        return str(address[0] if isinstance(address, tuple) and address else address)

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
        self.removers: list[Callable[[], None]] = []
        """Undo the callbacks added by :meth:`on_connect` and :meth:`on_disconnect`."""

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
        self.removers.append(lambda: self._forget(self._ws._client_connect_cb, connected))

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
        self.removers.append(lambda: self._forget(self._ws._client_disconnect_cb, disconnected))

    def wrap_server_dispatch(self, wrap: wire.Wrapper) -> None:
        """Route the messages handled at the server level (server-scoped widgets and scene) through ``wrap``."""
        self._ws._handle_incoming_message = wrap(self._ws._handle_incoming_message)

    def unwrap_server_dispatch(self) -> None:
        """Undo :meth:`wrap_server_dispatch` (viser's own dispatch again)."""
        self._ws.__dict__.pop("_handle_incoming_message", None)

    def shared_buffer(self) -> Any:
        """The message buffer every tab is sent (``AsyncMessageBuffer``, persistent)."""
        return self._ws._broadcast_buffer

    def on_new_buffer(self, cb: Callable[[Any], None]) -> Callable[[], None]:
        """Run ``cb(buffer)`` on the event loop with each new connection's own message buffer, before any other
        connect callback (viser's included) and before its sender starts. -> a function that stops it."""

        async def connected(conn: Any) -> None:
            cb(conn._state.message_buffer)

        self._ws._client_connect_cb.insert(0, connected)
        return lambda: self._forget(self._ws._client_connect_cb, connected)

    @staticmethod
    def _forget(callbacks: list[Any], cb: Any) -> None:
        if cb in callbacks:
            callbacks.remove(cb)

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


def connection_request(server: viser.ViserServer, client_id: int) -> tuple[Any, Any] | None:
    """``(client address as classroom.Handshakes read it, headers)`` of a tab's websocket handshake, or None."""
    connection = server._websock_server._live_connections.get(client_id)
    if connection is None or connection.request is None:
        return None
    client, remote = getattr(connection, "tpm_viz_client", None), tuple(connection.remote_address or ("", 0))
    return (remote if client is None else (client, *remote[1:])), connection.request.headers


# -- a tab's own words (ui/worded.py) --------------------------------------------------------------------------------
def client_request(client: viser.ClientHandle) -> tuple[Any, Any] | None:
    """:func:`connection_request` of a tab's own connection (its ``Accept-Language``: the tab's first language)."""
    return connection_request(client._viser_server, client.client_id)


def point_camera(camera: viser.CameraHandle, position: Any, look_at: Any) -> None:
    """``camera.position = position`` then ``camera.look_at = look_at`` (the same state and the same final messages,
    [m]) with the orientation computed once. Raises ValueError for a non-finite point or ``position == look_at``
    (the camera left as it was)."""
    state = camera._state
    new_position = np.asarray(position, dtype=np.float64)
    new_look_at = np.asarray(look_at, dtype=np.float64)
    if not (np.all(np.isfinite(new_position)) and np.all(np.isfinite(new_look_at))):
        raise ValueError(f"Camera position and look_at must be finite, got {new_position} and {new_look_at}.")
    place, aim = casts.cast_vector(new_position, 3), casts.cast_vector(new_look_at, 3)
    if casts.close(place, state.position.tolist()) and casts.close(aim, state.look_at.tolist()):
        return
    before = (state.position, state.look_at, state.update_timestamp)
    state.position, state.look_at, state.update_timestamp = new_position, new_look_at, time.time()
    try:
        camera._update_wxyz()
    except Exception:
        state.position, state.look_at, state.update_timestamp = before
        raise
    queue = state.client._websock_connection.queue_message
    queue(_messages.SetCameraPositionMessage(cast(Any, place)))
    queue(_messages.SetCameraLookAtMessage(cast(Any, aim)))


def relabel_tab(tab: Any, label: str) -> None:
    """Show ``label`` as the name of a tab of a tab group or panel (viser's ``GuiTabHandle`` has no label setter)."""
    tab._label = label
    tab._parent._rebuild_tab_props()


def removed(handle: Any) -> bool:
    """Whether a GUI handle (a tab's too) was removed, by itself or with its container."""
    return bool(getattr(getattr(handle, "_impl", handle), "removed", False))
