"""Plain helpers of the door to viser's internals (:mod:`._viser`): the shapes of the handlers it swaps, the stand-in
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
    "message_bytes",
    "next_minor",
    "renumbered",
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
    for value in vars(message).values():
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
