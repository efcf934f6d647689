"""The patches of viser 1.1.x that cannot be put on one server object alone, each guarded to act for tpm-viz's own
servers only (see ``PATCHES.md``); :mod:`.adapter` installs them.

A server is *registered* (:func:`register`) with what it takes: its event loop in :data:`~.incoming.LOOPS`, the
server in :data:`_SKIPS`. Four names of viser or websockets are looked up per connection, so they are replaced for
the whole process, by functions that do what the original does unless the object at hand belongs to a registered
server:

- ``viser.infra._infra._message_producer``: a buffer that carries a tpm-viz sender (``tpm_viz_produce``, put on it
  by :func:`upgrade_buffer`) is sent with it; any other with viser's own;
- ``viser.infra._infra._message_consumer``: on a registered loop, incoming bytes are decoded quietly
  (:func:`~.incoming.decode_quietly`); elsewhere viser's own loop runs;
- ``websockets.asyncio.server.ServerProtocol``: on a registered loop, a smaller frame limit and no HTTP 500
  (:class:`~.incoming.GuardedProtocol`); elsewhere every method is the original's;
- ``AssignablePropsBase._prop_hints``: a handle of a registered server reads its props' types from a cache per props
  class; any other handle from viser's own per-handle cache;
- ``viser._scene_handles._set_pose_vector`` and ``AssignablePropsBase._cast_value_recursive``: for a handle of a
  registered server, the same checks on plain floats and prebuilt aliases (:mod:`.casts`); for any other, viser's.

``websockets.asyncio.server.serve`` is replaced only while :func:`building` is entered, and hooks only the server
built inside it (found by its event loop). :func:`unregister` puts every original back once no server is left.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import threading
import weakref
from collections.abc import Iterator
from typing import Any, cast, get_type_hints

import viser
from viser import _assignable_props_api, _messages, _scene_handles
from viser.infra import _infra

from tpm_viz.viserkit import casts, wire
from tpm_viz.viserkit.incoming import BIG_MESSAGE, LOOPS, GuardedProtocol, LoopPatches, decode_quietly, message_consumer
from tpm_viz.viserkit.wakeups import Wakeups, thread_safe_set
from tpm_viz.viserkit.windows import Encode, Frames, Tick, encoder, producer, window_loop

__all__ = ["BIG_MESSAGE", "GuardedProtocol", "LoopPatches", "building", "decode_quietly", "lean_encoder"]
__all__ += ["count", "downgrade_buffer", "register", "registered", "skipped", "unregister", "upgrade_buffer"]

ws_server = _infra.websockets.asyncio.server  # websockets' server, as viser imported it (not a tpm-viz dependency)
_Props = _assignable_props_api.AssignablePropsBase
_ORIGINAL: dict[str, Any] = {
    "producer": _infra._message_producer,
    "consumer": _infra._message_consumer,
    "protocol": ws_server.ServerProtocol,
    "hints": _Props.__dict__["_prop_hints"],
}
SERIALIZE = _messages.Message.as_serializable_dict
"""viser's own serialisation of a message (the shared one calls it once per message)."""
_SKIPS: weakref.WeakKeyDictionary[viser.ViserServer, frozenset[str]] = weakref.WeakKeyDictionary()
_HINTED: weakref.WeakSet[viser.ViserServer] = weakref.WeakSet()
_CAST: weakref.WeakSet[viser.ViserServer] = weakref.WeakSet()
_WAKEUPS: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, Wakeups] = weakref.WeakKeyDictionary()
_LOCK = threading.RLock()  # re-entrant: a server collected while it is held restores under it


def _owner_server(handle: Any) -> Any:
    """The viser server a GUI or scene handle belongs to (None if it cannot be told)."""
    impl = handle.__dict__.get("_impl")
    api = getattr(impl, "gui_api", None) or getattr(impl, "api", None)
    owner = getattr(api, "_owner", None)
    return getattr(owner, "_viser_server", owner)


_HINTS = functools.cache(get_type_hints)  # a handle's property types once per props class (a sixth of a storm)


