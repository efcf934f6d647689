"""Typed number fields (``tpm_viz.ui.widgets.typed``): what is read from a text, when it is applied, what the note says.

The expected values are written out by hand (``1e9`` kg is 1 000 000 000 kg, ``-100000`` mm is -100 m) or come from
the arithmetic of the test itself, never from the module under test. The keyboard is simulated with explicit times:
a person typing a number (keystrokes closer together than the quiet time), a clock that ticks between keystrokes
like the app's timer, and an "app" that applies what the group asks for and shows the value in use back.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.core.errors import InputError
from tpm_viz.ui.widgets.typed import (
    QUIET,
    Quantity,
    TypedField,
    TypedGroup,
    duration_note,
    force_note,
)

MASS = Quantity("m_p", "kg")
LENGTH = Quantity("p1", "mm", 1e-3, -10_000.0, 10_000.0)
DURATION = Quantity("T", "s", 1.0, 0.01, 100.0)


# -- reading a text -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("quantity", "text", "si"),
    [
        (MASS, "1e9", 1_000_000_000.0),  # was 19 kg with viser's number input
        (DURATION, "5e-1", 0.5),  # was T = 0.01 s
        (DURATION, "0,25", 0.25),  # a decimal comma
        (DURATION, " 2.5E-1 s ", 0.25),  # the field's unit after the number
        (LENGTH, "-100000", None),  # beyond ±10 m: refused, not clipped (below)
        (LENGTH, "-10000", -10.0),  # mm -> m
        (LENGTH, "\u221212,5", -0.0125),  # Unicode minus and a comma
        (MASS, "2,21", 2.21),
    ],
)
def test_a_text_reads_as_the_number_it_spells(quantity, text, si):
    if si is None:
        with pytest.raises(InputError, match=r"p1: -100000 mm is out of range; type a value from -10000 to 10000 mm"):
            quantity.read(text)
    else:
        assert quantity.read(text) == pytest.approx(si, rel=1e-15)


@pytest.mark.parametrize("text", ["abc", "", "1e", "-", "1,2.5", "nan", "inf", "1e999"])
def test_a_text_that_is_not_a_finite_number_is_one_line_naming_the_field(text):
    with pytest.raises(InputError) as info:
        MASS.read(text)
    message = str(info.value)
    assert message.startswith("m_p [kg]") and "\n" not in message


def test_range_messages_say_what_to_type():
    with pytest.raises(InputError, match=r"^T: 0\.001 s is out of range; type a value from 0\.01 to 100 s$"):
        DURATION.read("1e-3")
    with pytest.raises(InputError, match=r"^m: -1 kg is too small; type at least 0 kg$"):
        Quantity("m", "kg", lo=0.0).read("-1")
    with pytest.raises(InputError, match=r"^f: 2e\+06 N is too large; type at most 100000 N$"):
        Quantity("f", "N", hi=1e5).read("2e6")


@settings(max_examples=examples(300), deadline=None)
@given(
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e12, max_value=1e12),
    st.sampled_from([1.0, 1e-3]),
)
def test_the_text_of_a_value_reads_back_to_it(value, scale):
    """What a field shows for a value in use reads back to that value (to the six digits shown) and 'means' it."""
    quantity = Quantity("x", "mm" if scale == 1e-3 else "N", scale)
    si = value * scale
    text = quantity.text(si)
    assert not text.startswith("-0") or float(text) != 0.0  # never a negative zero
    back = quantity.read(text)
    assert math.isclose(back, si, rel_tol=5e-6, abs_tol=quantity.resolution * scale)
    assert quantity.means(text, si)
    assert quantity.shown(si) == f"{text} {quantity.unit}"


def test_a_text_means_a_value_to_the_digits_shown():
    assert DURATION.means("5e-1", 0.5) and DURATION.means("0,5", 0.5) and DURATION.means("0.5 s", 0.5)
    assert not DURATION.means("0.05", 0.5) and not DURATION.means("abc", 0.5)
    assert LENGTH.text(-3e-14) == "0" and LENGTH.text(0.2) == "200" and LENGTH.text(0.12345678) == "123.457"


# -- the keyboard, the clock and the app -----------------------------------------------------------------------------
class App:
    """Applies what a group asks for (recording every application) and shows the values in use back."""

    def __init__(self, group: TypedGroup, refuse=None) -> None:
        self.group = group
        self.applied: list[tuple[float, dict[str, float]]] = []
        self.refuse = refuse  # values -> a reason to refuse them, or None
        self.values = {key: f.value for key, f in group.fields.items()}

    def settle(self, now: float) -> None:
        """Enter, the Apply button or the quiet time: read, apply or refuse, show the values in use."""
        try:
            values = self.group.read()
        except InputError:
            return
        why = None if self.refuse is None else self.refuse(values)
        if why is not None:
            self.group.refused(why)
            self.group.show(self.values)
            return
        self.applied.append((now, values))
        self.values = dict(values)
        self.group.applied()
        self.group.show(self.values)

    def tick(self, now: float) -> None:
        """The app's timer: a quiet group applies itself once it is due."""
        if self.group.due(now):
            self.settle(now)


