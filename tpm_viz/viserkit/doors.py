"""The two doors to one server's message handling under viser's public API (viser 1.1.x), for :mod:`.transport`,
:mod:`.limits` and :mod:`.adapter`: :class:`ClientDoor` (a tab's handlers of GUI updates and uploads, its widgets
by uuid, its uploads in progress) and :class:`ServerDoor` (the websocket server: each connection's dispatch, the
message buffers, the outgoing backlog, the raw connections). :func:`~.core.check_viser` checks at start that every
internal they use exists."""

from __future__ import annotations

import asyncio
import uuid
from collections.abc import Callable
from typing import Any, cast

import viser
from viser import _messages

from tpm_viz.viserkit import wire

__all__ = ["ClientDoor", "ServerDoor"]


def connection_request(server: viser.ViserServer, client_id: int) -> tuple[Any, Any] | None:
    """``(client address as classroom.Handshakes read it, headers)`` of a tab's websocket handshake, or None."""
    connection = server._websock_server._live_connections.get(client_id)
    if connection is None or connection.request is None:
        return None
    client, remote = getattr(connection, "tpm_viz_client", None), tuple(connection.remote_address or ("", 0))
    return (remote if client is None else (client, *remote[1:])), connection.request.headers


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

    def address(self, client_id: int) -> str:
        """The source address of a connection: as the handshake hook read it (``tpm_viz_client``, through a trusted
        proxy), else its peer's; ``""`` for a connection that is gone."""
        connection = self._ws._live_connections.get(client_id)
        if connection is None:
            return ""
        client = getattr(connection, "tpm_viz_client", None)
        remote = connection.remote_address
        return str(client) if client is not None else str(remote[0]) if remote else ""

    def header(self, client_id: int, name: str) -> str | None:
        """A header of a connection's websocket handshake (None: no such header, or the connection is gone)."""
        connection = self._ws._live_connections.get(client_id)
        request = None if connection is None else connection.request
        return None if request is None else cast("str | None", request.headers.get(name))

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
