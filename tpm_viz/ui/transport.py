"""Hardening of viser's message handling for one connected tab: malformed GUI updates and oversized uploads.

A browser only ever sends ``GuiUpdateMessage(uuid, {"value": v})`` with a ``v`` of the widget's type, and uploads
files no larger than the user picked. A hand-written client can send anything, and viser 1.1.1 then

- casts the value with the widget's Python type in its event loop (``float("abc")``, ``float(None)``, ``tuple(3.0)``
  raise there and print a traceback per message; ``float("nan")`` and ``float("1e999")`` succeed), and lets a
  client rewrite any property of its own widgets (label, min, max, disabled);
- buffers every upload part in memory until the declared size has arrived, with no limit of its own.

:func:`harden` wraps both handlers on the tab's own connection: a GUI update must carry exactly ``value`` and cast
like viser casts it, into finite numbers, else it is dropped with one warning line (at most one per second per
tab); an upload larger than :data:`~.validate.MAX_UPLOAD_BYTES` is refused before any byte is buffered, and a
transfer that sends more than it declared is dropped. What passes still goes through the callbacks' own
validation (:mod:`tpm_viz.app.inputs`). viser's internals are reached through :class:`~._viser.ClientDoor`.
"""

from __future__ import annotations

import contextlib
import math
import time

import viser

from tpm_viz.app.inputs import MAX_UPLOAD_BYTES
from tpm_viz.ui._viser import ClientDoor, widget_value
from tpm_viz.ui.guard import log

__all__ = ["harden", "update_problem"]


def update_problem(current, updates) -> str | None:
    """Why a GUI update would be refused (viser's own cast of ``updates["value"]`` to ``type(current)``), or None."""
    if not isinstance(updates, dict) or set(updates) != {"value"}:
        return f"only the value of a widget may change, got {sorted(map(str, updates))[:4]}"
    value = updates["value"]
    try:
        if isinstance(current, tuple):
            items = tuple(value)
            cast = tuple(type(current[0])(item) for item in items) if current else items
        elif current is not None:
            cast = (type(current)(value),)
        else:
            return "this widget takes no value"
    except (TypeError, ValueError, OverflowError):
        return f"a value of the wrong type for this widget ({type(value).__name__})"
    if any(isinstance(x, float) and not math.isfinite(x) for x in cast):
        return "not a finite number"  # no browser input yields NaN or inf; viser would cast "nan" to one
    return None


class _Warner:
    """One warning line per tab and second at most (a flood of bad messages must not flood the log)."""

    def __init__(self, client_id: int) -> None:
        self.client_id, self.last, self.dropped = client_id, 0.0, 0

    def __call__(self, text: str) -> None:
        now = time.monotonic()
        if now - self.last < 1.0:
            self.dropped += 1
            return
        more = f" (+{self.dropped} more dropped)" if self.dropped else ""
        log.warning("client %s: %s%s", self.client_id, text, more)
        self.last, self.dropped = now, 0


def harden(client: viser.ClientHandle, max_upload_bytes: int = MAX_UPLOAD_BYTES) -> None:
    """Install the filters of the module docstring on ``client``'s connection (call once, on connect)."""
    door = ClientDoor(client)
    warn = _Warner(client.client_id)

    async def gui_update(client_id, message) -> None:
        handle = door.widget(message.uuid)
        if handle is not None:
            problem = update_problem(widget_value(handle), message.updates)
            if problem is not None:
                warn(f"GUI update dropped: {problem}")
                return
        await door.gui_update(client_id, message)

    def refuse_upload(text: str) -> None:
        warn(f"upload refused: {text}")
        with contextlib.suppress(Exception):
            client.add_notification("Upload refused", text, color="red", auto_close_seconds=8.0)

    def upload_start(client_id, message) -> None:
        size, parts = message.size_bytes, message.part_count
        if not (0 <= size <= max_upload_bytes and 0 <= parts <= max(1, size)):
            refuse_upload(f"the file is too large ({size} bytes; at most {max_upload_bytes} bytes)")
            return
        door.upload_start(client_id, message)

    def upload_part(client_id, message) -> None:
        state = door.upload_state(message.transfer_uuid)
        if state is not None and state["transferred_bytes"] + len(message.content) > state["total_bytes"]:
            door.drop_upload(message.transfer_uuid)
            refuse_upload("the file sent more bytes than it announced")
            return
        door.upload_part(client_id, message)

    door.replace(gui_update, upload_start, upload_part)
