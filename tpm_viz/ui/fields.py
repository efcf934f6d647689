"""Typed number fields and notes next to controls: the widget side of :mod:`tpm_viz.ui.widgets.typed`.

viser's number inputs drop what they cannot show (``1e9`` became ``19``) and send every keystroke, and its text
input sends every keystroke too, with no blur event. So a typed number is an ``add_text`` field read through a
:class:`~tpm_viz.ui.widgets.typed.TypedGroup`:

- :class:`TypedBox`: the text fields of one group inside a viser form, and the :class:`Note` under them: why a text
  is refused, the value in use whenever a field's text is not it, the group's refusal, plausibility notes. Enter is
  part of the text: the fields are viser's multi-line text inputs (a textarea, drawn as one line by
  :data:`ONE_LINE_CSS`), so Enter adds a line break to the field's text and that whole text is the last message the
  page sends. viser's page sends every GUI message through one 50 ms throttle that keeps only the latest message:
  a form's submit (Enter in a one-line input) replaced the keystrokes still held, and ``60`` typed with Enter in
  one burst arrived as ``6`` then Enter. A text that holds a line break is entered: it is written back without it
  and its group is settled (the form's submit still settles it too).
- :class:`Typing`: the boxes of one tab and their behaviour. A keystroke is recorded (every field's text is read
  again, so a merged or lost event loses nothing); Enter, the box's Apply button, or the quiet time after the last
  keystroke (groups with one) settles the group: its values are applied together, or it is refused next to its
  fields. The quiet time is watched by one :class:`Waker` per tab (one timer thread at most, re-armed, never one
  per keystroke). The same throttle can still drop a box's last keys when keys for another box follow within
  50 ms (Tab and keys in one burst); the server cannot tell, so a settled group's typed texts are written back
  into the page as the server has them (:meth:`TypedBox.resend`): a box always shows what was applied.
- :class:`Note`: a few lines under a control, in the tab's language. ``view.refuse(what, where=note)`` puts a
  refusal there instead of the top of the panel; the next success of the same control clears it.

Everything here runs under the hub's lock (callbacks take it), like every other change of the panel.
"""

from __future__ import annotations

import functools
import html
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Protocol, cast

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, say
from tpm_viz.ui.widgets.typed import TypedGroup

__all__ = ["ONE_LINE_CSS", "Note", "Place", "TypedBox", "Typing", "Waker", "as_phrase", "control", "note_html"]

ONE_LINE_CSS = Html("""<style>
textarea.mantine-Textarea-input { max-height: 1.625rem !important; resize: none !important;
  overflow: hidden !important; white-space: pre !important; line-height: 1.5rem !important; }
</style>""")
"""The typed fields (viser's multi-line text inputs, autosized to two rows) drawn as one line, like viser's one-line
text input: every textarea of the panel is a typed field's. Added once per tab (by :class:`Typing`)."""


def one_line(text: object) -> object:
    """``text`` without its line breaks (a field's Enter, wherever the caret was; pasted lines are joined)."""
    if isinstance(text, str) and ("\n" in text or "\r" in text):
        return text.replace("\r", "").replace("\n", "")
    return text


Apply = Callable[[Mapping[str, float]], None]
"""What a settled group does with its values (raises :class:`~tpm_viz.TpmVizError` to refuse them)."""


class Place(Protocol):
    """Where a refusal is shown next to its control (:class:`Note`, :class:`TypedBox`)."""

    def tell(self, what: Phrase | str | BaseException | None, lang: Lang) -> None: ...


def as_phrase(what: object) -> Phrase:
    """A phrase for a refusal: a phrase as it is, an exception's phrase, or any text (English) as a phrase."""
    if isinstance(what, BaseException) and what.args and isinstance(what.args[0], Phrase):
        return what.args[0]
    if isinstance(what, Phrase):
        return what
    text = str(what)
    return Phrase(text.replace("{", "{{").replace("}", "}}"))  # an English text: shown as it is, or its Korean


