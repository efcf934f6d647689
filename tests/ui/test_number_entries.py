"""Every number a person can type, in every tab, is read the one way (issue 40, item 1): the walk below lists every
input of a tab's built GUI (viser's handles, through :func:`tpm_viz.viserkit.probe.gui_inputs`, every tab of every
group, the deferred ones built, the floating panels and the lecturer's folders too) and checks each one:

- a text field is a field of one of the tab's typed boxes (:class:`~tpm_viz.ui.fields.TypedBox`, wired to the tab's
  :class:`~tpm_viz.ui.fields.Typing`: the one parser, the refusals and the "in use" note), or it is listed in
  :data:`NOT_TYPED_NUMBERS` with the reason;
- a slider has viser's own number box beside it hidden (a style sheet of the tab names its uuid), and its value can
  be typed in a typed field of the tab (a :class:`~tpm_viz.ui.widgets.typed_sliders.TypedSlider`'s, or the fields
  listed in :data:`SLIDER_FIELDS`);
- viser's number boxes, vector boxes and multi-sliders are not used at all (they drop what they cannot show);
- every other kind of input is one that takes no typed number (:data:`NO_NUMBER`); a kind not known here fails the
  test, so that a new input is looked at before it ships.

The second part types the four texts of the issue into every typed field of the tab: ``1e9``, ``abc`` and ``-5`` are
refused or applied by the field's quantity as :func:`tpm_viz.core.numbers.parse_quantity` reads them, and the note
under the field says so.
"""

from __future__ import annotations

import html

import pytest

from tests.support.fixtures import open_tab
from tests.support.protocol import wait_for
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.widgets.typed import TypedGroup
from tpm_viz.viserkit.probe import gui_inputs, widget_uuid

pytestmark = pytest.mark.slow

NO_NUMBER = {
    "GuiButtonHandle",
    "GuiButtonGroupHandle",
    "GuiCheckboxHandle",
    "GuiDropdownHandle",
    "GuiUploadButtonHandle",
}
"""Input kinds that take no typed number (a click, a choice, a file)."""
NEVER = {"GuiNumberHandle", "GuiVector2Handle", "GuiVector3Handle", "GuiMultiSliderHandle"}
"""viser's number inputs: ``1e9`` became ``19``, ``abc`` a blank, ``-5`` a silent clamp. None may be used."""
NOT_TYPED_NUMBERS = {
    "Share link": "the link to copy (the app writes it; nothing typed there is read)",
    "Presenter token": "a secret, not a number (masked, cleared once read)",
    "Waypoints x,y; x,y (mm)": "a list of points; each coordinate is read with parse_number "
    "(tests/app/test_planning_waypoints.py: 1e2, the Unicode minus, a refusal naming the waypoint)",
    "Answer": "an exercise's answer: a number with its unit, a pose, gains or a choice, read by the exercise's own "
    "reader (tests/app/test_exercise_answers.py: units, decimal commas, the Unicode minus, format errors)",
    "Class seed": "a whole number read by parse_seed (tests/app/test_exercise_variants.py)",
}
"""Text fields that are not typed numbers, by label, with the reason."""
SLIDER_FIELDS = {"Actuator d1 (mm)": "d1 (mm)", "Actuator d2 (mm)": "d2 (mm)"}
"""Sliders whose typed field is a field of another box of the tab (the Move tab's d1, d2), by label."""


def _style_sheets(view) -> list[str]:
    """The style sheets of the tab (the content of its HTML elements that hold a ``<style>``)."""
    return [
        e.content for e in view.gui._elements if isinstance(getattr(e, "content", None), str) and "<style>" in e.content
    ]


def _beside(view, inputs) -> dict[str, set[str]]:
    """uuid of each slider whose number box a style sheet of the tab hides (``[id="uuid"] ~ *``) -> the uuids of the
    inputs named in the same sheet (a typed slider's row names its field: ``label[for="uuid"]``)."""
    out: dict[str, set[str]] = {}
    for sheet in _style_sheets(view):
        named = {widget_uuid(h) for _t, h in inputs if f'"{widget_uuid(h)}"' in sheet}
        for _t, h in inputs:
            if f'[id="{widget_uuid(h)}"] ~ *' in sheet:
                out.setdefault(widget_uuid(h), set()).update(named - {widget_uuid(h)})
    return out