def _type(group: TypedGroup, app: App, key: str, text: str, start: float, gaps: list[float], ticks: list[float]):
    """Type ``text`` into ``key`` one character at a time (``gaps`` [s] between keystrokes), the app's clock
    ticking at ``ticks`` (fractions of each gap) in between; returns the time of the last keystroke."""
    now = start
    for k in range(1, len(text) + 1):
        if k > 1:
            gap = gaps[(k - 2) % len(gaps)]
            for frac in ticks:
                app.tick(now + frac * gap)
            now += gap
        group.typed(key, text[:k], now)
    return now


NUMBERS = st.one_of(
    st.floats(min_value=-9999, max_value=9999, allow_nan=False).map(lambda x: format(x, ".6g")),
    st.integers(min_value=-9999, max_value=9999).map(str),
    st.builds(lambda m, e: f"{m}e{e}", st.integers(1, 9), st.integers(-3, 3)),
    st.builds(lambda i, f: f"{i},{f}", st.integers(-999, 999), st.integers(0, 999)),
)


@settings(max_examples=examples(200), deadline=None)
@given(
    NUMBERS,
    st.lists(st.floats(min_value=0.02, max_value=QUIET * 0.95), min_size=1, max_size=6),
    st.lists(st.floats(min_value=0.0, max_value=1.0), max_size=4),
    st.lists(st.floats(min_value=0.0, max_value=5 * QUIET), max_size=6),
)
def test_no_prefix_is_ever_applied_and_the_settled_text_is_applied_once(text, gaps, ticks, later):
    """Someone types a number (keystrokes closer together than the quiet time) while the app's clock ticks: nothing
    is applied before the quiet time after the last keystroke, then exactly the whole text's value, once."""
    field = TypedField(LENGTH, 0.05)
    group = TypedGroup({"p1": field}, quiet=QUIET)
    app = App(group)
    last = _type(group, app, "p1", text, 10.0, gaps, ticks)
    assert app.applied == []  # never a prefix (``-1`` of ``-100000``)
    for dt in sorted(later):
        app.tick(last + dt)
    app.tick(last + QUIET)
    app.tick(last + 10 * QUIET)
    expected = float(text.replace(",", ".")) * 1e-3
    assert len(app.applied) == 1
    when, values = app.applied[0]
    assert when >= last + QUIET
    assert values["p1"] == pytest.approx(expected, rel=1e-12, abs=1e-18)
    assert LENGTH.means(field.text, app.values["p1"])  # the field shows the value in use
    assert group.lines(last + 10 * QUIET) == []  # nothing to say


@settings(max_examples=examples(100), deadline=None)
@given(
    st.text(alphabet="abx,.-e ", min_size=1, max_size=6).filter(lambda t: t.strip() not in ("",)),
    st.floats(min_value=-100, max_value=100, allow_nan=False),
)
def test_a_text_that_does_not_parse_is_never_applied_and_the_note_shows_the_value_in_use(text, start_mm):
    field = TypedField(LENGTH, start_mm * 1e-3)
    group = TypedGroup({"p1": field}, quiet=QUIET)
    app = App(group)
    try:
        LENGTH.read(text)
    except InputError:
        pass
    else:
        return  # e.g. "-.5e-" is refused but ".5" would not be: only refused texts here
    group.typed("p1", text, 0.0)
    for t in (0.5, QUIET, 3 * QUIET):
        app.tick(t)
    assert app.applied == []
    assert field.text == text  # the field keeps the text
    (line,) = group.lines(3 * QUIET)
    assert str(line).startswith("p1 [mm]") and str(line).endswith(f"(in use: {LENGTH.shown(start_mm * 1e-3)})")
    assert group.problem()


def test_typing_is_never_overwritten_by_the_app_and_a_later_value_is_shown_once_settled():
    field = TypedField(LENGTH, 0.0)
    group = TypedGroup({"p1": field}, quiet=QUIET)
    group.typed("p1", "12", 0.0)
    assert group.show({"p1": 0.030}) == {}  # another tab moved the platform meanwhile: the typing stays
    assert field.text == "12" and field.value == 0.030
    assert group.lines(0.5) == []  # nothing said while typing
    assert group.read() == {"p1": pytest.approx(0.012)}
    group.applied()
    assert group.show({"p1": 0.012}) == {}  # the value it asked for: the text stays as typed
    assert field.state == "clean" and group.lines(5.0) == []
    assert group.show({"p1": 0.0405}) == {"p1": "40.5"}  # a later value in use is written


def test_a_clamped_value_replaces_the_typed_text():
    """The app may use another value than the one asked for (a pose outside the stroke stops at its edge): the
    field then shows the value in use."""
    field = TypedField(LENGTH, 0.0)
    group = TypedGroup({"p1": field}, quiet=QUIET)
    group.typed("p1", "500", 0.0)
    assert group.read() == {"p1": pytest.approx(0.5)}
    group.applied()
    assert group.show({"p1": 0.2134567}) == {"p1": "213.457"}
    assert field.state == "clean"


