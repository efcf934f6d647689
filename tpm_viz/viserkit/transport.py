"""Hardening of viser's message handling: malformed messages, wrong-kind widget updates and uploads.

A browser only ever sends messages of the declared shape, ``GuiUpdateMessage(uuid, {"value": v})`` with a ``v`` of
the widget's kind, and uploads files no larger than the user picked, to an upload button. A hand-written client can
send anything, and viser 1.1.1 then

- builds any message whose fields have the wrong type or length (a 2-element gizmo position reaches every redraw
  of that tab; a text ``owner`` where a string is due raises in a task nobody awaits);
- casts a GUI value with the widget's Python type in its event loop (``float("abc")`` raises there, ``float("nan")``
  and ``float("1e999")`` succeed, any string is a dropdown choice), and lets a client rewrite any property of its own
  widgets (label, min, max, disabled);
- accepts an upload aimed at any widget (a slider's value becomes an ``UploadedFile``) and buffers every upload
  part until the declared size has arrived, with no limit of its own.

:func:`message_problem` checks every incoming message against its declared field types (right types, tuple lengths,
finite numbers, bounded text); :mod:`.limits` drops the bad ones before viser dispatches them. :func:`harden` wraps
a tab's GUI and upload handlers: a GUI update must carry exactly ``value``, of the widget's kind (a number for a
number, one of the options for a dropdown or a button group, ``True`` for a button, a boolean for a checkbox, text of
at most :data:`MAX_TEXT` characters for a text input), finite; uploads go to upload buttons only, at most
:data:`~tpm_viz.app.inputs.MAX_UPLOAD_BYTES` each (refused before any byte is buffered), at most
:data:`MAX_UPLOADS` in flight per tab, each freed after :data:`UPLOAD_TIMEOUT` seconds if unfinished. Every drop is a
rate-limited log line (:func:`~.guard.log_fault`). What passes still goes through the callbacks' own validation
(:mod:`tpm_viz.app.inputs`). viser's internals are reached through :class:`~tpm_viz.viserkit.doors.ClientDoor`.

viser's page shows its own toast for every upload, "File uploaded successfully" once the last part is acknowledged,
whatever the app then makes of the file. That toast is hidden before the last acknowledgement goes out (and the
button freed when an upload is refused before its end): whether a file was taken is the app's to say, next to the
upload button (:mod:`.teaching.player`), so that a refused file never gets a success toast.

A refused upload is the one drop a user sees (a red notification, at most one a second): its words are phrases
shown in the tab's language (``harden(client, lang=...)``: how to read the tab's language when it happens); the log
lines and the reasons of the other drops (a browser never sends those) stay English.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import functools
import math
import types
import typing
from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.app.inputs import MAX_TEXT, MAX_UPLOAD_BYTES, TOO_LARGE, value_problem
from tpm_viz.classroom.guard import log_fault
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.viserkit.core import Malformed, widget_value
from tpm_viz.viserkit.doors import ClientDoor
from tpm_viz.viserkit.inputs import arrived
from tpm_viz.viserkit.patches import skipped
from tpm_viz.viserkit.uploads import UploadBudget, budget_of, expire_later

__all__ = ["MAX_UPLOADS", "UPLOAD_TIMEOUT", "harden", "message_problem", "update_problem"]

MAX_UPLOADS = 2
"""Uploads one tab may have in flight at once."""
UPLOAD_TIMEOUT = 30.0
"""Seconds an upload may take before its buffered parts are freed [s]."""
_MAX_FIELD_TEXT = 4096
"""Longest string in any field of an incoming message other than a GUI value (names, uuids, file names)."""
_SKIP = {"excluded_self_client"}


def update_problem(current: Any, updates: Any, handle: Any = None, max_text: int = MAX_TEXT) -> str | None:
    """Why a GUI update would be refused, or None. ``current`` is the widget's value, ``handle`` the widget (its
    kind and options; None: judged by the value's type only, as viser casts it)."""
    if not isinstance(updates, dict) or set(updates) != {"value"}:
        return f"only the value of a widget may change, got {sorted(map(str, updates))[:4]}"
    value = updates["value"]
    if isinstance(handle, viser.GuiUploadButtonHandle):
        return "an upload button takes files, not values"
    if isinstance(handle, viser.GuiButtonHandle):
        return None if value is True else "a button click is True"
    if isinstance(handle, (viser.GuiDropdownHandle, viser.GuiButtonGroupHandle)):
        return None if isinstance(value, str) and value in handle.options else "not one of the widget's options"
    return value_problem(current, value, max_text)