def note_html(lines: Sequence[str], problem: bool = False, notes: Sequence[str] = ()) -> Html:
    """The HTML of a note: ``lines`` (dark red if ``problem``, else slate), then ``notes`` (amber); empty if none."""
    if not lines and not notes:
        return Html("")
    colour = "#991b1b" if problem else "#334155"
    rows = [f'<div style="color:{colour}">{html.escape(x)}</div>' for x in lines]
    rows += [f'<div style="color:#92400e">{html.escape(x)}</div>' for x in notes]
    return Html('<div style="font-size:0.8em;line-height:1.35;margin:-0.2em 0.75em 0.5em">' + "".join(rows) + "</div>")


class Note:
    """A few lines under a control (an ``add_html`` element): a refusal, then notes, in the tab's language."""

    def __init__(self, gui: Any) -> None:
        self.handle = gui.add_html("")
        self.refusal: Phrase | None = None
        self.notes: tuple[Phrase, ...] = ()

    def tell(self, what: Phrase | str | BaseException | None, lang: Lang) -> None:
        """Show the refusal ``what`` (None: clear it)."""
        self.refusal = None if what is None else as_phrase(what)
        self.draw(lang)

    def draw(self, lang: Lang, lines: Sequence[Phrase] = (), problem: bool = False) -> None:
        """Write the note: the refusal, ``lines`` (a typed box's), then the notes (viser gets only a change)."""
        head = [] if self.refusal is None else [say(lang, "Refused: {text}", text=say(lang, self.refusal))]
        content = note_html(
            head + [say(lang, x) for x in lines],
            problem or self.refusal is not None,
            [say(lang, x) for x in self.notes],
        )
        if self.handle.content != content:
            self.handle.content = content


class TypedBox:
    """The text fields of one :class:`~tpm_viz.ui.widgets.typed.TypedGroup` in a form (Enter submits) and their note.

    ``labels`` by key (fixed English texts, translated on the wire); ``hints`` by key (optional). The note is
    created right under the fields unless ``note=False`` (then the caller places it with :meth:`add_note`, e.g.
    under an Apply button). ``form``: a form made by the caller (e.g. holding a slider before the fields)."""

    def __init__(
        self,
        gui: Any,
        group: TypedGroup,
        labels: Mapping[str, str],
        hints: Mapping[str, str] | None = None,
        note: bool = True,
        form: Any = None,
    ) -> None:
        self.group = group
        self.form = gui.add_form(None) if form is None else form
        with self.form:
            self.inputs = {
                key: gui.add_text(labels[key], group.fields[key].text, hint=(hints or {}).get(key), multiline=True)
                for key in group.fields
            }
        self.note: Note | None = Note(gui) if note else None
        self.notes: tuple[Phrase | None, ...] = ()
        """Plausibility notes about the results of the values in use (shown after the fields' lines)."""

    def add_note(self, gui: Any) -> Note:
        """Create the note here (for a box built with ``note=False``)."""
        self.note = Note(gui)
        return self.note

    def texts(self) -> dict[str, object]:
        """What each field holds now (as the browser last sent it, or the app wrote it), without line breaks."""
        return {key: one_line(handle.value) for key, handle in self.inputs.items()}

    def entered(self) -> bool:
        """Whether Enter reached a field as part of its text (a line break): that field's text is written back
        without it (the group is then to be settled)."""
        hit = False
        for handle in self.inputs.values():
            text = one_line(handle.value)
            if text != handle.value:
                handle.value, hit = text, True
        return hit

    def resend(self) -> None:
        """Write the text of each field the user typed in into the browser again, as the server has it: a keystroke
        lost in viser's throttle (keys typed in this box, then within 50 ms in another one) leaves the browser
        showing more than arrived; now the box shows what is applied. Nothing is pending when a group settles (the
        entered text was the latest message; the quiet time is longer than the throttle), so nothing is lost."""
        for key, handle in self.inputs.items():
            if self.group.fields[key].own:
                text = str(one_line(handle.value))
                handle.value = text + " "  # viser sends only a changed value: change it, then back
                handle.value = text

    def show(self, values: Mapping[str, float], force: bool = False) -> None:
        """The values in use (by key): written into the fields that show them (see ``TypedGroup.show``). A keystroke
        viser has stored but the tab's callback has not seen yet (the field's text is not the group's) is never
        written over, unless ``force``: the callback takes it next (another tab's move in between must not)."""
        arrived = {key: one_line(self.inputs[key].value) for key in values}
        known = {key: self.group.fields[key].text for key in values}
        for key, text in self.group.show(values, force).items():
            if force or arrived[key] == known[key]:
                self.inputs[key].value = text

    def tell(self, what: Phrase | str | BaseException | None, lang: Lang) -> None:
        """The group's values were refused as a whole (``what``), or accepted (None)."""
        if what is None:
            self.group.applied()
        else:
            self.group.refused(as_phrase(what))
        self.draw(lang)

    def draw(self, lang: Lang, now: float | None = None) -> None:
        """Write the note: the refusal, each field's line, the plausibility notes."""
        if self.note is None:
            return
        now = time.monotonic() if now is None else now
        self.note.notes = tuple(x for x in self.notes if x is not None)
        lines = self.group.lines(now)
        self.note.refusal = lines.pop(0) if self.group.refusal is not None else None  # first: "Refused: ..."
        self.note.draw(lang, lines, self.group.problem())

    def disable(self, disabled: bool) -> None:
        """Grey out (or not) every field of the box."""
        for handle in self.inputs.values():
            if handle.disabled != disabled:
                handle.disabled = disabled


