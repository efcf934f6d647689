"""One browser tab: its scene and panel, and the callbacks that turn its inputs into state changes.

Every callback has the same shape: under the hub's lock, read the widget's *current* value, validate it, call a
pure library function (:mod:`tpm_viz.interaction`, :mod:`tpm_viz.poses`, ``Params.replace``, trajectories),
and commit the new state, which redraws every view of the session. Events that the server caused itself (a
value written by :meth:`Panel.show`, which viser echoes synchronously with ``client=None``) are ignored.
A refused input is reported to this tab only; the last good state stays.
"""

from __future__ import annotations

import asyncio
import functools
import threading
import time
import traceback

import numpy as np
import viser

from .. import meshes
from ..errors import TpmVizError
from ..interaction import Move, drag_to, drive_to, place, switch_mode
from ..params import PARAM_INFO, Params
from ..poses import DEMO_KINDS, demo_pose, home_pose, settle
from ..readouts import LOAD_MODES, Load
from ..trajectories import circle_state, line_state
from .frame import Frame
from .panels import Panel
from .scene import MechanismScene, camera_pose
from .session import TRAJECTORY_KINDS, AppState, Hub, Session, TrajectorySample, read_number, read_vec2

__all__ = ["ClientView"]

PLAY_SECONDS = 4.0  # s, wall-clock length of a played trajectory (slow motion)
PLAY_FRAMES = 100
MAX_FORCE = 1e5  # N, bound on typed forces
MAX_SPEED = 100.0  # m/s
MAX_ACCEL = 1e5  # m/s²


def _sampled(state: AppState, sample: TrajectorySample) -> AppState:
    """``state`` driven by a trajectory sample: the pose at ``p(t)`` (working mode) and ``ṗ(t), p̈(t)`` as a
    dynamic load; unchanged pose and load, with the reason, if ``p(t)`` is not valid for these parameters."""
    if sample.kind == "none":
        return state.replace(trajectory=sample, note="")
    p, dp, ddp = (line_state if sample.kind == "line" else circle_state)(sample.t, sample.duration)
    move = place(state.params, state.pose, p)
    load = state.load if move.clamped else Load("dynamic", dp=tuple(dp), ddp=tuple(ddp))
    return state.replace(pose=move.pose, load=load, trajectory=sample, note=move.reason)


def _size(params: Params) -> float:
    """Side of the base plate [m]: what the camera frames."""
    lo, hi = meshes.base_extent(params)
    return hi - lo


def _report(future) -> None:
    """Print the traceback of a failed background drain (it would be lost otherwise)."""
    if not future.cancelled() and future.exception() is not None:
        traceback.print_exception(future.exception())


def _callback(method):
    """Run a handler under the hub's lock; ignore server-side echoes; report refused input to this tab."""

    @functools.wraps(method)
    def wrapper(self: ClientView, event, *args) -> None:
        if getattr(event, "client", None) is None:
            return
        with self.hub.lock:
            if self.closed:
                return
            try:
                method(self, event, *args)
            except TpmVizError as exc:
                self.refuse(str(exc))

    return wrapper


