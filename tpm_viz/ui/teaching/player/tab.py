"""The trajectory player of one tab: choose a trajectory (the paper's line or circle, your CSV, a demo's path),
play / pause / scrub it at 0.01x-1x, watch the path being traced and the charts' time marker move, export the
run as CSV and the force plot as PNG.

The run and the playback belong to the session (:mod:`tpm_viz.classroom.runhub`); this view only reads widgets, calls
:class:`~tpm_viz.classroom.runhub.RunHub` and draws. The duration is a typed field
(:class:`~tpm_viz.ui.fields.TypedBox`: ``5e-1`` and ``0,5`` are 0.5 s; applied on Enter or after a quiet time; the value
in use and the plausibility notes under it). So is the time: a slider with a typed field
(:class:`~tpm_viz.ui.widgets.typed_sliders.TypedSlider`, a time from 0 to the run's duration: ``2e-1`` is 0.2 s,
``abc`` and ``-5`` are refused under it with the time in use). The player's refusals (upload, choice, playback,
exports) are shown under the upload button, to that tab only, and the next success clears them. During playback the
charts and the trace are refreshed at most :data:`CHART_HZ` times a second (the kinematic charts every other time),
with the time slider and the summary; the 3D platform moves at every frame, and the last frame is always drawn in full.
"""

from __future__ import annotations

import time

import numpy as np
import viser

from tpm_viz.app.inputs import MAX_UPLOAD_BYTES, read_number, read_upload
from tpm_viz.app.runs import MAX_DURATION, MIN_DURATION, Source
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.runhub import RunHub, following
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.csvio import format_columns
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.markup import Markdown
from tpm_viz.core.words import Phrase, T
from tpm_viz.drawing.figures import force_plot_png, force_plot_svg
from tpm_viz.paper.trajectories import DEFAULT_DURATIONS
from tpm_viz.ui.fields import Note, TypedBox
from tpm_viz.ui.share import ShareBox
from tpm_viz.ui.teaching.player.charts import Charts
from tpm_viz.ui.teaching.player.text import summary_html
from tpm_viz.ui.teaching.player.trace import PathTrace
from tpm_viz.ui.teaching.stage import PLAYER, bring, front, show
from tpm_viz.ui.widgets.typed import QUIET, Quantity, TypedField, TypedGroup, duration_note, force_note
from tpm_viz.ui.widgets.typed_sliders import TypedSlider
from tpm_viz.ui.worded import TabGui, put, stored

__all__ = ["CHART_HZ", "SPEEDS", "PlayerView", "time_quantity"]

SPEEDS = {"0.01×": 0.01, "0.02×": 0.02, "0.05×": 0.05, "0.1×": 0.1, "0.2×": 0.2, "0.5×": 0.5, "1× (real time)": 1.0}
"""Playback speeds (the paper's motions last 0.2-0.5 s)."""
CHART_HZ = 4.0
NONE = "none"
PAPER = {"line (Fig. 4)": "line", "circle (Fig. 5)": "circle"}
_UNSET = object()


def _internal_error(owner, exc: Exception) -> None:
    """The guard's report to the tab whose callback failed (the traceback is in the server log)."""
    owner.view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__), resync=False)


def time_quantity(duration: float) -> Quantity:
    """What a *Time t (s)* box accepts: a time from 0 to the run's ``duration`` [s] (the Player, the Control lab)."""
    return Quantity("t", "s", 1.0, 0.0, float(duration))


def _option(source: Source) -> str:
    if source.kind in ("line", "circle"):
        return next(label for label, kind in PAPER.items() if kind == source.kind)
    prefix = "your CSV: " if source.kind == "csv" else "demo: "
    return prefix + source.label.split(", T =")[0]


