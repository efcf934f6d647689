"""The app's state transitions: raw widget values in, the next :class:`~.session.AppState` out. No viser.

One function per control of the panel. Each validates its raw inputs (:mod:`.validate`), calls a pure library
function (:mod:`tpm_viz.app.moves`, :mod:`tpm_viz.app.poses`, ``Params``, the trajectories) and returns a new
state; a refused input raises :class:`~tpm_viz.TpmVizError` with a one-line message and changes nothing. The
callbacks of :mod:`.client` are these functions plus a commit (the trajectory player's are in :mod:`.runs`), so
the property tests (``tests/test_reliability_app.py``) drive exactly the path a browser drives, without a browser.

Invariant (tested with generated inputs): from a valid state every function returns a valid state (finite pose
on the pose's branch, inside the stroke, clear of both singularities) or raises a ``TpmVizError``.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from tpm_viz.app.inputs import read_choice, read_number, read_params, read_vec2
from tpm_viz.app.moves import Move, drag_to, drive_to, switch_mode
from tpm_viz.app.poses import DEMO_KINDS, go_home, preset_pose, settle
from tpm_viz.app.readouts import LOAD_MODES, Load
from tpm_viz.app.state import AppState
from tpm_viz.core.params import Params
from tpm_viz.core.words import T

__all__ = [
    "MAX_ACCEL",
    "MAX_FORCE",
    "MAX_POSITION",
    "MAX_SPEED",
    "apply_params",
    "demo",
    "drag",
    "drive",
    "drive_both",
    "home",
    "move",
    "paper_params",
    "set_load",
    "switch",
]

MAX_POSITION = 10.0  # m, bound on typed positions (any pose beyond l_a is unreachable anyway)
MAX_FORCE = 1e5  # N, bound on typed forces
MAX_SPEED = 100.0  # m/s
MAX_ACCEL = 1e5  # m/s²
STROKE_SLACK = 1e-9
"""m: a typed actuator position this close to a stroke end is that end (the slack of the interactive moves on the
stroke, ``app.moves``: a pose may sit that far beyond an end, and its other actuator is typed as it is)."""


def _moved(state: AppState, move: Move) -> AppState:
    """``state`` at the move's pose, with its reason; a manual move leaves trajectory playback.

    A platform moved by hand is at rest: if its load was a trajectory's sample (``ṗ, p̈`` of the time last played),
    the load goes back to static (keeping the typed ``f_ext``), so that no stale acceleration is shown. A dynamic
    load typed by hand stays: it is the question being asked ("what forces at this velocity?")."""
    return state.at_rest(move.reason).replace(pose=move.pose)


def drag(state: AppState, position: object) -> AppState:
    """The gizmo at ``position`` (x, y[, z]) [m]: clamped inverse kinematics (z is ignored)."""
    try:
        xy = list(position)[:2]  # type: ignore[call-overload]  # anything a browser sent: TypeError is caught
    except TypeError:
        xy = position
    p_req = read_vec2(xy, T("platform position"), bound=MAX_POSITION)
    return _moved(state, drag_to(state.params, state.pose, p_req))


def move(state: AppState, p_mm: object) -> AppState:
    """The typed platform position ``p`` [mm]: clamped inverse kinematics."""
    p_req = read_vec2(p_mm, T("platform position p"), scale=1e-3, bound=MAX_POSITION)
    return _moved(state, drag_to(state.params, state.pose, p_req))


def drive(state: AppState, i: int, d_mm: object) -> AppState:
    """Actuator ``i`` (0 or 1) to ``d_mm`` [mm]: forward kinematics in the current assembly mode, clamped."""
    d_req = np.array(state.pose.d, dtype=float)
    d_req[i] = read_number(d_mm, f"d{i + 1}", scale=1e-3, lo=-MAX_POSITION, hi=MAX_POSITION)
    return _moved(state, drive_to(state.params, state.pose, d_req))


def drive_both(state: AppState, d_mm: object) -> AppState:
    """Both actuators to ``d_mm`` = (d1, d2) [mm] (a typed pair): forward kinematics in the current assembly mode,
    clamped like :func:`drive`. A value within :data:`STROKE_SLACK` of a stroke end is that end (the round trip
    m -> mm -> m of ``d = Δd`` may land an ulp beyond it)."""
    d_req = read_vec2(d_mm, T("actuator positions d"), scale=1e-3, bound=MAX_POSITION)
    stroke = state.params.stroke
    near = (d_req >= -STROKE_SLACK) & (d_req <= stroke + STROKE_SLACK)
    d_req = np.where(near, np.clip(d_req, 0.0, stroke), d_req)
    return _moved(state, drive_to(state.params, state.pose, d_req))


def switch(state: AppState) -> AppState:
    """The other assembly mode at the same actuator positions (or the reason why not)."""
    return _moved(state, switch_mode(state.params, state.pose))


def home(state: AppState) -> AppState:
    """The home pose ``p = 0`` (or the nearest valid pose)."""
    return _moved(state, go_home(state.params, state.pose))


def demo(state: AppState, kind: object) -> AppState:
    """A pose near an inverse singularity, the direct singularity or a stroke end (``DEMO_KINDS``)."""
    kind = read_choice(kind, T("demo"), DEMO_KINDS)
    return _moved(state, preset_pose(state.params, kind, near=state.pose))


def set_load(state: AppState, mode: object, f_ext: object, dp: object, ddp: object) -> AppState:
    """The load inputs; the same state object if nothing changed."""
    load = Load(
        mode=read_choice(mode, T("load"), LOAD_MODES),
        f_ext=tuple(read_vec2(f_ext, "f_ext", bound=MAX_FORCE)),
        dp=tuple(read_vec2(dp, T("platform velocity"), bound=MAX_SPEED)),
        ddp=tuple(read_vec2(ddp, T("platform acceleration"), bound=MAX_ACCEL)),
    )
    return state if load == state.load else state.replace(load=load, note="")


def apply_params(state: AppState, raw: Mapping[str, object]) -> AppState:
    """The parameter inputs (mm, kg): a new mechanism and the nearest valid pose on it."""
    return _new_params(state, read_params(state.params, raw))


def paper_params(state: AppState) -> AppState:
    """The paper's Tables 1-2 and the nearest valid pose on them."""
    return _new_params(state, Params.paper())


def _new_params(state: AppState, params: Params) -> AppState:
    """``params`` and the nearest valid pose on them. A run's sample is left (its ``ṗ, p̈`` belong to the old
    mechanism): the platform is at rest there, with the static load (:meth:`AppState.at_rest`)."""
    move = settle(params, state.pose)
    base = state if params == state.params else state.at_rest()
    return base.replace(params=params, pose=move.pose, note=move.reason)