class Waker:
    """Calls ``fn()`` at the earliest time asked for (``time.monotonic`` seconds), from one timer thread at a
    time: a later time while a timer is pending changes nothing (``fn`` asks again when it runs), an earlier one
    replaces the timer. Bounded: at most one thread per owner, however fast the keystrokes come."""

    def __init__(self, fn: Callable[[], None]) -> None:
        self._fn = fn
        self._lock = threading.Lock()
        self._at: float | None = None
        self._timer: threading.Timer | None = None
        self._closed = False

    def at(self, when: float) -> None:
        """Run ``fn`` at ``when`` (or earlier, if already asked for)."""
        with self._lock:
            if self._closed or (self._timer is not None and self._at is not None and self._at <= when):
                return
            if self._timer is not None:
                self._timer.cancel()
            self._at = when
            self._timer = threading.Timer(max(0.0, when - time.monotonic()), self._fire)
            self._timer.daemon = True
            self._timer.name = "tpm-viz-typing"
            self._timer.start()

    def _fire(self) -> None:
        with self._lock:
            self._timer, self._at = None, None
            if self._closed:
                return
        self._fn()

    @property
    def pending(self) -> bool:
        """Whether a timer is waiting."""
        return self._timer is not None

    def close(self) -> None:
        """No more calls (the tab went away)."""
        with self._lock:
            self._closed = True
            if self._timer is not None:
                self._timer.cancel()
            self._timer = None


def _internal_error(owner: Any, exc: Exception) -> None:
    """The guard's report to the tab whose callback failed (the traceback is in the server log)."""
    view = getattr(owner, "view", owner)
    what = Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__)
    view.refuse(what, resync=view is owner)


def control(method: Any = None, *, place: str | None = None) -> Any:
    """Decorator of a tab's control callback (a method of the view): run it under the hub's lock, ignore
    server-side echoes (no client), report a refused input to this tab, next to the control (``place``: the name of
    the panel's :class:`Note` or :class:`TypedBox`; else at the top of the panel); a success clears the refusal
    shown there."""

    def decorate(method: Any) -> Any:
        @guarded(on_error=_internal_error)
        @functools.wraps(method)
        def wrapper(self: Any, event: Any, *args: Any) -> None:
            if getattr(event, "client", None) is None:
                return
            with self.hub.locked():
                if self.closed:
                    return
                where = None if place is None else cast(Place, getattr(self.panel, place))
                try:
                    method(self, event, *args)
                except TpmVizError as exc:
                    self.refuse(as_phrase(exc), where=where)
                else:
                    if where is not None:
                        where.tell(None, self.lang)

        return wrapper

    return decorate if method is None else decorate(method)


