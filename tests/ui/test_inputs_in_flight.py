"""Every input a browser sends reaches the server in order and is never written over by a redraw, a deferred tab build
or a restore (issue 35, item 5), at the protocol level, at the worst moment, made deterministic: the test holds the
hub's lock (the tab's callback is then queued or waiting for it, its value stored by viser), sends the tab's inputs,
does what the server may do meanwhile (another tab's change of the shared mechanism, a deferred tab build, a
restore), then lets go. For each input kind: a slider, a dropdown, a checkbox (the own copy; a view option), a typed
box, a button (the last two were safe already; they are kept to stay so).

Before the fix a redraw wrote the state over the slider and the dropdown (their callbacks took the server's value for
an echo and the student's input was lost), a restore wrote the view options over an untick, and a callback read its
widget's latest value, not its event's (``d1 = 100``, *Work on my own copy*, ``d1 = 140``: 140 went to the shared
mechanism), or a later input of a callback already waiting overtook the inputs sent between.
"""

from __future__ import annotations

import concurrent.futures
import threading

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz.app import transitions
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.ui.continuity import restore
from tpm_viz.viserkit.core import widget_value
from tpm_viz.viserkit.inputs import pending
from tpm_viz.viserkit.limits import Gate, guard_of


@pytest.fixture
def two(app, connect):
    """Two tabs on the shared mechanism, the deferred tabs built only when asked for (inside the test's window)."""
    if app.services.later is not None:
        app.services.later.quiet = 3600.0
    a, view_a = connect()
    b, view_b = connect()
    return app, (a, view_a), (b, view_b)


def _stored(handle, value) -> None:
    """Wait until viser stored the browser's ``value`` (its callback is then queued, or waits for the lock)."""
    wait_for(lambda: widget_value(handle) == value, what=f"the browser's {value!r} stored")


def _applied(app, view, *handles) -> None:
    """Wait until the tab's callbacks have run (nothing queued, no input of these widgets in flight)."""
    gate = guard_of(app.server).gate
    wait_for(
        lambda: gate.pending(view.client.client_id) == 0 and not any(pending(h) for h in handles),
        what="the tab's callbacks",
    )


def _moved(app, view_b, p=(0.02, -0.01)) -> None:
    """Tab b moves the shared mechanism (under the lock the test holds): every shared tab is redrawn."""
    view_b.hub.commit(app.hub.shared, transitions.move(app.hub.shared.state, tuple(v * 1e3 for v in p)), origin=view_b)


def test_a_slider_input_is_applied_when_a_redraw_of_another_tabs_change_came_first(two):
    app, (a, view_a), (_b, view_b) = two
    slider = view_a.panel.d[0]
    with app.hub.lock:
        a.set_value(slider, 150.0)
        _stored(slider, 150.0)
        _moved(app, view_b)  # redraws tab a: the shared d1 is not 150 mm
        view_a.teaching.open("lab")  # and a deferred build of tab a meanwhile
        assert widget_value(slider) == 150.0  # not written over
    _applied(app, view_a, slider)
    assert app.hub.shared.state.pose.d[0] == pytest.approx(0.150, abs=1e-9)  # applied after b's move


def test_a_dropdown_input_is_applied_when_a_refusal_re_syncs_the_panel(two):
    """The load dropdown changed while another input of the same tab is refused: the refusal writes the whole panel
    again from the state (the static load), over the dropdown's new value."""
    app, (a, view_a), _b = two
    mode = view_a.panel.load_mode
    with app.hub.lock:
        a.set_value(mode, "dynamic")
        _stored(mode.handle, "dynamic")
        view_a.refuse("another input of this tab was refused")  # its re-sync: forget, then draw the state
        assert widget_value(mode.handle) == "dynamic"
    _applied(app, view_a, mode)
    assert app.hub.shared.state.load.mode == "dynamic"