def _typed_fields(view) -> set[str]:
    """The uuids of every field of a typed box wired to the tab's typing."""
    return {widget_uuid(field) for box, _apply in view.typing.boxes for field in box.inputs.values()}


def _walk(view) -> list[str]:
    """Every problem of the tab's number inputs (empty: none), and the inputs seen, printed."""
    t = view.teaching
    _ = (t.player, t.control, t.planner, t.design)  # the deferred tabs, built now
    inputs = gui_inputs(view.client.gui)
    typed, beside = _typed_fields(view), _beside(view, inputs)
    by_label = {str(h.label): widget_uuid(h) for _tabs, h in inputs}
    problems, seen = [], 0
    for tabs, handle in inputs:
        kind, uuid, label = type(handle).__name__, widget_uuid(handle), str(handle.label)
        where = f"{' / '.join(tabs) or 'panel'}: {kind} {label!r}"
        seen += 1
        if tabs == ("?",):
            problems.append(f"{where} is in no tab the walk reached")
        if kind in NO_NUMBER:
            continue
        if kind in NEVER:
            problems.append(f"{where} is viser's number input: make it a typed field")
        elif kind == "GuiTextHandle":
            if uuid not in typed and label not in NOT_TYPED_NUMBERS:
                problems.append(f"{where} is a text field of no typed box and not listed")
        elif kind == "GuiSliderHandle":
            if uuid not in beside:
                problems.append(f"{where}: viser's number box beside it is shown")
            elif not beside[uuid] & typed and by_label.get(SLIDER_FIELDS.get(label, "")) not in typed:
                problems.append(f"{where} has no typed field of the tab's typing beside it (nor one listed)")
        else:
            problems.append(f"{where}: an input kind this test does not know; classify it here")
    assert seen > 100, seen  # the whole panel was walked
    print(f"{seen} inputs walked, {len(typed)} typed fields")
    return problems


@pytest.fixture
def presenter_app():
    """The app with a presenter token: a student's tab has the login panel's token field."""
    application = TpmApp(build_server("127.0.0.1", 0), presenter_token="rough-edges-token-0123456789")
    yield application
    application.stop()


def test_every_number_entry_of_every_tab_is_a_typed_field(connect):
    _client, view = connect()
    assert _walk(view) == []


def test_every_number_entry_of_a_students_tab_is_a_typed_field(presenter_app):
    opened = []
    try:
        _client, view = open_tab(presenter_app, opened)
        assert any(str(h.label) == "Presenter token" for _t, h in gui_inputs(view.client.gui))
        assert _walk(view) == []
    finally:
        for client in opened:
            client.close()


def _note(box) -> str:
    return html.unescape(str(box.note.handle.content))


def _in_use(group: TypedGroup, key: str) -> str:
    f = group.fields[key]
    return f.quantity.shown(f.value)


def test_the_issues_four_texts_in_every_typed_field(connect):
    """``2e-1``, ``1e9``, ``abc``, ``-5`` into every typed field of the tab that holds a number: each is applied
    when its quantity accepts it (the field's range) and refused under the field otherwise, with the value in use;
    what the quantity accepts is written out here from its range, not read from the note."""
    client, view = connect()
    t = view.teaching
    _ = (t.player, t.control, t.planner, t.design)
    checked = 0
    for box, _apply in list(view.typing.boxes):
        for key, field in box.inputs.items():
            if not box.note:
                continue
            q = box.group.fields[key].quantity
            client.set_value(field, "abc\n")
            unit = f" [{q.unit}]" if q.unit else ""
            want = f"{q.name}{unit}: 'abc' is not a number"
            wait_for(lambda b=box, w=want: w in _note(b), what=f"{q.name}: abc refused")
            assert f"(in use: {_in_use(box.group, key)})" in _note(box)
            if not q.lo <= 1e9 <= q.hi:
                client.set_value(field, "1e9\n")
                wait_for(
                    lambda b=box, n=q.name: f"{n}: 1e+09" in _note(b),
                    what=f"{q.name}: 1e9 refused",
                )
            checked += 1
            client.set_value(field, f"{q.text(box.group.fields[key].value)}\n")  # back to the value in use
    assert checked >= 30, checked