class Typing:
    """The typed boxes of one tab (``view``: its :class:`~.client.ClientView`): keystrokes, Enter, Apply, quiet."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self.boxes: list[tuple[TypedBox, Apply]] = []
        self.waker = Waker(self._tick)
        self.style = view.gui.add_html(ONE_LINE_CSS)
        """The tab's :data:`ONE_LINE_CSS` (in the panel's root: a tab's contents are drawn only while it is open)."""

    def add(self, box: TypedBox, apply: Apply) -> None:
        """Wire ``box``: its keystrokes (Enter among them), its form's submit; ``apply(values)`` when it settles."""
        self.boxes.append((box, apply))
        for handle in box.inputs.values():
            handle.on_update(self._on_key)
        box.form.on_submit(lambda event, box=box: self._on_enter(event, box))

    def _live(self, event: Any) -> bool:
        return getattr(event, "client", None) is not None and not self.view.closed

    @guarded(on_error=_internal_error)
    def _on_key(self, event: Any) -> None:
        if not self._live(event):
            return
        with self.view.hub.locked():
            if not self.view.closed:
                self._sync(time.monotonic())
                for box, _apply in self.boxes:
                    if box.entered():  # Enter, as a line break of the text: the whole text is here
                        self.settle(box)
                self.view.client.flush()

    @guarded(on_error=_internal_error)
    def _on_enter(self, event: Any, box: TypedBox) -> None:
        if not self._live(event):
            return
        with self.view.hub.locked():
            if not self.view.closed:
                self.settle(box)

    @guarded(on_error=_internal_error)
    def _tick(self) -> None:
        with self.view.hub.locked():
            if self.view.closed:
                return
            now = time.monotonic()
            for box, _apply in self.boxes:  # a keystroke not yet handled starts the quiet time again: no prefix
                box.group.sync(box.texts(), now)
                if box.group.due(now):
                    self.settle(box, now)
            self._sync(now)
            self.view.client.flush()

    def _sync(self, now: float) -> None:
        """Every field's text as the browser holds it; the notes; the next wake-up."""
        for box, _apply in self.boxes:
            box.group.sync(box.texts(), now)
            box.draw(self.view.lang, now)
        wakes = [w for w in (box.group.wake_at() for box, _ in self.boxes) if w is not None]
        if wakes:
            self.waker.at(min(wakes))

    def settle(self, box: TypedBox, now: float | None = None) -> None:
        """Enter, Apply or the quiet time (under the hub's lock): apply the group's values, or show why not next
        to its fields. A group in which nothing was typed, with nothing refused, has nothing to apply."""
        now = time.monotonic() if now is None else now
        box.group.sync(box.texts(), now)
        box.resend()
        apply = next(a for b, a in self.boxes if b is box)
        group = box.group
        if any(f.own for f in group.fields.values()) or group.refusal is not None:
            try:
                values = group.read()
            except TpmVizError:
                pass  # each refused text is held with its reason: the note says it
            else:
                try:
                    apply(values)
                except TpmVizError as exc:
                    self.view.refuse(as_phrase(exc), resync=False, where=box)
                else:
                    group.applied()
        box.draw(self.view.lang, now)
        self.view.client.flush()

    def draw(self) -> None:
        """Every box's note again (the tab's language changed, a frame was drawn)."""
        now = time.monotonic()
        for box, _apply in self.boxes:
            box.draw(self.view.lang, now)

    def close(self) -> None:
        """The tab went away: no more timer."""
        self.waker.close()
