"""Honest panels without a browser (issue 25): a run's dynamic load never outlives the run.

A platform left on a run's sample (a control run, a plan, a played trajectory) shows that run's ``ṗ, p̈``; once it
is moved by hand, given new parameters, or saved and read back, it is at rest and the forces are the static load of
the pose shown. The expected forces come from the paper's closed form at zero velocity and acceleration
(:func:`tpm_viz.paper.dynamics.inverse_dynamics`), the forces shown from :func:`tpm_viz.app.readouts.evaluate` of
the state the app keeps.
"""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz.app import transitions
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState, TrajectorySample, run_note
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.core.params import Params
from tpm_viz.paper.dynamics import inverse_dynamics

P = Params.paper()
F_EXT = (4.0, -2.5)  # N, typed on the Forces tab before the run
RUN = Load("dynamic", f_ext=F_EXT, dp=(0.4, -0.2), ddp=(30.0, 15.0))  # the p̈ = (30, 15) m/s²


def _on_run(kind: str = "control#7f00", duration: float = 0.3, t: float = 0.1) -> AppState:
    pose = Pose.working(P, (0.03, 0.02))
    return AppState(P, pose, RUN, TrajectorySample(kind, duration, t), note=run_note("the control run", t))


def _tau_shown(state: AppState) -> np.ndarray:
    tau = evaluate(state.params, state.pose, state.load).forces.tau
    assert tau is not None
    return np.asarray(tau)


def _tau_static(state: AppState) -> np.ndarray:
    """The closed form at rest (ṗ = p̈ = 0) under the typed external force: the load of the pose shown."""
    return inverse_dynamics(state.params, state.pose.p, (0.0, 0.0), (0.0, 0.0), f_ext=F_EXT)


def test_the_phantom_is_a_real_dynamic_load_while_on_the_run():
    state = _on_run()
    moving = inverse_dynamics(P, state.pose.p, RUN.dp, RUN.ddp)
    np.testing.assert_allclose(_tau_shown(state), moving, rtol=1e-12)
    assert np.max(np.abs(moving - _tau_static(state))) > 10.0  # tens of newtons: the phantom the issue saw
    assert "the control run" in str(state.note) and "t = 0.100 s" in str(state.note)


@pytest.mark.parametrize(
    "leave",
    [
        lambda s: transitions.move(s, [float(v) * 1e3 for v in s.pose.p]),  # typed p: the same pose, at rest
        lambda s: transitions.drag(s, (*s.pose.p, 0.09)),
        lambda s: transitions.drive(s, 0, float(s.pose.d[0]) * 1e3),
        transitions.home,
        lambda s: transitions.apply_params(s, {"m_p": 1.9}),  # a new mechanism: the old run's p̈ is not its load
        lambda s: transitions.paper_params(transitions.apply_params(s, {"m_p": 1.9})),
    ],
    ids=["typed-p", "drag", "actuator", "home", "parameters", "paper-values"],
)
def test_leaving_the_run_shows_the_static_load_of_the_pose(leave):
    state = leave(_on_run(t=0.1))
    assert state.load == Load("static", f_ext=F_EXT) and state.trajectory.kind == "none"
    np.testing.assert_allclose(_tau_shown(state), _tau_static(state), rtol=1e-12, atol=1e-12)


def test_the_same_parameters_again_keep_the_run_and_its_load():
    state = _on_run()
    again = transitions.apply_params(state, {"m_p": P.m_p})
    assert again.load == RUN and again.trajectory == state.trajectory


def test_a_dynamic_load_typed_by_hand_is_a_question_and_stays():
    typed = AppState(P, Pose.working(P, (0.0, 0.0)), RUN)  # sample "none": typed on the Forces tab
    assert transitions.home(typed).load == RUN
    back = sessionfile.loads(sessionfile.dumps(Document(Saved(typed))))
    assert back.shared.state.load == RUN


def _round_trip(saved: Saved) -> AppState:
    """Save, then read back as a restarted server does (a new process reads the file)."""
    return sessionfile.loads(sessionfile.dumps(Document(saved))).shared.state


def test_a_control_runs_load_is_never_saved():
    state = _on_run()
    raw = sessionfile.encode_saved(Saved(state))
    assert raw["load"]["mode"] == "static" and raw["sample"]["kind"] == "none"
    back = _round_trip(Saved(state))
    assert back.load == Load("static", f_ext=F_EXT)
    np.testing.assert_allclose(back.pose.p, state.pose.p)
    np.testing.assert_allclose(_tau_shown(back), _tau_static(back), rtol=1e-12, atol=1e-12)


def test_a_played_trajectory_keeps_its_sample_to_seek_again_but_not_its_load():
    """The saved trajectory is reloaded after a restart and the player seeks to the saved time (recomputing ṗ, p̈
    from the run): until then, and if it cannot be, the platform is at rest."""
    source = Source.paper("line")
    state = _on_run(kind="line", duration=source.duration, t=0.05)
    back = _round_trip(Saved(state, source, 0.05))
    assert back.trajectory == state.trajectory and back.load == Load("static", f_ext=F_EXT)
    other = _round_trip(Saved(_on_run(kind="circle", duration=0.5), source, 0.05))  # not the saved trajectory's
    assert other.trajectory.kind == "none" and other.load.mode == "static"


def test_an_old_file_with_a_phantom_load_is_read_at_rest():
    """A file saved before this fix (a run's dynamic load in it) opens at rest: 122.6 N at rest never comes back."""
    text = sessionfile.dumps(Document(Saved(AppState(P, _on_run().pose))))
    doc = sessionfile.json.loads(text)
    doc["shared"]["load"] = {"mode": "dynamic", "f_ext": list(F_EXT), "dp": list(RUN.dp), "ddp": list(RUN.ddp)}
    doc["shared"]["sample"] = {"kind": "plan#1a2b", "duration": 0.4, "t": 0.2}
    back = sessionfile.loads(sessionfile.json.dumps(doc)).shared.state
    assert back.load == Load("static", f_ext=F_EXT) and back.trajectory.kind == "none"
    np.testing.assert_allclose(_tau_shown(back), _tau_static(back), rtol=1e-12, atol=1e-12)
