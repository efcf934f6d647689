"""Trajectory runs of each session: loading (in the background), playback, pause and seek.

A session (the shared mechanism or a private copy) has at most one loaded :class:`~tpm_viz.app.runs.Run`; every
tab on that session shows the same run, and playing it moves everybody's platform. No viser here: views are
reached through ``session.views`` (their ``teaching.player``), and state changes go through ``Hub.commit`` under
the hub's lock, like every other input.

- :meth:`RunHub.load`: checks and evaluates a trajectory in the :class:`~.worker.Worker` thread (closed form +
  Pinocchio, ~50 ms), outside the lock; a refused trajectory is reported to the tab that asked (only), and the
  last good run stays. A parameter change reloads the run for the new mechanism (:meth:`RunHub.follow_params`).
- :meth:`RunHub.play`: a thread steps the state along the run at ``speed`` x real time (~30 frames/s). Its frames
  are committed as *intermediate* frames (``dragging=True``: views may skip costly parts), the last one is not.
  Any other input to the session bumps ``session.play_token``, which stops it.
"""

from __future__ import annotations

import threading
import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from tpm_viz.app.moves import place
from tpm_viz.app.readouts import Load, reason
from tpm_viz.app.runs import Run, Source, build_run
from tpm_viz.app.state import AppState, TrajectorySample, run_note
from tpm_viz.classroom.session import Hub, Session, View
from tpm_viz.classroom.worker import Worker
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.words import Phrase, T

__all__ = ["FPS", "PlayerSession", "RunHub", "following", "sampled"]

FPS = 30.0
"""Frames per second of playback (wall clock)."""


def sampled(state: AppState, run: Run, t: float, settled: bool = False) -> AppState:
    """``state`` at time ``t`` [s] of ``run``: the pose at ``p(t)`` (working mode), ``ṗ(t), p̈(t)`` as a dynamic
    load; the pose and load unchanged, with the reason, if ``p(t)`` is not a valid pose. ``settled``: the platform
    stays there (paused, scrubbed, at the end): the note says whose load the forces are."""
    t, p, dp, ddp = run.state_at(t)
    move = place(state.params, state.pose, p)
    load = state.load if move.clamped else Load("dynamic", dp=tuple(dp), ddp=tuple(ddp))
    sample = TrajectorySample(run.source.kind, run.duration, t)
    note = move.reason or (run_note(T("the played trajectory"), t) if settled else "")
    return state.replace(pose=move.pose, load=load, trajectory=sample, note=note)


def following(state: AppState, run: Run | None) -> bool:
    """Whether ``state`` is a sample of ``run`` (not moved by hand since)."""
    return (
        run is not None
        and state.trajectory.kind == run.source.kind
        and abs(state.trajectory.duration - run.duration) < 1e-12
        and state.params == run.params
    )


@dataclass
class PlayerSession:
    """The player's data of one session (mutated under the hub's lock)."""

    run: Run | None = None
    loading: Source | None = None  # being computed
    uploaded: Source | None = None  # the last good upload
    extra: Source | None = None  # a demonstration's path
    previous: tuple[str, float] | None = None  # label and peak force [N] of the run before
    playing: bool = False
    token: int = -1  # session.play_token of the playing thread
    status: Phrase | str = ""  # why the run was dropped (rendered in each tab's language), or empty


