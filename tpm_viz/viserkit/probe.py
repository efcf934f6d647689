"""Small public functions over viser's internals for tests and benchmarks (the app does not use them), so that no
private viser or websockets name is written outside :mod:`tpm_viz.viserkit`.

- :data:`messages`: viser's message classes (its ``_messages`` module), to build what a browser would send;
  :data:`props_api`, the module of its handles' property writes;
- message buffers as viser makes them (:func:`message_buffer`) or with tpm-viz's senders on them
  (:func:`lean_buffer`), viser's own window loop and serialisation (:data:`VISER_WINDOW_LOOP`,
  :data:`VISER_SERIALIZE`) and the shared one (:func:`shared_serialize`), its buffer alignment (:func:`align`);
- a widget's uuid, a value arriving without its callbacks (:func:`arrive`), a tab's uploads in progress, the
  connections a server still holds, viser's tunnel class, whether a tab's sending is viser's own
  (:func:`outgoing_replaced`);
- the bytes an image node sends (:func:`image_bytes`), the length of a recording (:func:`recorded_seconds`).
"""

from __future__ import annotations

import asyncio
from typing import Any

import viser
import viser._tunnel
from viser import _assignable_props_api, _messages
from viser.infra import _infra
from viser.infra._async_message_buffer import AsyncMessageBuffer

from tpm_viz.viserkit import patches, wire
from tpm_viz.viserkit.core import thread_pool, widget_uuid, widget_value
from tpm_viz.viserkit.doors import ServerDoor

__all__ = ["VISER_SERIALIZE", "VISER_WINDOW_LOOP", "align", "arrive", "connection_states", "lean_buffer"]
__all__ += ["message_buffer", "messages", "shared_serialize", "tunnel_class", "upload_states", "widget_uuid"]
__all__ += ["event_loop", "gizmo_echoes", "share_tunnel", "shared_buffer", "thread_pool", "wake_safely"]
__all__ += ["gui_inputs", "image_bytes", "outgoing_replaced", "props_api", "recorded_seconds", "widget_value"]

messages = _messages
"""viser's message classes (``viser._messages``)."""
props_api = _assignable_props_api
"""viser's module of handle properties (``viser._assignable_props_api``): the names its casts look up."""
VISER_WINDOW_LOOP = AsyncMessageBuffer._window_loop
"""viser's own window loop (``AsyncMessageBuffer._window_loop``), to compare :func:`~.windows.window_loop` with."""
VISER_SERIALIZE = patches.SERIALIZE
"""viser's own ``Message.as_serializable_dict``."""
shared_serialize = wire.shared_serializer(VISER_SERIALIZE)
"""``shared_serialize(message, buffers)``: a message's wire dict, made once for every tab (what tpm-viz sends)."""
align = _infra._append_aligned_buffers
"""viser's alignment of array buffers in a frame."""


def message_buffer(loop: asyncio.AbstractEventLoop | Any, persistent: bool) -> Any:
    """A message buffer as viser makes one (``persistent``: the one shared by every tab)."""
    return AsyncMessageBuffer(loop, persistent_messages=persistent)


def lean_buffer(loop: asyncio.AbstractEventLoop | Any, persistent: bool, wakeups: bool = True) -> Any:
    """A message buffer with tpm-viz's senders on it, as :func:`~.adapter.install` puts them (``wakeups``: woken
    through the loop's one :class:`~.wakeups.Wakeups`)."""
    buffer = message_buffer(loop, persistent)
    patches.upgrade_buffer(buffer, wakeups, True, patches.lean_encoder(True))
    return buffer


def wake_safely(buffer: Any) -> None:
    """Put only the safe wake-ups on a buffer of viser's."""
    patches.upgrade_buffer(buffer, True, False, None)


def arrive(handle: Any, value: Any) -> None:
    """Store ``value`` in a GUI handle as viser does when it arrives from the page, before its callbacks run."""
    handle._impl.value = value


def outgoing_replaced(client: viser.ClientHandle) -> bool:
    """Whether a tab's connection sends through a ``queue_message`` of its own instead of viser's."""
    return "queue_message" in vars(client._websock_connection)


def upload_states(client: viser.ClientHandle) -> dict[str, Any]:
    """viser's uploads in progress of a tab (transfer uuid -> state), the same dict viser keeps."""
    states: dict[str, Any] = client.gui._current_file_upload_states
    return states


def connection_states(server: viser.ViserServer) -> dict[int, Any]:
    """The connections viser still keeps state for (client id -> state), the same dict viser keeps."""
    states: dict[int, Any] = server._websock_server._client_state_from_id
    return states


def event_loop(server: viser.ViserServer) -> asyncio.AbstractEventLoop:
    """The event loop a server's websocket server runs on."""
    loop = ServerDoor(server).loop
    assert loop is not None, "the server has not started"
    return loop


def shared_buffer(server: viser.ViserServer) -> Any:
    """The message buffer every tab of ``server`` is sent."""
    return ServerDoor(server).shared_buffer()


def gizmo_echoes(gizmo: Any) -> bool:
    """Whether a transform control still echoes its drags to the other tabs (viser's ``sync_cb``)."""
    aux = getattr(gizmo, "_impl_aux", None)
    return getattr(aux, "sync_cb", None) is not None


def share_tunnel(server: viser.ViserServer) -> Any:
    """The share-URL tunnel a server opened (None: none)."""
    return server._share_tunnel


def image_bytes(image: viser.ImageHandle) -> bytes:
    """The encoded image (PNG or JPEG) a scene image node sends the page (viser keeps it in its ``_data`` prop)."""
    return bytes(image._data)


def recorded_seconds(serializer: Any) -> float:
    """How long a recording of viser's ``StateSerializer`` lasts so far [s] (the sleeps inserted; its ``_time``)."""
    return float(serializer._time)


def tunnel_class() -> type:
    """viser's share-URL tunnel (a test replaces its ``__init__`` to see whether one is opened)."""
    return viser._tunnel.ViserTunnel


def gui_inputs(gui: Any) -> list[tuple[tuple[str, ...], Any]]:
    """Every input of a tab's GUI (``client.gui``): ``(tabs, handle)``, ``tabs`` the labels of the tabs the input
    sits in, outermost first (``()`` in the panel's root or a floating panel). Inputs in folders and forms are in
    their tab; an input that no walk from the root reaches is listed with ``("?",)`` (none should be)."""
    found: dict[str, tuple[tuple[str, ...], Any]] = {}

    def walk(container: Any, tabs: tuple[str, ...]) -> None:
        for child in list(getattr(container, "_children", {}).values()):
            for tab in list(getattr(child, "_tab_handles", ())):
                walk(tab, (*tabs, str(tab._label)))
            if getattr(child, "_children", None) is not None:
                walk(child, tabs)
            impl = getattr(child, "_impl", None)
            if impl is not None and impl.uuid in gui._gui_input_handle_from_uuid:
                found[impl.uuid] = (tabs, child)

    walk(gui._container_handle_from_uuid["root"], ())
    for container in list(gui._container_handle_from_uuid.values()):  # floating panels: their own roots
        if getattr(container, "_parent", None) is None and getattr(container, "_impl", None) is None:
            walk(container, ())
    for uuid, handle in list(gui._gui_input_handle_from_uuid.items()):
        found.setdefault(uuid, (("?",), handle))
    return list(found.values())
