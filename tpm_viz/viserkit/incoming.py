"""What a browser sends, received on a registered server's event loop (the ``frames`` and ``decoding`` patches,
``PATCHES.md`` entries 8 and 9): a smaller frame limit and no HTTP 500 (:class:`GuardedProtocol`, in place of
websockets' ``ServerProtocol``), and messages decoded quietly (:func:`message_consumer`, in place of viser's
``_message_consumer``; :func:`decode_quietly`). :mod:`.patches` puts both on the classes and takes them off again;
each acts for the event loops in :data:`LOOPS` only (:func:`~.patches.register`) and is websockets' or viser's own
anywhere else.
"""

from __future__ import annotations

import asyncio
import dataclasses
import errno
import http
import weakref
from collections.abc import Callable
from typing import Any

from viser.infra import _infra

from tpm_viz.viserkit.wire import Malformed

__all__ = ["BIG_MESSAGE", "LOOPS", "GuardedProtocol", "LoopPatches", "decode_quietly", "message_consumer"]

ws_server = _infra.websockets.asyncio.server  # websockets' server, as viser imported it (not a tpm-viz dependency)
_VISER_CONSUMER = _infra._message_consumer

BIG_MESSAGE = 64 << 10
"""Incoming messages larger than this [bytes] must be upload parts (nothing else a browser sends is that big): a
big map or list in any other message would hold the event loop while it is decoded."""


@dataclasses.dataclass
class LoopPatches:
    """What the guarded class-level patches do on one registered server's event loop (None: that patch skipped)."""

    max_frame_bytes: int | None = None
    on_garbage: Callable[[str], object] | None = None


LOOPS: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, LoopPatches] = weakref.WeakKeyDictionary()
"""The registered event loops and what the patches do on each (written by :mod:`.patches` under its lock)."""


async def message_consumer(websocket: Any, handle_message: Callable[[Any], None], message_class: type) -> None:
    """viser's reader of one connection's messages; on a registered loop with ``decoding`` on, each message is decoded
    by :func:`decode_quietly` (viser's own reader everywhere else)."""
    patches = LOOPS.get(asyncio.get_running_loop())
    on_garbage = None if patches is None else patches.on_garbage
    if on_garbage is None:
        await _VISER_CONSUMER(websocket, handle_message, message_class)
        return
    while True:
        raw = await websocket.recv()
        assert isinstance(raw, bytes)
        handle_message(decode_quietly(message_class, raw, on_garbage))


class _UploadPart(_infra.msgspec.Struct, forbid_unknown_fields=True):
    """The one big message a browser sends, decoded strictly (fails at the first unexpected field)."""

    type: str
    source_component_uuid: str | None
    transfer_uuid: str
    part_index: int
    content: bytes


def decode_quietly(message_class: Any, raw: bytes, on_garbage: Callable[[str], object]) -> Any:
    """viser's decoding of an incoming message, made forgiving: a message whose fields cannot be cast
    (``float("a")`` in a position, a missing field) becomes a :class:`~.wire.Malformed` instead of an exception that
    closes the connection with a traceback in the log; bytes that are not a message at all (not msgpack, no known
    type, a big one that is not an upload part) still close the connection, quietly (``on_garbage(text)``)."""
    if len(raw) > BIG_MESSAGE:
        try:
            big = _infra.msgspec.msgpack.decode(raw, type=_UploadPart)
        except _infra.msgspec.MsgspecError:
            big = None
        if big is None or big.type != "FileTransferPart":
            on_garbage(f"connection closed: a message of {len(raw)} bytes that is not an upload part")
            raise _infra.websockets.exceptions.ConnectionClosedError(None, None)
    try:
        return message_class.deserialize(raw)
    except (_infra.msgspec.DecodeError, KeyError, AttributeError) as exc:
        on_garbage(f"connection closed: not a viser message ({type(exc).__name__})")
        raise _infra.websockets.exceptions.ConnectionClosedError(None, None) from None
    except (ValueError, TypeError, IndexError) as exc:
        return Malformed(f"{type(exc).__name__}: {str(exc)[:120]}")


class GuardedProtocol(ws_server.ServerProtocol):
    """websockets' per-connection protocol; on a registered loop with a frame limit (:class:`LoopPatches`): that
    smaller limit (the rest of a refused frame dropped as it arrives, not parsed), and a path the file server cannot
    even look up (a segment too long for the file system) answered 414 or 404 instead of 500."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        try:
            patches = LOOPS.get(asyncio.get_running_loop())
        except RuntimeError:
            patches = None
        limit = None if patches is None else patches.max_frame_bytes
        self.tpm_viz_limited, self.tpm_viz_failed = limit is not None, False
        if limit is not None:
            size = kwargs.get("max_size")
            kwargs["max_size"] = limit if not isinstance(size, int) else min(size, limit)
        super().__init__(*args, **kwargs)

    def fail(self, code: Any, reason: str = "") -> None:
        super().fail(code, reason)
        self.tpm_viz_failed = self.tpm_viz_limited

    def receive_data(self, data: bytes | bytearray) -> None:
        if self.tpm_viz_failed:
            return
        super().receive_data(data)

    def reject(self, status: Any, text: str) -> Any:
        exc = self.handshake_exc
        internal = int(status) == http.HTTPStatus.INTERNAL_SERVER_ERROR
        if self.tpm_viz_limited and internal and isinstance(exc, (OSError, ValueError)):
            too_long = isinstance(exc, OSError) and exc.errno == errno.ENAMETOOLONG
            status = http.HTTPStatus.REQUEST_URI_TOO_LONG if too_long else http.HTTPStatus.NOT_FOUND
            text = "URI TOO LONG\n" if too_long else "NOT FOUND\n"
            self.handshake_exc = None  # not a server fault: no traceback in the log
        return super().reject(status, text)
