"""A browser's input is never written over before its callback has applied it.

viser stores a widget's new value the moment the browser's message arrives (on the event loop) and runs the
widget's callbacks later, in its thread pool, where the app's callbacks wait for the hub's lock. Meanwhile the server
may write that widget: a redraw after another tab's change (a slider, the load dropdown), a refusal's re-sync, a
restore (the view options, the own-copy box of a share link), a language switch. The callback then reads the
server's value instead of the one the student chose, takes it for an echo of its own write, and the input is lost.

The rule, for every input kind (checkbox, typed box, slider, dropdown, button group):

- :func:`arrived` (:mod:`.transport`, on the event loop, before viser stores the value): one more input of the
  widget, counted only when viser will hand it to a callback (the widget has one and the value changes);
- :func:`stamp` (:mod:`.limits`' gate, on the event loop, when viser hands an event to the thread pool, right after
  storing its value): the event carries the value it brought. A tab's callbacks run one at a time, in the order
  the tab sent its inputs; a callback that reads its widget (:func:`sent`) gets its own event's value, not a later
  one that arrived meanwhile (``d1 = 100``, *Work on my own copy*, ``d1 = 140``: 100 on the shared mechanism);
- :func:`running` (around each callback of the widget, :mod:`tpm_viz.ui.worded`): which inputs it applies (those
  arrived when it starts) and, in its thread, which widget and which value it is about;
- :func:`writable` (before every write of a widget's value by the app): False while an input of the widget waits for
  its callback or while that callback runs, except from inside that callback itself as long as nothing newer
  arrived (it may write the value it applied, or the state again after a refusal);
- :func:`abandon` (:mod:`.limits`, when its gate drops a callback that will never run): the widget's inputs are
  given up, so that the server writes it again.

A write that is skipped loses nothing: the pending callback applies the browser's value (and the next redraw shows
its result), or refuses it and re-syncs the widget from the state.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["abandon", "arrived", "pending", "running", "sent", "stamp", "writable"]

_local = threading.local()
_lock = threading.Lock()
_NONE = object()
_STAMP = "tpm_viz_value"


class _Inputs:
    """The inputs of one widget: ``arrived`` counts them, ``done`` up to which their callbacks finished, ``active``
    callbacks running."""

    __slots__ = ("active", "arrived", "done")

    def __init__(self) -> None:
        self.arrived = self.done = self.active = 0


def _state(handle: Any) -> Any:
    """viser's state of a GUI handle (a :class:`~tpm_viz.ui.worded.Worded` handle: of its viser handle)."""
    inner = getattr(handle, "__dict__", {}).get("handle", handle)
    return getattr(inner, "_impl", None)


def _inputs(state: Any, create: bool = False) -> _Inputs | None:
    found = getattr(state, "tpm_viz_inputs", None)
    if found is None and create and state is not None:
        found = _Inputs()
        state.tpm_viz_inputs = found
    return found


def _cast(current: Any, value: Any) -> Any:
    """``value`` as viser will store it over ``current`` (its type cast, :meth:`viser.GuiApi._handle_gui_updates`)."""
    if isinstance(current, tuple):
        return tuple(type(current[0])(v) for v in value) if current else tuple(value)
    return type(current)(value)


def arrived(handle: Any, updates: Any) -> None:
    """A browser's update of ``handle`` (a viser GUI handle) that viser is about to store and hand to its callbacks:
    counted (nothing for a button, a widget without callbacks or a value that does not change)."""
    state = _state(handle)
    if state is None or getattr(state, "is_button", False) or not getattr(state, "update_cb", None):
        return
    try:
        changed = _cast(state.value, updates["value"]) != state.value
    except Exception:  # viser refuses it itself: no callback will run
        return
    if changed:
        with _lock:
            inputs = _inputs(state, create=True)
            if inputs is not None:
                inputs.arrived += 1


def stamp(event: Any) -> None:
    """Let a browser's GUI event carry the value its widget holds now (called as viser hands it to the pool, right
    after storing the value it brought; a button's or a server's event: nothing)."""
    state = _state(getattr(event, "target", None))
    if state is None or getattr(event, "client", None) is None or getattr(state, "is_button", False):
        return
    try:
        object.__setattr__(event, _STAMP, state.value)  # a frozen dataclass: its own attribute, set once
    except (AttributeError, TypeError):  # an event of another shape: its callback reads the widget
        return


@contextlib.contextmanager
def running(handle: Any, event: Any = None) -> Iterator[None]:
    """Around one callback of ``handle``'s widget for ``event``: it applies the inputs arrived so far, and reads
    the value ``event`` brought (:func:`sent`)."""
    state = _state(handle)
    with _lock:
        inputs = _inputs(state)
        seen = 0 if inputs is None else inputs.arrived
        if inputs is not None:
            inputs.active += 1
    stack = _local.__dict__.setdefault("running", [])
    stack.append((state, seen, getattr(event, _STAMP, _NONE)))
    try:
        yield
    finally:
        stack.pop()
        if inputs is not None:
            with _lock:
                inputs.active -= 1
                inputs.done = max(inputs.done, seen)


def sent(handle: Any, current: Any) -> Any:
    """The value of ``handle``'s widget as its callback running in this thread must read it: the one its event
    brought; ``current`` (the widget's value now) anywhere else."""
    state = _state(handle)
    for running_state, _seen, value in reversed(getattr(_local, "running", ())):
        if running_state is state:
            return current if value is _NONE else value
    return current


def pending(handle: Any) -> bool:
    """Whether an input of ``handle``'s widget waits for its callback (or that callback runs)."""
    inputs = _inputs(_state(handle))
    return inputs is not None and (inputs.arrived > inputs.done or inputs.active > 0)


def writable(handle: Any) -> bool:
    """Whether the app may write ``handle``'s value now (see the module docstring)."""
    state = _state(handle)
    inputs = _inputs(state)
    if inputs is None:
        return True
    for running_state, seen, _value in reversed(getattr(_local, "running", ())):
        if running_state is state:
            return inputs.arrived == seen
    return inputs.arrived == inputs.done and inputs.active == 0


def abandon(handle: Any) -> None:
    """The callbacks of ``handle``'s widget will not run for the inputs arrived so far (a gate dropped them)."""
    with _lock:
        inputs = _inputs(_state(handle))
        if inputs is not None:
            inputs.done = max(inputs.done, inputs.arrived)
