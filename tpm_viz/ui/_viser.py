"""The one door to viser's private internals (viser 1.1.x). No other module of tpm-viz touches a private viser name.

tpm-viz needs five things viser's public API does not offer:

- the server's callback thread pool (``server._thread_executor``), to guard every callback (:mod:`.guard`);
- a tab's message handlers (``client._websock_connection``, ``gui._handle_gui_updates``,
  ``gui._handle_file_transfer_start/part``, ``gui._current_file_upload_states``, ``gui._gui_input_handle_from_uuid``),
  to drop malformed GUI updates and oversized uploads before viser handles them (:mod:`.transport`);
- a GUI handle's current value without running its callbacks (``handle._impl.value``);
- a client-scoped gizmo's cross-client echo (``gizmo._impl_aux.sync_cb``), which costs CPU and reaches nobody;
- the share-URL tunnel, which any client can request: ``server.request_share_url`` is replaced by a no-op.

:func:`check_viser` runs when the server is built: the installed viser must be the tested minor version
(:data:`TESTED`, pinned in ``pyproject.toml``) and every internal above must exist, else the app stops at start with
one line saying what to install, instead of serving blank pages. ``tests/system/test_security.py`` pins the
behaviour of each internal.
"""

from __future__ import annotations

import inspect
from collections.abc import Awaitable, Callable
from typing import Any, cast

import viser
from viser import _messages

from tpm_viz.errors import TpmVizError

__all__ = [
    "TESTED",
    "ClientDoor",
    "IncompatibleViserError",
    "check_viser",
    "disable_share_url",
    "drop_gizmo_echo",
    "thread_pool",
    "widget_value",
]

TESTED = "1.1"
"""The viser minor version tpm-viz is tested with (``pyproject.toml`` pins ``viser>=1.1.1,<1.2``)."""

_SERVER_ATTRS = ("_thread_executor", "request_share_url")
_GUI_METHODS = ("_handle_gui_updates", "_handle_file_transfer_start", "_handle_file_transfer_part")
_MESSAGES = ("GuiUpdateMessage", "FileTransferStartUpload", "FileTransferPart")


class IncompatibleViserError(TpmVizError):
    """The installed viser is not the version tpm-viz was tested with, or lacks an internal it relies on."""


def check_viser(version: str | None = None) -> None:
    """Raise :class:`IncompatibleViserError` (one line: what to install) unless viser is the tested minor version
    and has every internal this module uses. ``version`` defaults to the installed one (a test passes another)."""
    version = viser.__version__ if version is None else version
    fix = f"install the tested version: pip install 'viser>={TESTED}.1,<{_next_minor(TESTED)}'"
    if version.split(".")[:2] != TESTED.split("."):
        raise IncompatibleViserError(f"viser {version} is installed but tpm-viz is tested with viser {TESTED}.x; {fix}")
    missing = [f"ViserServer.{a}" for a in _SERVER_ATTRS if not _has_attr_or_init(viser.ViserServer, a)]
    missing += [f"GuiApi.{m}" for m in _GUI_METHODS if not hasattr(viser.GuiApi, m)]
    missing += [f"_messages.{m}" for m in _MESSAGES if not hasattr(_messages, m)]
    if missing:
        raise IncompatibleViserError(f"viser {version} lacks {', '.join(missing)}; {fix}")


def _next_minor(minor: str) -> str:
    major, m = minor.split(".")
    return f"{major}.{int(m) + 1}"


def _has_attr_or_init(cls: type, name: str) -> bool:
    """Whether ``cls`` has ``name`` or assigns ``self.name`` in its ``__init__`` (instance attributes)."""
    if hasattr(cls, name):
        return True
    try:
        return f"self.{name}" in inspect.getsource(cls.__init__)
    except (OSError, TypeError):
        return False


def thread_pool(server: viser.ViserServer) -> Any:
    """The executor viser runs plain ``def`` callbacks in."""
    return server._thread_executor


def disable_share_url(server: viser.ViserServer) -> None:
    """Make ``server.request_share_url`` a no-op: no outside tunnel, whatever a client asks."""

    def _no_share_url(*_args: object, **_kwargs: object) -> None:
        return None

    server.request_share_url = _no_share_url  # type: ignore[method-assign]


def widget_value(handle: Any) -> Any:
    """The current value of a GUI handle as viser stores it (no callback runs, no cast)."""
    return handle._impl.value


def drop_gizmo_echo(gizmo: Any) -> None:
    """Drop viser's cross-client echo of a client-scoped gizmo's drags: it queues two messages per drag event
    addressed to every client but this one, i.e. to nobody (~5 % of the server's CPU with 30 tabs dragging)."""
    aux = getattr(gizmo, "_impl_aux", None)
    if aux is not None and hasattr(aux, "sync_cb"):
        aux.sync_cb = None


GuiUpdate = Callable[[Any, Any], Awaitable[None]]
Upload = Callable[[Any, Any], None]


class ClientDoor:
    """A tab's message handling, for :mod:`.transport`: look up widgets and uploads, replace three handlers."""

    def __init__(self, client: viser.ClientHandle) -> None:
        self._conn = client._websock_connection
        self._gui = client.gui
        self.gui_update: GuiUpdate = cast(GuiUpdate, self._gui._handle_gui_updates)
        """viser's own handler of ``GuiUpdateMessage`` (call it to let a message through)."""
        self.upload_start: Upload = cast(Upload, self._gui._handle_file_transfer_start)
        self.upload_part: Upload = cast(Upload, self._gui._handle_file_transfer_part)

    def widget(self, uuid: str) -> Any:
        """The GUI handle with this uuid, or None."""
        return self._gui._gui_input_handle_from_uuid.get(uuid)

    def upload_state(self, transfer_uuid: str) -> Any:
        """viser's state of an upload in progress (``transferred_bytes``, ``total_bytes``), or None."""
        return self._gui._current_file_upload_states.get(transfer_uuid)

    def drop_upload(self, transfer_uuid: str) -> None:
        """Forget an upload in progress (its buffered parts are freed)."""
        self._gui._current_file_upload_states.pop(transfer_uuid, None)

    def replace(self, gui_update: GuiUpdate, upload_start: Upload, upload_part: Upload) -> None:
        """Route this tab's GUI updates and upload messages to the given handlers instead of viser's."""
        pairs: tuple[tuple[Any, Any, Any], ...] = (
            (_messages.GuiUpdateMessage, self.gui_update, gui_update),
            (_messages.FileTransferStartUpload, self.upload_start, upload_start),
            (_messages.FileTransferPart, self.upload_part, upload_part),
        )
        for message_type, old, new in pairs:
            self._conn.unregister_handler(message_type, old)
            self._conn.register_handler(message_type, new)