def test_enter_settles_a_group_without_quiet_time_and_the_note_says_what_waits():
    a = TypedField(Quantity("a", "mm", 1e-3), 0.482)
    la = TypedField(Quantity("l_a", "mm", 1e-3), 0.260)
    group = TypedGroup({"a": a, "l_a": la})  # the Parameters: Enter or Apply only
    app = App(group)
    group.typed("l_a", "2,8e2", 0.0)
    for t in (1.0, 5.0, 60.0):
        app.tick(t)
    assert app.applied == []  # never by itself
    assert group.lines(0.5) == []
    (line,) = group.lines(QUIET)
    assert str(line) == "l_a: 280 mm typed, not applied yet (press Enter or Apply); in use: 260 mm"
    app.settle(61.0)  # Enter
    assert app.applied == [(61.0, {"a": 0.482, "l_a": pytest.approx(0.280)})]  # the clean field: its value in use
    assert group.lines(62.0) == []


def test_a_refusal_stays_until_a_later_success_and_the_fields_keep_their_texts():
    a = TypedField(Quantity("a", "mm", 1e-3), 0.482)
    b = TypedField(Quantity("b", "mm", 1e-3), 0.092)
    group = TypedGroup({"a": a, "b": b})
    app = App(group, refuse=lambda v: None if v["b"] > 0 else "b must be positive")
    group.typed("b", "-5", 0.0)
    group.typed("a", "500", 0.1)
    app.settle(1.0)
    assert app.applied == [] and a.text == "500" and b.text == "-5"
    assert [str(x) for x in group.lines(2.0)] == ["b must be positive", "a: in use 482 mm", "b: in use 92 mm"]
    assert group.problem()
    group.show({"a": 0.482, "b": 0.092})  # the tab is drawn again: nothing changes
    assert group.refusal == "b must be positive" and b.text == "-5"
    group.typed("b", "90", 3.0)
    assert group.refusal is not None  # typing alone does not clear it
    app.settle(4.0)
    assert app.applied == [(4.0, {"a": pytest.approx(0.5), "b": pytest.approx(0.09)})]
    assert group.refusal is None and group.lines(5.0) == [] and not group.problem()


def test_a_refusal_goes_when_new_values_are_forced_or_its_texts_are_replaced():
    b = TypedField(Quantity("b", "mm", 1e-3), 0.092)
    group = TypedGroup({"b": b})
    group.typed("b", "-5", 0.0)
    group.read()
    group.refused("b must be positive")
    assert group.show({"b": 0.092}, force=True) == {"b": "92"}  # e.g. the paper's values
    assert group.refusal is None and b.state == "clean"
    group.typed("b", "-5", 1.0)
    group.read()
    group.refused("b must be positive")
    assert group.show({"b": 0.1}) == {"b": "100"}  # another tab applied b = 100 mm: the text it was about is gone
    assert group.refusal is None


def test_a_group_with_a_bad_field_is_refused_as_a_whole_and_applies_nothing():
    x = TypedField(Quantity("f_x", "N"), 0.0)
    y = TypedField(Quantity("f_y", "N"), 0.0)
    group = TypedGroup({"x": x, "y": y}, quiet=QUIET)
    app = App(group)
    group.typed("x", "12", 0.0)
    group.typed("y", "1O", 0.2)  # a letter O
    app.tick(0.2 + QUIET)
    assert app.applied == [] and x.text == "12" and y.text == "1O"
    lines = [str(x) for x in group.lines(0.2 + QUIET)]
    assert lines == ["f_x: in use 0 N", "f_y [N] has an unknown unit 'O' (use N or kN) (in use: 0 N)"]
    group.typed("y", "10", 5.0)
    app.tick(5.0 + QUIET)
    assert app.applied == [(5.0 + QUIET, {"x": 12.0, "y": 10.0})]


def test_sync_turns_the_browser_texts_into_keystrokes():
    x = TypedField(Quantity("x", "N"), 1.0)
    y = TypedField(Quantity("y", "N"), 2.0)
    group = TypedGroup({"x": x, "y": y}, quiet=QUIET)
    assert not group.sync({"x": "1", "y": "2"}, 0.0)  # what the app wrote: no keystroke
    assert group.sync({"x": "1", "y": "25", "z": "3"}, 0.5) and y.state == "typing" and x.state == "clean"
    assert group.wake_at() == pytest.approx(0.5 + QUIET)
    assert not group.due(0.5 + QUIET - 1e-6) and group.due(0.5 + QUIET)
    assert TypedGroup({"x": TypedField(x.quantity, 0.0)}).wake_at() is None


# -- plausibility ---------------------------------------------------------------------------------------------------
def test_plausibility_notes_for_extreme_results():
    assert force_note(None) is None and force_note(177.0) is None and force_note(-1999.0) is None
    note = force_note(442_871.0)
    assert note is not None and str(note).startswith("note: |τ| = 4.43e+05 N is more than 10 times the usual 200 N")
    assert force_note(-2500.0) is not None
    assert duration_note(0.5) is None and duration_note(0.02) is None and duration_note(None) is None
    short = duration_note(0.01)
    assert short is not None and str(short).startswith("note: T = 10 ms is very short")
