"""A slider with a typed number beside it: the Control and Planner settings (ω_n, ζ, payload, F_max, ...).

viser's slider has a number box of its own beside it, which drops what it cannot show (``1e9`` became ``19``),
blanks itself on ``abc`` and keeps showing ``-5`` while the slider's 100 Hz is used, and nothing says so. A
:class:`TypedSlider` is the slider without that box (hidden by the style sheet :func:`row_css`) and, in the same
row where the box was, a typed field of the app (:class:`~.fields.TypedBox` of one field, read by
:mod:`tpm_viz.ui.widgets.typed`: scientific notation, decimal commas, the unit after the number, the slider's range as
the accepted range) with its note under the row: the same refusals and "in use" notes as every typed number.

The slider's value is the value in use: a settled text is written into the slider (then ``on_change()`` runs, as
a drag of the slider runs the tab's own callback; if it refuses the value, the slider goes back and the refusal is
shown under the field), and a drag of the slider, or a value the app writes (:meth:`TypedSlider.set`), is shown in
the field (over what is typed there: the newest input wins). A value that only follows something else (the time of
a playback: :meth:`TypedSlider.follow`) is shown in the field unless a text is being typed there. The range may
change (:meth:`TypedSlider.limit`: the time boxes span the run loaded). Units are those of the label (UI units: Hz,
kg, %, N, µm, m/s, s); the tab reads ``slider.value`` as before.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html
from tpm_viz.ui.fields import TypedBox
from tpm_viz.ui.widgets.typed import QUIET, Quantity, TypedField, TypedGroup
from tpm_viz.viserkit.core import widget_uuid

__all__ = ["FIELD_WIDTH", "SLIDER_HINT", "Setting", "TypedSlider", "add_sliders", "row_css"]

FIELD_WIDTH = "4.75rem"
"""Width of the typed field beside a slider (``1.5e-3``, ``5000`` and ``-50`` show whole)."""
SLIDER_HINT = "Drag, or type a number (1e3, 0,5 and the unit work); Enter applies (or stop typing for a moment)"
KEY = "value"


def row_css(slider: Any, field: Any) -> Html:
    """The style sheet of one row: the slider's form as a grid of two columns (the slider, then the typed field in
    :data:`FIELD_WIDTH`), viser's number box beside the slider hidden, the field's own label kept for screen readers
    only (the slider's label names the row). In viser 1.1.1 the slider's root has the handle's uuid as ``id``; a
    field is found by its label's ``for``."""
    try:
        s, f = widget_uuid(slider), widget_uuid(field)
    except AttributeError:  # a GUI without a page (a test's stand-in): nothing to style
        return Html("")
    form = f'form:has(label[for="{f}"])'
    row = f'div:has(> div > div > p > label[for="{f}"])'
    return Html(
        "<style>"
        f"{form} {{ display: grid; grid-template-columns: minmax(0, 1fr) {FIELD_WIDTH}; align-items: center; }}"
        f'[id="{s}"] ~ * {{ display: none !important; }}'
        f"{row} {{ padding-left: 0 !important; }}"
        f"{row} > div > div:first-child {{ position: absolute !important; width: 1px !important; height: 1px;"
        " padding: 0 !important; overflow: hidden; clip-path: inset(50%); white-space: nowrap; }"
        "</style>"
    )


class TypedSlider:
    """A slider and its typed field in one row of ``view``'s panel (inside the caller's container), the field's
    note under the row. ``quantity``: the field's name, UI unit and range (the slider's ``[lo, hi]``);
    ``on_change()`` runs under the hub's lock after a typed value is written into the slider."""

    def __init__(
        self,
        view: Any,
        label: str,
        quantity: Quantity,
        step: float,
        value: float,
        on_change: Callable[[], None] | None = None,
        hint: str | None = None,
    ) -> None:
        gui = view.gui
        self.view = view
        self.on_change = on_change
        self._following = False  # the app writes a followed value: the field keeps what is being typed there
        form = gui.add_form(None)
        with form:
            self.slider = gui.add_slider(label, quantity.lo, quantity.hi, step, float(value), hint=hint)
        group = TypedGroup({KEY: TypedField(quantity, float(value))}, quiet=QUIET)
        self.box = TypedBox(gui, group, {KEY: label}, {KEY: SLIDER_HINT}, form=form)
        self.field = self.box.inputs[KEY]
        self.css = gui.add_html(row_css(self.slider, self.field))
        view.typing.add(self.box, self._apply)
        self.slider.on_update(self._on_slider)

    @property
    def value(self) -> float:
        """The value in use (the slider's) [UI unit]."""
        return float(self.slider.value)

    def set(self, value: float) -> None:
        """Write ``value`` [UI unit] into the slider and the field (under the hub's lock)."""
        self.slider.value = float(value)
        self.box.show({KEY: float(value)}, force=True)

    def follow(self, value: float) -> None:
        """Write ``value`` [UI unit] into the slider as the app's reading of something that moves by itself (a
        playback's time): the field shows it unless a text is being typed there (under the hub's lock)."""
        self._following = True
        try:
            self.slider.value = float(value)
        finally:
            self._following = False

    def limit(self, lo: float, hi: float, step: float) -> None:
        """Accept ``[lo, hi]`` with ``step`` [UI units] from now on, in the slider and in the field (a run of
        another length was loaded); the value in use is kept inside."""
        self.box.group.limit(float(lo), float(hi))
        for name, value in (("min", lo), ("max", hi), ("step", step)):
            if getattr(self.slider, name) != float(value):
                setattr(self.slider, name, float(value))
        if not lo <= self.value <= hi:
            self.follow(min(max(self.value, float(lo)), float(hi)))

    def _apply(self, values: Mapping[str, float]) -> None:
        """A settled text (under the hub's lock): into the slider, then the tab's reaction; if that refuses it
        (:class:`~tpm_viz.TpmVizError`), the slider goes back to the value it had and the refusal is told."""
        before = self.value
        self.set(values[KEY])
        if self.on_change is not None:
            try:
                self.on_change()
            except TpmVizError:
                self.set(before)
                raise

    @guarded
    def _on_slider(self, event: Any) -> None:
        """The slider moved (a drag, or the app wrote it): the field shows its value."""
        with self.view.hub.locked():
            if self.view.closed:
                return
            self.box.show({KEY: float(self.slider.value)}, force=not self._following)
            self.box.draw(self.view.lang)
            if getattr(event, "client", None) is not None:
                self.view.client.flush()


@dataclass(frozen=True)
class Setting:
    """One setting of a tab: its label (UI unit in it), the field's quantity (name, unit, the slider's range), the
    slider's step and first value [UI unit], the slider's hint."""

    label: str
    quantity: Quantity
    step: float
    value: float
    hint: str | None = None


def add_sliders(
    view: Any,
    settings: Mapping[str, Setting],
    names: Iterable[str],
    on_change: Callable[[], None] | None,
    into: dict[str, TypedSlider],
) -> tuple[Any, ...]:
    """A :class:`TypedSlider` for each of ``names`` (in the caller's container), kept ``into`` by name; their
    sliders, in order (the handles the tab reads)."""
    names = tuple(names)
    for name in names:
        s = settings[name]
        into[name] = TypedSlider(view, s.label, s.quantity, s.step, s.value, on_change, s.hint)
    return tuple(into[name].slider for name in names)
