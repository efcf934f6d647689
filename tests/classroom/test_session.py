"""Shared and private sessions, the lock, and validation of incoming widget values (tpm_viz.classroom.session)."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

from tpm_viz import InputError, Params
from tpm_viz.app.moves import Pose
from tpm_viz.app.state import AppState
from tpm_viz.classroom.session import Hub, read_number, read_vec2

P = Params.paper()


class FakeView:
    """Records what it was asked to draw."""

    def __init__(self) -> None:
        self.frames = []

    def render(self, frame, *, dragging: bool) -> None:
        self.frames.append((frame, dragging))


def test_read_number_validates_and_converts():
    assert read_number("12.5", "x", scale=1e-3) == pytest.approx(0.0125)
    assert read_number(7000.0, "d1", scale=1e-3, lo=0.0, hi=0.3) == pytest.approx(0.3)
    for bad in (math.nan, math.inf, "abc", None, True):
        with pytest.raises(InputError):
            read_number(bad, "x")


def test_read_vec2_validates():
    np.testing.assert_allclose(read_vec2((1, 2), "p", scale=1e-3), (0.001, 0.002))
    np.testing.assert_allclose(read_vec2((1e9, -1e9), "p", bound=5.0), (5.0, -5.0))
    for bad in ((1,), (1, 2, 3), (1, math.nan), 5):
        with pytest.raises(InputError):
            read_vec2(bad, "p")


def test_commit_draws_every_view_of_the_session_origin_first_and_computes_once():
    hub = Hub(AppState.initial(P))
    a, b = FakeView(), FakeView()
    hub.join(a, private=False)
    hub.join(b, private=False)
    new = hub.shared.state.replace(pose=Pose.working(P, (0.02, 0.0)))
    hub.commit(hub.shared, new, origin=b, dragging=True)
    frame_a, drag_a = a.frames[-1]
    frame_b, drag_b = b.frames[-1]
    assert frame_a is frame_b and frame_a.state is new  # one frame for both views
    assert drag_b and not drag_a  # only the dragging tab keeps its gizmo untouched


def test_private_copy_is_independent_and_shared_is_back():
    hub = Hub(AppState.initial(P))
    a, b = FakeView(), FakeView()
    hub.join(a, private=False)
    shared = hub.join(b, private=False)
    hub.leave(b, shared)
    private = hub.join(b, private=True, session=shared)
    assert private is not hub.shared and private.state is hub.shared.state
    hub.commit(private, private.state.replace(pose=Pose.working(P, (0.05, 0.0))), origin=b)
    assert hub.shared.state.pose.p[0] == 0.0
    assert len(a.frames) == 1  # the shared tab was not redrawn
    assert hub.shared_viewers() == 1


def test_commits_from_many_threads_are_serialised():
    hub = Hub(AppState.initial(P))
    inside = []
    overlaps = []

    class SlowView(FakeView):
        def render(self, frame, *, dragging: bool) -> None:
            inside.append(1)
            if len(inside) > 1:
                overlaps.append(1)
            threading.Event().wait(0.001)
            inside.pop()

    hub.join(SlowView(), private=False)

    def work(k: int) -> None:
        for j in range(10):
            with hub.lock:  # read-modify-write under the lock, as every callback does
                state = hub.shared.state
                hub.commit(hub.shared, state.replace(pose=Pose.working(P, (0.001 * ((k + j) % 5), 0.0))))

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert overlaps == []
    assert hub.shared.state.version == 40  # no update lost


def test_live_frames_show_the_pinocchio_forces_beside_the_closed_form():
    """Issue 3: both numbers side by side on every displayed frame, intermediate drag frames included."""
    import dataclasses

    from tpm_viz import inverse_dynamics, multibody
    from tpm_viz.app.readouts import Load

    hub = Hub(AppState.initial(Params.paper()), reference=multibody.inverse_dynamics)
    state = hub.shared.state
    state = dataclasses.replace(state, load=Load(mode="dynamic", dp=(0.3, -0.2), ddp=(4.0, 1.0)))
    for dragging in (True, False):
        shown = hub.frame(state, dragging=dragging).displayed_readout.forces
        closed = inverse_dynamics(state.params, state.pose.p, [0.3, -0.2], [4.0, 1.0])
        assert shown.tau == pytest.approx(closed, rel=1e-12)
        assert shown.tau_ref == pytest.approx(closed, rel=1e-9, abs=1e-9)
        assert "Pinocchio" in hub.frame(state, dragging=dragging).dashboard