def harden(
    client: viser.ClientHandle,
    max_upload_bytes: int = MAX_UPLOAD_BYTES,
    lang: Callable[[], Lang] | None = None,
    budget: UploadBudget | None = None,
) -> None:
    """Install the filters of the module docstring on ``client``'s connection (call once, on connect). ``lang``
    returns the tab's language at the time of a refusal (None: English), e.g. ``lambda: view.lang``; ``budget``: the
    server's bytes of uploads in flight (default: :func:`~.uploads.budget_of` the client's server; the app gives
    a tab's back when it leaves). Nothing is installed if the ``transport`` patch is skipped on the client's server
    (:func:`~.adapter.install`)."""
    if skipped(client, "transport"):
        return
    door = ClientDoor(client)
    cid = client.client_id
    uploads = _Uploads(client, door, max_upload_bytes, lang, budget if budget is not None else budget_of(door.server))

    async def gui_update(client_id: Any, message: Any) -> None:
        handle = door.widget(message.uuid)
        if handle is not None:
            problem = update_problem(widget_value(handle), message.updates, handle)
            if problem is not None:
                log_fault(cid, "gui", f"GUI update dropped: {problem}")
                return
            arrived(handle, message.updates)  # its callback will apply it: no redraw writes over it meanwhile
        await door.gui_update(client_id, message)

    door.replace(gui_update, uploads.start, uploads.part)


class _Uploads:
    """One tab's uploads in flight (see :mod:`.uploads`): at most :data:`MAX_UPLOADS`, each in the server's budget,
    each freed after :data:`UPLOAD_TIMEOUT` seconds if unfinished."""

    def __init__(
        self,
        client: viser.ClientHandle,
        door: ClientDoor,
        max_upload_bytes: int,
        lang: Callable[[], Lang] | None,
        budget: UploadBudget,
    ) -> None:
        self.client, self.door, self.cid = client, door, client.client_id
        self.max_upload_bytes, self.lang, self.budget = max_upload_bytes, lang, budget
        self.address = door.address()
        self.in_flight: dict[str, tuple[str, int, Any]] = {}  # transfer uuid -> (button, size, timer): unfinished

    def refuse(self, why: Phrase, button: str | None, transfer: str, size: int) -> None:
        self.door.end_upload(str(button), transfer, max(0, size))  # no spinner left, the button free again
        if log_fault(self.cid, "upload", f"upload refused: {why}"):  # at most one notification per second as well
            tab = Lang.EN
            with contextlib.suppress(Exception):  # a getter that fails: English
                tab = Lang.EN if self.lang is None else Lang(self.lang())
            with contextlib.suppress(Exception):
                title, text = say(tab, T("Upload refused")), say(tab, why)
                self.client.add_notification(title, text, color="red", auto_close_seconds=8.0)

    def end(self, transfer: str) -> tuple[str, int, Any] | None:
        """``transfer`` is over (finished, refused, expired): its timer stopped, its bytes given back."""
        entry = self.in_flight.pop(transfer, None)
        if entry is not None and entry[2] is not None:
            entry[2].cancel()
        self.budget.give(self.cid, transfer)
        return entry

    def expire(self, transfer: str) -> None:
        if transfer in self.in_flight and self.door.upload_state(transfer) is not None:
            self.door.drop_upload(transfer)
            button, size, _timer = self.end(transfer) or ("", 0, None)
            late = Phrase("the upload did not finish within {seconds:g} s", seconds=UPLOAD_TIMEOUT)
            self.refuse(late, button, transfer, size)
        else:
            self.end(transfer)

    def start(self, client_id: Any, message: Any) -> None:
        size, parts = message.size_bytes, message.part_count
        for transfer in [t for t in self.in_flight if self.door.upload_state(t) is None]:  # finished ones
            self.end(transfer)
        if not isinstance(self.door.widget(message.source_component_uuid), viser.GuiUploadButtonHandle):
            log_fault(self.cid, "upload", "upload dropped: not aimed at an upload button")
            return
        button, transfer = message.source_component_uuid, message.transfer_uuid
        if not (0 <= size <= self.max_upload_bytes and 0 <= parts <= max(1, size)):
            self.refuse(Phrase(TOO_LARGE.template, size=size, most=self.max_upload_bytes), button, transfer, size)
            return
        if len(self.in_flight) >= MAX_UPLOADS or transfer in self.in_flight:
            self.refuse(Phrase("at most {count} uploads at a time", count=MAX_UPLOADS), button, transfer, size)
            return
        refusal = self.budget.take(self.cid, self.address, transfer, size)
        if refusal is not None:
            self.refuse(refusal.why, button, transfer, size)
            return
        timer = None
        with contextlib.suppress(RuntimeError):  # called on the server's event loop
            timer = expire_later(asyncio.get_running_loop(), UPLOAD_TIMEOUT, self, _Uploads.expire, transfer)
        self.in_flight[transfer] = (str(button), size, timer)
        if parts == 0:  # an empty file: viser finishes it at once
            self.door.end_upload(str(button), transfer)
        self.door.upload_start(client_id, message)
        if self.door.upload_state(transfer) is None:
            self.end(transfer)

    def part(self, client_id: Any, message: Any) -> None:
        transfer = message.transfer_uuid
        state = self.door.upload_state(transfer)
        if state is None or transfer not in self.in_flight:
            return  # not this tab's upload in progress (or already refused): nothing is buffered
        if state["transferred_bytes"] + len(message.content) > state["total_bytes"]:
            self.door.drop_upload(transfer)
            self.end(transfer)
            button = message.source_component_uuid
            self.refuse(T("the file sent more bytes than it announced"), button, transfer, state["total_bytes"])
            return
        parts, count = state["parts"], state["part_count"]
        if message.part_index not in parts and 0 <= message.part_index < count and len(parts) + 1 >= count:
            self.door.end_upload(str(message.source_component_uuid), transfer)  # the last part: before its ack
        self.door.upload_part(client_id, message)
        if self.door.upload_state(transfer) is None:
            self.end(transfer)