def test_an_untick_is_not_written_over_by_a_restore(two):
    app, (a, view_a), _b = two
    box = view_a.panel.show_toggles["forces"]
    assert widget_value(box) is True
    with app.hub.lock:
        a.set_value(box, False)
        _stored(box, False)
        saved = Saved(app.hub.shared.state, show={"forces": True})
        restore(view_a, saved, private=False)  # a restore (a share link, Restore my own copy) meanwhile
    _applied(app, view_a, box)
    assert widget_value(box) is False and view_a.scene.show["forces"] is False


def test_inputs_are_applied_in_the_order_sent_own_copy_then_d1(two):
    """d2 (its callback waits for the lock), d1 = 100, *Work on my own copy*, d1 = 140: d1 = 100 on the shared
    mechanism, then the own copy, then d1 = 140 on the own copy (a later d1 does not overtake the tick)."""
    app, (a, view_a), (_b, view_b) = two
    d1, d2, own = view_a.panel.d[0], view_a.panel.d[1], view_a.panel.own_copy
    gate = guard_of(app.server).gate
    with app.hub.lock:
        a.set_value(d2, 120.0)
        wait_for(lambda: gate.pending(view_a.client.client_id) == 1, what="d2's callback running")
        a.set_value(d1, 100.0)
        a.set_value(own, True)
        a.set_value(d1, 140.0)
        _stored(d1, 140.0)
        _stored(own.handle, True)
        view_a.teaching.open("teach")  # a deferred build meanwhile
        _moved(app, view_b, (0.0, 0.0))  # and a redraw
    _applied(app, view_a, d1, d2, own)
    assert not view_a.session.shared
    assert view_a.session.state.pose.d[0] == pytest.approx(0.140, abs=1e-9)
    assert app.hub.shared.state.pose.d[0] == pytest.approx(0.100, abs=1e-9)  # applied before the tick


def test_a_typed_box_and_a_button_are_applied_after_a_redraw(two):
    app, (a, view_a), (_b, view_b) = two
    box = view_a.panel.d_typed
    field = box.inputs["d1"]
    with app.hub.lock:
        a.set_value(field, "120")
        _stored(field, "120")
        _moved(app, view_b)  # rewrites the typed d1 of tab a's page to b's move
        assert widget_value(field) == "120"
        a.enter(box)
    _applied(app, view_a, field)
    wait_for(lambda: app.hub.shared.state.pose.d[0] == pytest.approx(0.120, abs=1e-9), what="d1 typed, then Enter")
    with app.hub.lock:
        a.click(view_a.panel.home)
        wait_for(lambda: guard_of(app.server).gate.pending(view_a.client.client_id), what="Home queued")
        _moved(app, view_b)
    _applied(app, view_a)
    wait_for(lambda: np.allclose(app.hub.shared.state.pose.p, 0.0, atol=1e-12), what="Home applied after b's move")


class _Event:
    def __init__(self, client_id: int, n: int) -> None:
        self.client_id, self.n = client_id, n


def test_the_gate_runs_a_tabs_calls_in_the_order_sent_merging_only_repeats_in_a_row():
    """While a call runs: d1, own copy, d1, d1 -> d1, own copy, d1 (the last two merged: latest wins); the later d1
    never overtakes the own copy (it did, merged into the first d1's place)."""
    pool = concurrent.futures.ThreadPoolExecutor(2)
    gate = Gate(pool.submit, max_per_tab=8)
    release, ran = threading.Event(), []

    def slow(event) -> None:
        release.wait(10.0)
        ran.append(("slow", event.n))

    def d1(event) -> None:
        ran.append(("d1", event.n))

    def own(event) -> None:
        ran.append(("own", event.n))

    gate.submit(slow, _Event(1, 0))
    for fn, n in ((d1, 1), (own, 2), (d1, 3), (d1, 4)):
        gate.submit(fn, _Event(1, n))
    assert gate.pending(1) == 1 + 3 and gate.merged == 1
    release.set()
    wait_for(lambda: gate.pending(1) == 0, what="the calls to run")
    pool.shutdown(wait=True)
    assert ran == [("slow", 0), ("d1", 1), ("own", 2), ("d1", 4)]