def _prop_hints(self: Any) -> dict[str, Any]:
    server = _owner_server(self)
    if server is not None and server in _HINTED:
        hints: dict[str, Any] = _HINTS(cast(Any, type(self._impl.props)))
        return hints
    return cast("dict[str, Any]", _ORIGINAL["hints"].__get__(self, type(self)))


def _set_pose_vector(current: Any, value: Any, length: int, queue: Any, make_message: Any) -> None:
    api = getattr(queue, "__self__", None)  # the scene API whose node this is
    owner = getattr(api, "_owner", None)
    if getattr(owner, "_viser_server", owner) in _CAST:
        casts.set_pose_vector(current, value, length, queue, make_message)
    else:
        casts.VISER["pose"](current, value, length, queue, make_message)


def _cast_value_recursive(self: Any, hint: Any, value: Any, prop_name: str) -> Any:
    if _owner_server(self) in _CAST:
        return casts.cast_value(hint, value, prop_name)
    return casts.VISER["cast"](self, hint, value, prop_name)


async def _message_producer(
    websocket: Any, buffer: Any, client_id: int, backlog_done_message: Any | None = None
) -> None:
    produce = buffer.__dict__.get("tpm_viz_produce")
    if produce is None:
        await _ORIGINAL["producer"](websocket, buffer, client_id, backlog_done_message=backlog_done_message)
    else:
        await produce(websocket, buffer, client_id, backlog_done_message)


def _put_guards() -> None:
    _infra._message_producer = _message_producer
    _infra._message_consumer = message_consumer
    ws_server.ServerProtocol = GuardedProtocol
    _Props._prop_hints = property(_prop_hints)  # type: ignore[assignment]
    _Props._cast_value_recursive = _cast_value_recursive  # type: ignore[method-assign]
    _scene_handles._set_pose_vector = _set_pose_vector


def _put_originals() -> None:
    _infra._message_producer = _ORIGINAL["producer"]
    _infra._message_consumer = _ORIGINAL["consumer"]
    ws_server.ServerProtocol = _ORIGINAL["protocol"]
    _Props._prop_hints = _ORIGINAL["hints"]  # type: ignore[method-assign]
    _Props._cast_value_recursive = casts.VISER["cast"]  # type: ignore[method-assign]
    _scene_handles._set_pose_vector = casts.VISER["pose"]


def register(
    server: viser.ViserServer, loop: asyncio.AbstractEventLoop, patches: LoopPatches, skip: frozenset[str]
) -> None:
    """Let the guarded patches act for ``server`` (its event loop ``loop``); ``skip``: names of patches it does not
    take (``"serialization"`` in it: its handles keep viser's per-handle type hints)."""
    with _LOCK:
        if not _SKIPS:
            _put_guards()
        LOOPS[loop] = patches
        _SKIPS[server] = skip
        weakref.finalize(server, _restore_if_none)  # a server collected without unregister: originals back
        if "serialization" not in skip:
            _HINTED.add(server)
        if "casts" not in skip:
            _CAST.add(server)


def unregister(server: viser.ViserServer, loop: asyncio.AbstractEventLoop | None) -> None:
    """Stop the guarded patches acting for ``server``; the originals are back once no server is registered."""
    with _LOCK:
        _SKIPS.pop(server, None)
        _HINTED.discard(server)
        _CAST.discard(server)
        if loop is not None:
            LOOPS.pop(loop, None)
            _WAKEUPS.pop(loop, None)
    _restore_if_none()


def _restore_if_none() -> None:
    with _LOCK:
        if not list(_SKIPS.keys()):  # live servers only (a collected one may not be removed from the dict yet)
            _put_originals()


def registered(server: Any) -> bool:
    """Whether ``server`` is a registered tpm-viz server."""
    return server in _SKIPS


def count() -> int:
    """How many tpm-viz servers are registered (alive) in this process."""
    return len(_SKIPS)