class RunHub:
    """The player sessions of one hub."""

    def __init__(self, hub: Hub, worker: Worker) -> None:
        self.hub = hub
        self.worker = worker
        self._sessions: weakref.WeakKeyDictionary[Session, PlayerSession] = weakref.WeakKeyDictionary()

    def of(self, session: Session) -> PlayerSession:
        """The player data of ``session`` (created empty)."""
        ps = self._sessions.get(session)
        if ps is None:
            ps = self._sessions[session] = PlayerSession()
        return ps

    def adopt(self, session: Session, source: Session) -> None:
        """A private copy starts with the run of the session it was copied from (its player may already have been
        drawn once, empty, when the tab joined the copy: that empty player is replaced); the shared session never
        takes a copy's run."""
        mine = self._sessions.get(session)
        fresh = mine is None or (mine.run is None and mine.loading is None and mine.uploaded is None)
        if fresh and not session.shared and source in self._sessions and source is not session:
            old = self._sessions[source]
            self._sessions[session] = PlayerSession(run=old.run, uploaded=old.uploaded, extra=old.extra)

    # -- loading -----------------------------------------------------------------------------------------------
    def load(
        self,
        session: Session,
        source: Source,
        origin: View | None = None,
        on_done: Callable[[Run], None] | None = None,
        on_refused: Callable[[Exception], None] | None = None,
    ) -> None:
        """Compute ``source`` for the session's parameters in the background; then show its start and call
        ``on_done(run)``. A refused trajectory is told to ``on_refused(error)`` if given, else to the ``origin``
        tab's top line (if that tab is still open)."""
        with self.hub.lock:
            if origin is not None:
                self.hub.authorize(origin, session)  # presenter mode: before anything changes
            ps = self.of(session)
            ps.loading = source
            params = session.state.params
            self._refresh(session)
        reference = self.hub.reference

        def done(run: Any, error: Exception | None) -> None:
            with self.hub.lock:
                if ps.loading is not source:
                    return  # superseded by a newer request
                ps.loading = None
                if error is not None:
                    if origin is not None and not getattr(origin, "closed", False):
                        if on_refused is not None:
                            on_refused(error)
                        else:
                            origin.refuse(error)
                    self._refresh(session)
                    return
                if session.state.params != params:  # the mechanism changed meanwhile: again, for the new one
                    self.load(session, source, origin, on_done, on_refused)
                    return
                if ps.run is not None and ps.run.source is not source:
                    ps.previous = (ps.run.source.label, ps.run.peak)
                ps.run, ps.status = run, ""
                if source.kind == "csv":
                    ps.uploaded = source
                session.play_token += 1
                ps.playing = False
                self.hub.commit(session, sampled(session.state, run, 0.0, settled=True))
                if on_done is not None:
                    on_done(run)

        # the session takes turns in the worker's fair queue (it outlives its tabs: its run is never dropped)
        self.worker.submit(("run", id(session)), lambda: build_run(params, source, reference), done, tab=session)

    def follow_params(self, session: Session) -> None:
        """After a parameter change: recompute the run for the new mechanism (called under the lock by views)."""
        ps = self.of(session)
        run = ps.run
        if run is None or ps.loading is not None or run.params == session.state.params:
            return
        ps.loading = source = run.source
        params = session.state.params
        reference = self.hub.reference

        def done(new: Any, error: Exception | None) -> None:
            with self.hub.lock:
                if ps.loading is not source:
                    return
                ps.loading = None
                if error is not None:
                    ps.run, ps.status = None, Phrase("Trajectory unloaded: {why}", why=reason(error))
                elif session.state.params != params:
                    ps.run = new
                    self.follow_params(session)
                    return
                else:
                    ps.run, ps.status = new, ""
                self._refresh(session)

        self.worker.submit(("run", id(session)), lambda: build_run(params, source, reference), done, tab=session)

    def unload(self, session: Session, origin: View | None = None) -> None:
        """No trajectory any more (the pose stays)."""
        with self.hub.lock:
            if origin is not None:
                self.hub.authorize(origin, session)
            ps = self.of(session)
            session.play_token += 1
            ps.playing, ps.loading, ps.status = False, None, ""
            if ps.run is not None:
                ps.previous = (ps.run.source.label, ps.run.peak)
            ps.run = None
            self._refresh(session)

    # -- playback ----------------------------------------------------------------------------------------------
    def _usable(self, session: Session) -> Run:
        run = self.of(session).run
        if run is None:
            raise InputError(T("load a trajectory first (line, circle or your CSV)"))
        if run.params != session.state.params:
            raise InputError(T("the trajectory is being recomputed for the new parameters; try again in a moment"))
        return run

    def play(self, session: Session, speed: float, loop: bool = False, origin: View | None = None) -> None:
        """Play the session's run from the current sample (from the start if at the end or off the path)."""
        with self.hub.lock:
            if origin is not None:
                self.hub.authorize(origin, session)
            run = self._usable(session)
            ps = self.of(session)
            state = session.state
            t0 = state.trajectory.t if following(state, run) and state.trajectory.t < run.duration - 1e-9 else 0.0
            session.play_token += 1
            ps.token = token = session.play_token
            ps.playing = True
            self._refresh(session)
        threading.Thread(
            target=self._play,
            args=(session, run, t0, float(speed), bool(loop), token),
            name="tpm-viz-play",
            daemon=True,
        ).start()

    def _play(self, session: Session, run: Run, t0: float, speed: float, loop: bool, token: int) -> None:
        ps = self.of(session)
        tick0 = wall0 = time.monotonic()
        k = 0
        try:
            while True:
                t = t0 + speed * (time.monotonic() - wall0)
                with self.hub.lock:
                    if session.play_token != token or ps.run is not run or not session.views:
                        return
                    if t >= run.duration and loop:
                        t0, wall0 = 0.0, time.monotonic()
                    elif t >= run.duration:
                        ps.playing = False
                    state = sampled(session.state, run, min(t, run.duration), settled=not ps.playing)
                    if state.note:
                        ps.playing = False
                    try:
                        self.hub.commit(session, state, dragging=ps.playing)
                    except TpmVizError:  # a frame that cannot be drawn: stop there
                        ps.playing = False
                        return
                    if not ps.playing:
                        return
                k += 1
                time.sleep(max(0.0, tick0 + k / FPS - time.monotonic()))
        finally:
            with self.hub.lock:
                if ps.token == token and ps.playing:  # stopped by another input: say so in the panels
                    ps.playing = False
                    self._refresh(session)

    def pause(self, session: Session, origin: View | None = None) -> None:
        """Stop playing; the last frame is committed again in full (equations, charts)."""
        with self.hub.lock:
            if origin is not None:
                self.hub.authorize(origin, session)
            ps = self.of(session)
            session.play_token += 1
            ps.playing = False
            run = ps.run
            if run is not None and following(session.state, run):
                self.hub.commit(session, sampled(session.state, run, session.state.trajectory.t, settled=True))
            else:
                self._refresh(session)

    def seek(self, session: Session, t: float, origin: View | None = None) -> None:
        """Stop playing and show the run at ``t`` [s]."""
        with self.hub.lock:
            if origin is not None:
                self.hub.authorize(origin, session)
            run = self._usable(session)
            ps = self.of(session)
            session.play_token += 1
            ps.playing = False
            self.hub.commit(session, sampled(session.state, run, t, settled=True))

    def _refresh(self, session: Session) -> None:
        """Redraw the player panel of every view of ``session`` (status, buttons, charts)."""
        for view in list(session.views):
            view.run_changed()