class ClientView:
    """The scene, panel and callbacks of one connected browser tab."""

    def __init__(self, client: viser.ClientHandle, hub: Hub) -> None:
        self.client = client
        self.hub = hub
        self.closed = False
        self._pending_drags: list[tuple[str, np.ndarray]] = []
        with hub.lock:
            state = hub.shared.state
            self.scene = MechanismScene(client.scene, state.params)
            self.panel = Panel(client.gui, state)
            self._wire()
            self.frame_camera(state.params)
            self.session: Session = hub.join(self, private=False)

    # -- drawing -------------------------------------------------------------------------------------------
    def render(self, frame: Frame, *, dragging: bool = False) -> None:
        """Draw ``frame`` in this tab (called by the hub under its lock) and flush at once."""
        if self.closed:
            return
        with self.client.atomic():
            self.scene.update(frame, dragging=dragging)
            self.panel.show(frame)
            size = _size(frame.state.params)
            if not 0.8 < size / self._framed_size < 1.25:  # the mechanism grew or shrank a lot: reframe
                self.frame_camera(frame.state.params)
        self.client.flush()

    def refuse(self, text: str) -> None:
        """Tell this tab (only) that its input was refused; the mechanism keeps its last good state."""
        self.panel.tell(f"Refused: {text}")
        self.client.add_notification("Input refused", text, color="red", auto_close_seconds=8.0)
        self.client.flush()

    def frame_camera(self, params: Params) -> None:
        """Point this tab's camera at the whole mechanism."""
        self._framed_size = _size(params)
        position, look_at = camera_pose(params)
        self.client.camera.position = position
        self.client.camera.look_at = look_at

    def close(self) -> None:
        """The tab went away: stop drawing and leave the session."""
        with self.hub.lock:
            self.closed = True
            self.hub.leave(self, self.session)

    def set_class_info(self, text: str) -> None:
        """The classroom line of the *Class & view* tab."""
        self.panel.class_info.content = text

    # -- commits -------------------------------------------------------------------------------------------
    def _commit(self, state: AppState, dragging: bool = False) -> None:
        self.panel.tell("")
        self.session.play_token += 1  # any input stops a playing trajectory
        self.hub.commit(self.session, state, origin=self, dragging=dragging)

    def _move(self, move: Move, **changes) -> None:
        state = self.session.state
        changes.setdefault("trajectory", TrajectorySample("none", state.trajectory.duration, 0.0))
        self._commit(state.replace(pose=move.pose, note=move.reason, **changes))

    # -- wiring --------------------------------------------------------------------------------------------
    def _wire(self) -> None:
        panel, scene = self.panel, self.scene
        scene.gizmo.on_update(self._on_drag)
        panel.p.on_update(self._on_p)
        for i, slider in enumerate(panel.d):
            slider.on_update(lambda event, i=i: self._on_d(event, i))
        panel.switch_mode.on_click(self._on_switch_mode)
        panel.home.on_click(self._on_home)
        for kind in DEMO_KINDS:
            panel.demo[kind].on_click(lambda event, kind=kind: self._on_demo(event, kind))
        for handle in (panel.load_mode, panel.f_ext, panel.dp, panel.ddp):
            handle.on_update(self._on_load)
        for handle in (panel.trajectory, panel.duration, panel.time):
            handle.on_update(self._on_trajectory)
        panel.play.on_click(self._on_play)
        panel.apply.on_click(self._on_apply)
        panel.paper.on_click(self._on_paper)
        panel.own_copy.on_update(self._on_own_copy)
        for what, handle in panel.show_toggles.items():
            handle.on_update(lambda event, what=what: self._on_show(event, what))
        panel.frame_camera.on_click(self._on_frame)

    async def _on_drag(self, event) -> None:
        """Gizmo events, in arrival order on the event loop: keep a snapshot, hand the work to the pool."""
        self._pending_drags.append((event.phase, np.array(event.target.position, dtype=float)))
        asyncio.get_running_loop().run_in_executor(None, self._drain_drags).add_done_callback(_report)

    def _drain_drags(self) -> None:
        """Apply the latest pending gizmo position (latest value wins); ``end`` writes the gizmo back."""
        with self.hub.lock:
            if self.closed or not self._pending_drags:
                return
            phase, position = self._pending_drags[-1]
            self._pending_drags.clear()
            try:
                p_req = read_vec2(position[:2], "platform position")
            except TpmVizError as exc:
                self.refuse(str(exc))
                return
            state = self.session.state
            move = drag_to(state.params, state.pose, p_req)
            self.panel.tell("")
            sample = TrajectorySample("none", state.trajectory.duration)
            changed = state.replace(pose=move.pose, note=move.reason, trajectory=sample)
            self._commit(changed, dragging=phase != "end")

    @_callback
    def _on_p(self, event) -> None:
        if self.panel.is_echo(self.panel.p):
            return
        p_req = read_vec2(self.panel.p.value, "platform position p", scale=1e-3, bound=10.0)
        state = self.session.state
        self._move(drag_to(state.params, state.pose, p_req))

    @_callback
    def _on_d(self, event, i: int) -> None:
        if self.panel.is_echo(self.panel.d[i]):
            return
        state = self.session.state
        d_req = np.array(state.pose.d, dtype=float)
        d_req[i] = read_number(self.panel.d[i].value, f"d{i + 1}", scale=1e-3, lo=-10.0, hi=10.0)
        self._move(drive_to(state.params, state.pose, d_req))

    @_callback
    def _on_switch_mode(self, event) -> None:
        state = self.session.state
        self._move(switch_mode(state.params, state.pose))

    @_callback
    def _on_home(self, event) -> None:
        state = self.session.state
        self._move(Move(home_pose(state.params)))

    @_callback
    def _on_demo(self, event, kind: str) -> None:
        state = self.session.state
        self._move(demo_pose(state.params, kind, near=state.pose.p))

    @_callback
    def _on_load(self, event) -> None:
        panel = self.panel
        if panel.is_echo(panel.load_mode, panel.f_ext, panel.dp, panel.ddp):
            return
        mode = panel.load_mode.value if panel.load_mode.value in LOAD_MODES else "static"
        load = Load(
            mode=mode,
            f_ext=tuple(read_vec2(panel.f_ext.value, "f_ext", bound=MAX_FORCE)),
            dp=tuple(read_vec2(panel.dp.value, "platform velocity", bound=MAX_SPEED)),
            ddp=tuple(read_vec2(panel.ddp.value, "platform acceleration", bound=MAX_ACCEL)),
        )
        state = self.session.state
        if load != state.load:
            self._commit(state.replace(load=load, note=""))

    @_callback
    def _on_trajectory(self, event) -> None:
        panel = self.panel
        if panel.is_echo(panel.trajectory, panel.duration, panel.time):
            return
        kind = panel.trajectory.value if panel.trajectory.value in TRAJECTORY_KINDS else "none"
        duration = read_number(panel.duration.value, "duration T", lo=0.01, hi=100.0)
        t = read_number(panel.time.value, "time t", lo=0.0, hi=duration)
        self._commit(_sampled(self.session.state, TrajectorySample(kind, duration, t)))

    @_callback
    def _on_play(self, event) -> None:
        """Play the selected trajectory (the line if none) in slow motion, in a background thread."""
        session = self.session
        traj = session.state.trajectory
        kind = traj.kind if traj.kind != "none" else "line"
        duration = traj.duration
        session.play_token += 1
        threading.Thread(
            target=self._play, args=(session, kind, duration, session.play_token), name="tpm-viz-play", daemon=True
        ).start()

    def _play(self, session: Session, kind: str, duration: float, token: int) -> None:
        """Step through ``PLAY_FRAMES`` samples over ``PLAY_SECONDS``; any other input stops it."""
        for k in range(PLAY_FRAMES + 1):
            if k:
                time.sleep(PLAY_SECONDS / PLAY_FRAMES)
            with self.hub.lock:
                if session.play_token != token or not session.views:
                    return
                state = _sampled(session.state, TrajectorySample(kind, duration, duration * k / PLAY_FRAMES))
                self.hub.commit(session, state)
                if state.note:
                    return

    @_callback
    def _on_apply(self, event) -> None:
        state = self.session.state
        raw = self.panel.read_params()
        try:
            changes = {
                name: read_number(value, name, scale=1.0 / PARAM_INFO[name]["ui_scale"]) for name, value in raw.items()
            }
            params = state.params.replace(**changes)
            move = settle(params, state.pose)
        except TpmVizError:
            self.panel.show_params(state.params)  # revert the inputs to the last good mechanism
            raise
        self._commit(state.replace(params=params, pose=move.pose, note=move.reason))

    @_callback
    def _on_paper(self, event) -> None:
        state = self.session.state
        params = Params.paper()
        move = settle(params, state.pose)
        self._commit(state.replace(params=params, pose=move.pose, note=move.reason))

    @_callback
    def _on_own_copy(self, event) -> None:
        private = bool(self.panel.own_copy.value)
        if private == (not self.session.shared):
            return
        old = self.session
        self.hub.leave(self, old)
        self.session = self.hub.join(self, private=private, session=old)
        self.hub.membership_changed()

    def _on_show(self, event, what: str) -> None:
        if getattr(event, "client", None) is None:
            return
        with self.hub.lock:
            self.scene.set_visible(what, bool(self.panel.show_toggles[what].value))
            if self.session.frame is not None:
                self.render(self.session.frame)

    def _on_frame(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        self.frame_camera(self.session.state.params)
        self.client.flush()