def skipped(owner: Any, name: str) -> bool:
    """Whether the patch ``name`` is switched off on the registered server of ``owner`` (a server or a client
    handle; False for a server that is not registered: the patch acts, as on a bare server in a test)."""
    server = getattr(owner, "_viser_server", owner)
    try:
        return name in _SKIPS.get(server, frozenset())
    except TypeError:  # None or another object that cannot be weakly referenced: not a registered server
        return False


def lean_encoder(shared: bool) -> Encode:
    """viser's wire format with its own msgpack, a zstd compressor of this encoder's own (used on one event loop
    only) and its buffer alignment; ``shared``: each message's wire dict made once for every tab."""
    serialize = wire.shared_serializer(SERIALIZE) if shared else SERIALIZE
    zstd = _infra.zstandard.ZstdCompressor(level=1)
    return encoder(_infra.msgspec.msgpack.encode, zstd.compress, _infra._append_aligned_buffers, serialize)


def upgrade_buffer(buffer: Any, wakeups: bool, lean: bool, encode: Encode | None) -> None:
    """Put the per-buffer patches on one of viser's message buffers (before a sender reads it): ``wakeups`` (its
    loop seen through the loop's one :class:`~.wakeups.Wakeups`, its message event safe from any thread), ``lean``
    (one pause timer per buffer, viser's window loop by :func:`~.windows.window_loop`, a window of the shared buffer
    encoded once for every tab), ``encode`` (send with it instead of viser's producer; None: viser's producer)."""
    if wakeups and not isinstance(buffer.event_loop, Wakeups):
        loop = buffer.event_loop
        with _LOCK:
            buffer.event_loop = _WAKEUPS.get(loop) or _WAKEUPS.setdefault(loop, Wakeups(loop))
        buffer.message_event.set = thread_safe_set(buffer.message_event, buffer.event_loop)
    if lean:
        buffer.tick = Tick(buffer.event_loop, buffer.window_duration_sec)
        buffer.flush_event.set = buffer.tick.after(buffer.flush_event.set)  # viser sets it on the loop
        buffer._window_loop = functools.partial(window_loop, buffer)
    if encode is not None:
        buffer.frames = Frames(encode) if lean and buffer.persistent_messages else None  # the shared buffer's only
        buffer.tpm_viz_produce = producer(encode)


def downgrade_buffer(buffer: Any) -> None:
    """Take the per-buffer patches off again (senders already running keep theirs)."""
    if isinstance(buffer.event_loop, Wakeups):
        buffer.event_loop = buffer.event_loop.loop
    for event in (buffer.message_event, buffer.flush_event):
        event.__dict__.pop("set", None)
    for name in ("tick", "_window_loop", "frames", "tpm_viz_produce"):
        buffer.__dict__.pop(name, None)


_BUILDING: list[tuple[viser.ViserServer, wire.Handshake]] = []
_BUILD_LOCK = threading.Lock()


def _hooked_serve(*args: Any, **kwargs: Any) -> Any:
    loop = asyncio.get_running_loop()
    for server, hook in _BUILDING:
        ws = server.__dict__.get("_websock_server")
        if ws is not None and ws._background_event_loop is loop:
            return wire.hooked_serve(_ORIGINAL["serve"], hook)(*args, **kwargs)
    return _ORIGINAL["serve"](*args, **kwargs)


@contextlib.contextmanager
def building(server: viser.ViserServer, hook: wire.Handshake) -> Iterator[None]:
    """While ``server`` (made with ``ViserServer.__new__``) runs its ``__init__`` inside this block, every HTTP
    request and websocket handshake of the server it starts goes through ``hook`` first (viser passes its page server
    to websockets' ``serve(process_request=)``; ``ViserServer()`` returns once ``serve`` was entered). Another
    server's ``serve`` meanwhile, on its own event loop, is websockets' own."""
    with _BUILD_LOCK:
        _ORIGINAL["serve"] = ws_server.serve
        ws_server.serve = _hooked_serve  # type: ignore[assignment]
        _BUILDING.append((server, hook))
        try:
            yield
        finally:
            _BUILDING.clear()
            ws_server.serve = _ORIGINAL["serve"]