class PlayerView:
    """Player widgets and scene nodes of one tab."""

    def __init__(self, view, runs: RunHub) -> None:
        self.view = view
        self.runs = runs
        self._run = None
        self._written: dict[int, object] = {}
        self._last_push = 0.0
        self._pushes = 0
        self._shown_t = _UNSET
        self.trace = PathTrace(view.client.scene)
        self._in_front = True  # the path and trace are shown (another run's drawing is in front: hidden)
        self._frame: Snapshot | None = None

    def build(self, gui: TabGui) -> None:
        """The *Player* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            Markdown(
                "Play a trajectory: the platform follows it, leaves a trace, and the charts mark the current time. "
                "Your own CSV needs the columns `t,p1,p2` (s, m), at least 4 rows, at most "
                f"{MAX_UPLOAD_BYTES / 2**20:g} MiB; it must stay inside the stroke and clear of the singularities."
            )
        )
        self.choice = gui.add_dropdown("Trajectory", (NONE, *PAPER), initial_value=NONE)
        quantity = Quantity("T", "s", 1.0, MIN_DURATION, MAX_DURATION)
        self.duration = TypedBox(
            gui,
            TypedGroup({"T": TypedField(quantity, DEFAULT_DURATIONS["line"])}, quiet=QUIET),
            {"T": "Duration T (s)"},
            {"T": "Of the paper's line or circle; 5e-1 and 0,5 work; Enter applies (or stop typing for a moment)"},
        )
        self.upload = gui.add_upload_button(
            "Upload CSV (t, p1, p2 in s, m)", icon=viser.Icon.UPLOAD, mime_type=".csv,text/csv,text/plain"
        )
        self.note = Note(gui)
        """Refusals of the player's controls (upload, choice, playback, exports), under the upload button."""
        self.controls = gui.add_button_group("Playback", ("Play", "Pause", "To start"))
        self.time_typed = TypedSlider(self.view, "Time t (s)", time_quantity(0.2), 0.001, 0.0, self._typed_time)
        self.time = self.time_typed.slider
        self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.05×")
        self.loop = gui.add_checkbox("Loop", False)
        self.summary = gui.add_html("")
        self.charts = Charts(gui)
        self.export_csv = gui.add_button("Download the run (CSV)", icon=viser.Icon.DOWNLOAD, color="gray")
        self.export_png = gui.add_button("Download the force plot (PNG)", icon=viser.Icon.PHOTO, color="gray")
        self.export_svg = gui.add_button("Download the force plot (SVG)", icon=viser.Icon.VECTOR, color="gray")
        self.share = ShareBox(self.view, gui)  # *Copy share link* (ui/share.py)
        self.charts.show_run(None, None)
        self.choice.on_update(self._on_choice)
        self.view.typing.add(self.duration, self._apply_duration)
        self.upload.on_upload(self._on_upload)
        self.controls.on_click(self._on_controls)
        self.time.on_update(self._on_time)
        self.export_csv.on_click(self._on_export_csv)
        self.export_png.on_click(self._on_export_png)
        self.export_svg.on_click(self._on_export_svg)

    # -- helpers -------------------------------------------------------------------------------------------
    @property
    def session(self):
        return self.view.session

    def _put(self, handle, value) -> None:
        """Write a widget value and remember it (see :meth:`_is_echo`), never over an input on its way
        (:mod:`tpm_viz.viserkit.inputs`)."""
        if stored(handle) == value or put(handle, value):
            self._written[id(handle)] = stored(handle)

    def _is_echo(self, *handles) -> bool:
        return all(self._written.get(id(h), _UNSET) == h.value for h in handles)

    def _guard(self, event, fn, *args) -> None:
        """Run ``fn`` for a user event (not a server echo); refused input is told to this tab only, under the upload
        button; a success clears an earlier refusal there (a load: once it is computed)."""
        if getattr(event, "client", None) is None or getattr(self.view, "closed", False) or self.session is None:
            return
        bring(self.view, PLAYER, redraw=True)
        try:
            fn(*args)
        except TpmVizError as exc:
            self._refused(exc)
        else:
            with self.view.hub.locked():
                self.note.tell(None, self.view.lang)

    def _refused(self, error: Exception) -> None:
        """Tell this tab why its player input was refused, under the upload button (any thread)."""
        with self.view.hub.locked():
            if not getattr(self.view, "closed", False):
                phrase = error.args[0] if error.args and isinstance(error.args[0], Phrase) else str(error)
                self.view.refuse(phrase, where=self.note)

    def _load(self, source: Source) -> None:
        """Load ``source`` for this tab's session; its refusal is shown under the upload button."""
        self.runs.load(self.session, source, origin=self.view, on_refused=self._refused)

    def speed_value(self) -> float:
        """The chosen playback speed (x real time)."""
        return SPEEDS.get(self.speed.value, 0.05)

    def _sources(self) -> dict[str, Source | None]:
        ps = self.runs.of(self.session)
        out: dict[str, Source | None] = dict.fromkeys((NONE, *PAPER))
        for source in (ps.uploaded, ps.extra):
            if source is not None:
                out[_option(source)] = source
        return out

    # -- callbacks -----------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_choice(self, event) -> None:
        self._guard(event, self._choose)

    def _apply_duration(self, values) -> None:
        """The typed duration T [s], settled (under the lock): the chosen paper trajectory, that long."""
        label = self.choice.value
        if label not in PAPER:
            raise InputError(Phrase("the duration T is for the paper's line and circle: choose one under Trajectory"))
        self._choose(values["T"])

    def _choose(self, duration: float | None = None) -> None:
        """Load the chosen trajectory: a newly chosen paper trajectory with its default duration
        (``docs/conventions.md``: line 0.2 s, circle 0.5 s), or with the typed ``duration`` [s]."""
        with self.view.hub.locked():
            if duration is None and self._is_echo(self.choice):
                return
            label = self.choice.value
            sources = self._sources()
            if label not in sources:
                raise InputError(Phrase("unknown trajectory {name}", name=repr(label)))
            source = sources[label]
            run = self.runs.of(self.session).run
            if label == NONE:
                self.runs.unload(self.session, origin=self.view)
                return
            if source is None:
                kind = PAPER[label]
                source = Source.paper(kind, DEFAULT_DURATIONS[kind] if duration is None else duration)
            if run is not None and run.source == source and source.kind != "csv":
                return
        self._load(source)

    @guarded(on_error=_internal_error)
    def _on_upload(self, event) -> None:
        self._guard(event, self._uploaded)

    def _uploaded(self) -> None:
        file = self.upload.value
        self._load(Source.from_trajectory(read_upload(file.content, file.name)))

    @guarded(on_error=_internal_error)
    def _on_controls(self, event) -> None:
        self._guard(event, self._control, self.controls.value)

    def _control(self, what: str) -> None:
        session = self.session
        if what == "Play":
            self.runs.play(session, self.speed_value(), bool(self.loop.value), origin=self.view)
        elif what == "Pause":
            self.runs.pause(session, origin=self.view)
        elif what == "To start":
            self.runs.seek(session, 0.0, origin=self.view)

    @guarded(on_error=_internal_error)
    def _on_time(self, event) -> None:
        self._guard(event, self._seek)

    def _seek(self) -> None:
        with self.view.hub.locked():
            if self._is_echo(self.time):
                return
            t = read_number(self.time.value, T("time t"), lo=0.0, hi=1e4)
            self.runs.seek(self.session, t, origin=self.view)

    def opened(self) -> None:
        """The page shows the Player tab (under the hub's lock): its path and trace in front."""
        bring(self.view, PLAYER, redraw=True)

    def _typed_time(self) -> None:
        """A typed time, settled and written into the slider (under the hub's lock): the run at that time."""
        bring(self.view, PLAYER)
        self.runs.seek(self.session, float(self.time.value), origin=self.view)

    def _download(self, name: str, data: bytes) -> None:
        self.view.client.send_file_download(name, data, save_immediately=True)

    def _run_or_refuse(self):
        run = self.runs.of(self.session).run
        if run is None:
            raise InputError(T("load a trajectory first"))
        return run

    @guarded(on_error=_internal_error)
    def _on_export_csv(self, event) -> None:
        def export() -> None:
            run = self._run_or_refuse()
            self._download(f"tpm-run-{run.source.kind}-T{run.duration:g}s.csv", format_columns(run.columns()).encode())

        self._guard(event, export)

    @guarded(on_error=_internal_error)
    def _on_export_png(self, event) -> None:
        def export() -> None:
            run = self._run_or_refuse()
            png = force_plot_png(run.t, run.tau, run.tau_ref, title=f"Actuator forces: {run.source.label}")
            self._download(f"tpm-forces-{run.source.kind}-T{run.duration:g}s.png", png)

        self._guard(event, export)

    @guarded(on_error=_internal_error)
    def _on_export_svg(self, event) -> None:
        def export() -> None:
            run = self._run_or_refuse()
            svg = force_plot_svg(run.t, run.tau, run.tau_ref, title=f"Actuator forces: {run.source.label}")
            self._download(f"tpm-forces-{run.source.kind}-T{run.duration:g}s.svg", svg)

        self._guard(event, export)

    # -- drawing -------------------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Redraw from the session's current frame (under the hub's lock)."""
        session = self.session
        if session is not None and session.frame is not None and not getattr(self.view, "closed", False):
            self.render(session.frame, force=True)
            self.view.client.flush()

    def render(self, frame: Snapshot, force: bool = False) -> None:
        """Draw the player's part of ``frame`` (under the hub's lock); throttled while playing."""
        self._frame = frame
        session = self.session
        if session is None:
            return
        self.runs.follow_params(session)
        ps = self.runs.of(session)
        run = ps.run
        if run is not None and run.params != frame.state.params:
            run = None  # recomputing for the new parameters
        new_run = run is not self._run
        if new_run:
            self._set_run(run)
        state = frame.state
        t = state.trajectory.t if following(state, run) else None
        if t is not None and ps.playing:
            bring(self.view, PLAYER)  # played on the shared mechanism (by the lecturer, a lesson): in front
        in_front = front(self.view, PLAYER) == PLAYER
        if in_front != self._in_front:
            self._in_front = in_front
            show(self.trace.path, in_front and run is not None)
            force = True
        now = time.monotonic()
        due = not frame.in_drag or now - self._last_push >= 1.0 / CHART_HZ
        if (new_run or force or t != self._shown_t) and (due or new_run or force):
            self._shown_t = t
            self._last_push = now
            self._pushes += 1
            self.charts.show_time(t, forces_only=frame.in_drag and self._pushes % 2 == 1)
            self.trace.show_time(run, t if in_front else None)
            if t is not None:
                self._follow_time(float(np.clip(round(t, 4), 0.0, self.time.max)))
        if due or new_run or force:
            shown_t = self._shown_t if self._shown_t is not _UNSET else t
            self.summary.content = summary_html(ps, run, shown_t, self.view.lang)
            self.duration.notes = () if run is None else (duration_note(run.duration), force_note(run.peak))
            self.duration.draw(self.view.lang)
            self.note.draw(self.view.lang)

    def _follow_time(self, t: float) -> None:
        """The time shown [s] (the run's, as it plays or was sought): in the slider, and in the typed field unless
        a time is being typed there."""
        self.time_typed.follow(t)
        self._written[id(self.time)] = self.time.value

    def _set_run(self, run) -> None:
        self._run = run
        self._shown_t = _UNSET
        self.charts.show_run(run, None)
        sources = self._sources()
        self.choice.options = tuple(sources)
        self.trace.show_run(run)
        if not self._in_front:
            show(self.trace.path, False)
        if run is None:
            if self.runs.of(self.session).loading is None:
                self._put(self.choice, NONE)
            return
        self._put(self.choice, _option(run.source))
        self.duration.show({"T": run.duration})
        self.duration.disable(run.source.kind not in ("line", "circle"))
        self.time_typed.limit(0.0, run.duration, max(run.duration / 400.0, 1e-4))

    def close(self) -> None:
        """The tab went away (nothing to release: scene nodes go with the client)."""
