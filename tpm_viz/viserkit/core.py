"""The one door to viser's private internals on one server (viser 1.1.x); :mod:`.patches` holds the few patches
that act through a class, :mod:`.adapter` installs both.

tpm-viz needs these things viser's public API does not offer:

- the server's callback thread pool (``server._thread_executor``), to guard every callback (:mod:`.guard`);
- a tab's message handlers (``client._websock_connection``, ``gui._handle_gui_updates``,
  ``gui._handle_file_transfer_start/part``, ``gui._current_file_upload_states``, ``gui._gui_input_handle_from_uuid``),
  to drop malformed GUI updates and oversized uploads before viser handles them and hide its toasts (:mod:`.transport`,
  through :class:`~.doors.ClientDoor`);
- a GUI handle's current value without running its callbacks (``handle._impl.value``);
- a client-scoped gizmo's cross-client echo (``gizmo._impl_aux.sync_cb``), which costs CPU and reaches nobody;
- the share-URL tunnel, which any client can request: ``server.request_share_url`` is replaced by a no-op;
- the websocket server under viser (:class:`~.doors.ServerDoor`, for :mod:`.limits` and :mod:`.adapter`): each
  connection's message dispatch (``_handle_incoming_message``, wrapped to drop malformed messages), its message
  buffers (the shared one and each tab's: :mod:`.patches` puts the senders' patches on them), its outgoing backlog
  (``_client_state_from_id``), the raw connections (``_live_connections``, to refuse or drop a tab);
- a tab's camera pointed in one step (:func:`point_camera`: viser's two setters compute its orientation twice and
  ask ``np.allclose`` four times, a tenth of a reconnect storm's CPU);
- a tab's handshake headers (:func:`client_request`), a tab's label (:func:`relabel_tab`: viser's ``GuiTabHandle`` has
  no setter) and whether a handle was removed with its container (:func:`removed`), for :mod:`tpm_viz.ui.worded`;
- the id by which viser's page names a tab's button (:func:`tab_id`), for a style sheet of :mod:`tpm_viz.ui.panels`.

:func:`check_viser` runs when the server is built: the installed viser must be the tested minor version
(:data:`TESTED`, pinned in ``pyproject.toml``) and every internal above must exist, else the app stops at start with
one line saying what to install, instead of serving blank pages. ``tests/viserkit/`` shows what each patch is for.
The two doors live in :mod:`.doors` (re-exported here).
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any, cast

import numpy as np
import viser
import websockets
from viser import _messages
from viser.infra import _infra
from viser.infra._async_message_buffer import AsyncMessageBuffer

from tpm_viz.core.errors import TpmVizError
from tpm_viz.viserkit import casts, wire
from tpm_viz.viserkit.doors import ClientDoor, ServerDoor, connection_request
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
__all__ += ["point_camera", "relabel_tab", "removed", "tab_id", "thread_pool", "widget_uuid", "widget_value"]
__all__ += ["ws_server"]

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
_TAB_FIELDS = ("_id", "_label", "_parent")  # tab_id, relabel_tab


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
    tab_fields = (
        {f.name for f in dataclasses.fields(viser.GuiTabHandle)}
        if dataclasses.is_dataclass(viser.GuiTabHandle)
        else set()
    )
    missing += [f"GuiTabHandle.{f}" for f in _TAB_FIELDS if f not in tab_fields]
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


def tab_id(tab: Any) -> str | None:
    """The id of a tab of a tab group or panel (a ``viser.GuiTabHandle``, or an object that holds one as ``handle``:
    :class:`tpm_viz.ui.worded.Tab`), which viser's page names the tab's button by (``data-dock-tab="<id>"`` on a
    wide screen, ``id="…-tab-<id>"`` on a phone's tab strip); None for anything else (viser's public API has no name
    for it)."""
    handle = tab if isinstance(tab, viser.GuiTabHandle) else getattr(tab, "handle", None)
    uuid = handle._id if isinstance(handle, viser.GuiTabHandle) else None
    return uuid if isinstance(uuid, str) else None


def drop_gizmo_echo(gizmo: Any) -> None:
    """Drop viser's cross-client echo of a client-scoped gizmo's drags: it queues two messages per drag event
    addressed to every client but this one, i.e. to nobody (~5 % of the server's CPU with 30 tabs dragging)."""
    owner = getattr(getattr(getattr(gizmo, "_impl", None), "api", None), "_owner", None)
    if skipped(owner, "gizmo_echo"):
        return
    aux = getattr(gizmo, "_impl_aux", None)
    if aux is not None and hasattr(aux, "sync_cb"):
        aux.sync_cb = None


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
