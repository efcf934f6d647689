"""Plain helpers of the door to viser's internals (:mod:`.core`): the shapes of the handlers it swaps, the stand-in
for an undecodable message, and small functions on messages. Nothing here touches a private viser name."""

from __future__ import annotations

import inspect
from collections.abc import Awaitable, Callable
from typing import Any

__all__ = [
    "GuiUpdate",
    "Handshake",
    "Incoming",
    "Malformed",
    "Upload",
    "Wrapper",
    "has_attr_or_init",
    "hooked_serve",
    "message_bytes",
    "next_minor",
    "renumbered",
    "shared_serializer",
]

GuiUpdate = Callable[[Any, Any], Awaitable[None]]
Upload = Callable[[Any, Any], None]


Incoming = Callable[[int, Any], Awaitable[None]]
Wrapper = Callable[[Incoming], Incoming]


Handshake = Callable[[Any, Any, Callable[[], Any]], Any]
"""``hook(connection, request, viser_response)``: return a websockets ``Response`` (e.g. ``viser_response()``, with
headers added, or ``connection.respond(403, ...)`` to refuse) or None (go on with the websocket handshake)."""


class Malformed:
    """Stands for a message of a known type whose fields viser could not decode (wrong types, missing fields):
    dispatched like a message, handled by nobody, dropped with a log line by :mod:`.limits`."""

    def __init__(self, problem: str) -> None:
        self.problem = problem


def message_bytes(message: Any) -> int:
    """Rough size of a queued message [bytes]: its bytes, text and array payloads plus a fixed overhead."""
    size = 64
    for value in list(vars(message).values()):  # a copy: the event loop may add to a message's dict meanwhile
        if isinstance(value, (bytes, bytearray, str)):
            size += len(value)
        else:
            size += int(getattr(value, "nbytes", 0) or 0)
    return size


def renumbered(value: Any, shift: int) -> Any:
    """``value`` with every binary placeholder's index moved by ``shift`` (copies only what holds one)."""
    if isinstance(value, dict):
        if "__binary_index" in value and "dtype" in value:
            return {**value, "__binary_index": value["__binary_index"] + shift}
        return {k: renumbered(v, shift) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(renumbered(v, shift) for v in value)
    return value


def next_minor(minor: str) -> str:
    return f"{minor.split('.')[0]}.{int(minor.split('.')[1]) + 1}"


def has_attr_or_init(cls: type, name: str) -> bool:
    """Whether ``cls`` has ``name`` or assigns ``self.name`` in its ``__init__`` (instance attributes)."""
    if hasattr(cls, name):
        return True
    try:
        return f"self.{name}" in inspect.getsource(cls.__init__)
    except (OSError, TypeError):
        return False


def shared_serializer(serialize: Callable[..., dict[str, Any]]) -> Callable[..., dict[str, Any]]:
    """viser's ``Message.as_serializable_dict`` that makes a message's wire dict once for every tab (``serialize``:
    viser's own): the first call with a list of array buffers keeps the dict and the buffers it added in the
    message; a later call (another tab's window) appends the same buffers and renumbers their placeholders."""

    def as_serializable_dict(self: Any, binary_buffers: list | None = None) -> dict[str, Any]:
        cached = self.__dict__.get("_tpm_viz_wire")
        if binary_buffers is None or cached is None or cached[0] != id(self):
            start = 0 if binary_buffers is None else len(binary_buffers)
            out = serialize(self, binary_buffers)
            if binary_buffers is not None:
                self.__dict__["_tpm_viz_wire"] = (id(self), out, start, tuple(binary_buffers[start:]))
            return out
        _, out, start, buffers = cached
        shift = len(binary_buffers) - start
        binary_buffers.extend(buffers)
        return renumbered(out, shift) if buffers and shift else out

    return as_serializable_dict


def hooked_serve(serve: Callable[..., Any], hook: Handshake) -> Callable[..., Any]:
    """websockets' ``serve`` that passes every HTTP request and websocket handshake through ``hook`` first (before
    the ``process_request`` it is given: viser's page server)."""

    def hooked(*args: Any, **kwargs: Any) -> Any:
        inner = kwargs.get("process_request")

        def process_request(connection: Any, request: Any) -> Any:
            return hook(connection, request, lambda: None if inner is None else inner(connection, request))

        kwargs["process_request"] = process_request
        return serve(*args, **kwargs)

    return hooked