def message_problem(message: Any) -> str | None:
    """Why an incoming message does not match its declared field types (None if it does)."""
    if isinstance(message, Malformed):
        return message.problem
    for name, check in _schema(type(message)):
        problem = check(getattr(message, name, None))
        if problem is not None:
            return f"{type(message).__name__}.{name}: {problem}"
    return None


Check = Callable[[Any], "str | None"]
"""A field's check: why a value does not match the field's declared type, or None."""

_SCHEMAS: dict[type, tuple[tuple[str, Check], ...]] = {}


def _schema(cls: type) -> tuple[tuple[str, Check], ...]:
    """``(field, check)`` of a message class, built once per class (empty if its annotations cannot be read): every
    incoming message is checked on the event loop, 600 a second in a lecture hall (``bench_load.py --mode hall``)."""
    schema = _SCHEMAS.get(cls)
    if schema is None:
        try:
            hints = typing.get_type_hints(cls)
            names = [f.name for f in dataclasses.fields(cls)]
        except Exception:  # an unknown message shape: viser alone decides
            names, hints = [], {}
        finite = cls.__name__ != "ViewerCameraMessage"  # a browser's camera is never dropped (the tab would not start)
        schema = tuple((n, _check(hints[n], finite)) for n in names if n in hints and n not in _SKIP)
        _SCHEMAS[cls] = schema
    return schema


def _ok(value: Any) -> None:
    return None


def _check(annotation: Any, finite: bool) -> Check:
    """The check of a value against ``annotation`` (numbers finite if ``finite``); nested props and anything else
    pass (viser's own decoding decides)."""
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if annotation is Any or annotation is object:
        return _ok
    if annotation in (float, int):
        return functools.partial(_number, finite=finite)
    if annotation is bool:
        return lambda v: None if isinstance(v, bool) else f"a boolean is due, got {type(v).__name__}"
    if annotation is str:
        return _text
    if annotation is bytes:
        return lambda v: None if isinstance(v, (bytes, bytearray, memoryview)) else "bytes are due"
    if annotation is type(None):
        return lambda v: None if v is None else "None is due"
    if origin in (typing.Union, types.UnionType):
        return functools.partial(_any_of, tuple(_check(a, finite) for a in args))
    if origin is typing.Literal:
        return lambda v: None if v in args else "not one of the allowed values"
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return functools.partial(_sequence, None, _check(args[0], finite))
        return functools.partial(_sequence, tuple(_check(a, finite) for a in args), _ok)
    if origin is dict:
        return lambda v: None if isinstance(v, dict) else "a map is due"
    if origin is list:
        return lambda v: None if isinstance(v, (list, tuple)) else "a list is due"
    return _ok


def _number(value: Any, finite: bool) -> str | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"a number is due, got {type(value).__name__}"
    if finite and isinstance(value, float) and not math.isfinite(value):
        return "not a finite number"
    return None


def _text(value: Any) -> str | None:
    if not isinstance(value, str):
        return f"text is due, got {type(value).__name__}"
    return None if len(value) <= _MAX_FIELD_TEXT else "text too long"


def _any_of(checks: tuple[Check, ...], value: Any) -> str | None:
    found = [check(value) for check in checks]
    return None if any(p is None for p in found) else next(p for p in found if p)


def _sequence(items: tuple[Check, ...] | None, each: Check, value: Any) -> str | None:
    """A fixed tuple (``items``: one check per item) or a variadic one (every item checked with ``each``)."""
    if not isinstance(value, (tuple, list)):
        return f"a sequence is due, got {type(value).__name__}"
    if items is None:
        return next((p for v in value if (p := each(v)) is not None), None)
    if len(items) != len(value):
        return f"{len(items)} items are due, got {len(value)}"
    return next((p for check, v in zip(items, value, strict=True) if (p := check(v)) is not None), None)
