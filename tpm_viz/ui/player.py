"""The trajectory player of one tab: choose a trajectory (the paper's line or circle, your CSV, a demo's path),
play / pause / scrub it at 0.01x-1x, watch the path being traced and the charts' time marker move, export the
run as CSV and the force plot as PNG.

The run and the playback belong to the session (:mod:`.runs`); this view only reads widgets, calls
:class:`~.runs.RunHub` and draws. During playback the charts and the trace are refreshed at most
:data:`CHART_HZ` times a second (the kinematic charts every other time), with the time slider and the summary;
the 3D platform moves at every frame, and the last frame is always drawn in full.
"""

from __future__ import annotations

import html
import time

import numpy as np
import viser

from .. import meshes
from ..csvio import format_columns
from ..errors import InputError, TpmVizError
from ..playback import Source
from ..trajectories import DEFAULT_DURATIONS
from .charts import Charts
from .frame import Frame
from .guard import guarded
from .runs import RunHub, following
from .text import num
from .validate import MAX_UPLOAD_BYTES, read_number, read_upload

__all__ = ["CHART_HZ", "SPEEDS", "PlayerView"]

SPEEDS = {"0.01×": 0.01, "0.02×": 0.02, "0.05×": 0.05, "0.1×": 0.1, "0.2×": 0.2, "0.5×": 0.5, "1× (real time)": 1.0}
"""Playback speeds (the paper's motions last 0.2-0.5 s)."""
CHART_HZ = 4.0
NONE = "none"
PAPER = {"line (Fig. 4)": "line", "circle (Fig. 5)": "circle"}
TRACE_Z = meshes.PLATFORM_Z[1] + 0.003  # m, just over the platform: the path leaves the tool marker
PATH_COLOUR = (234, 179, 8)  # the tool marker's yellow: where P will go
TRACE_COLOUR = (15, 23, 42)
_UNSET = object()


def _internal_error(owner, exc: Exception) -> None:
    """The guard's report to the tab whose callback failed (the traceback is in the server log)."""
    owner.view.refuse(f"internal error ({type(exc).__name__}), logged on the server", resync=False)


def _segments(p: np.ndarray, z: float, max_segments: int) -> np.ndarray:
    step = max(1, int(np.ceil((len(p) - 1) / max_segments)))
    pts = p[np.unique(np.r_[np.arange(0, len(p), step), len(p) - 1])]
    segs = np.zeros((max(len(pts) - 1, 1), 2, 3), dtype=np.float32)
    if len(pts) >= 2:
        segs[:, 0, :2], segs[:, 1, :2] = pts[:-1], pts[1:]
    segs[..., 2] = z
    return segs


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
        self._path = None
        self._trace = None
        self._frame: Frame | None = None

    def build(self, gui: viser.GuiApi) -> None:
        """The *Player* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            "Play a trajectory: the platform follows it, leaves a trace, and the charts mark the current time. "
            "Your own CSV needs the columns `t,p1,p2` (s, m), at least 4 rows, at most "
            f"{MAX_UPLOAD_BYTES / 2**20:g} MiB; it must stay inside the stroke and clear of the singularities."
        )
        self.choice = gui.add_dropdown("Trajectory", (NONE, *PAPER), initial_value=NONE)
        self.duration = gui.add_number("Duration T (s)", 0.2, min=0.01, max=100.0, step=0.01)
        self.upload = gui.add_upload_button(
            "Upload CSV (t, p1, p2 in s, m)", icon=viser.Icon.UPLOAD, mime_type=".csv,text/csv,text/plain"
        )
        self.controls = gui.add_button_group("Playback", ("Play", "Pause", "To start"))
        self.time = gui.add_slider("Time t (s)", 0.0, 0.2, 0.001, 0.0)
        self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.05×")
        self.loop = gui.add_checkbox("Loop", False)
        self.summary = gui.add_html("")
        self.charts = Charts(gui)
        self.export_csv = gui.add_button("Download the run (CSV)", icon=viser.Icon.DOWNLOAD, color="gray")
        self.export_png = gui.add_button("Download the force plot (PNG)", icon=viser.Icon.PHOTO, color="gray")
        self.charts.show_run(None, None)
        self.choice.on_update(self._on_choice)
        self.duration.on_update(self._on_duration)
        self.upload.on_upload(self._on_upload)
        self.controls.on_click(self._on_controls)
        self.time.on_update(self._on_time)
        self.export_csv.on_click(self._on_export_csv)
        self.export_png.on_click(self._on_export_png)

    # -- helpers -------------------------------------------------------------------------------------------
    @property
    def session(self):
        return getattr(self.view, "session", None)

    def _put(self, handle, value) -> None:
        if handle.value != value:
            handle.value = value
        self._written[id(handle)] = handle.value

    def _is_echo(self, *handles) -> bool:
        return all(self._written.get(id(h), _UNSET) == h.value for h in handles)

    def _guard(self, event, fn, *args) -> None:
        """Run ``fn`` for a user event (not a server echo); refused input is told to this tab only."""
        if getattr(event, "client", None) is None or getattr(self.view, "closed", False) or self.session is None:
            return
        try:
            fn(*args)
        except TpmVizError as exc:
            with self.view.hub.lock:
                self.view.refuse(str(exc))

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
        self._guard(event, self._choose, True)

    @guarded(on_error=_internal_error)
    def _on_duration(self, event) -> None:
        self._guard(event, self._choose, False)

    def _choose(self, new_kind: bool) -> None:
        """Load the chosen trajectory: a newly chosen paper trajectory with its default duration
        (``conventions.md``: line 0.2 s, circle 0.5 s), a typed duration otherwise."""
        with self.view.hub.lock:
            if self._is_echo(self.choice, self.duration):
                return
            label = self.choice.value
            sources = self._sources()
            if label not in sources:
                raise InputError(f"unknown trajectory {label!r}")
            source = sources[label]
            run = self.runs.of(self.session).run
            if label == NONE:
                self.runs.unload(self.session, origin=self.view)
                return
            if source is None:
                kind = PAPER[label]
                if new_kind:
                    duration = DEFAULT_DURATIONS[kind]
                else:
                    duration = read_number(self.duration.value, "duration T", lo=0.01, hi=100.0)
                source = Source.paper(kind, duration)
            if run is not None and run.source == source and source.kind != "csv":
                return
            session = self.session
        self.runs.load(session, source, origin=self.view)

    @guarded(on_error=_internal_error)
    def _on_upload(self, event) -> None:
        self._guard(event, self._uploaded)

    def _uploaded(self) -> None:
        file = self.upload.value
        source = Source.from_trajectory(read_upload(file.content, file.name))
        self.runs.load(self.session, source, origin=self.view)

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
        with self.view.hub.lock:
            if self._is_echo(self.time):
                return
            t = read_number(self.time.value, "time t", lo=0.0, hi=1e4)
            self.runs.seek(self.session, t, origin=self.view)

    def _download(self, name: str, data: bytes) -> None:
        self.view.client.send_file_download(name, data, save_immediately=True)

    def _run_or_refuse(self):
        run = self.runs.of(self.session).run
        if run is None:
            raise InputError("load a trajectory first")
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
            from ..figures import force_plot_png  # matplotlib, only when asked

            run = self._run_or_refuse()
            png = force_plot_png(run.t, run.tau, run.tau_ref, title=f"Actuator forces: {run.source.label}")
            self._download(f"tpm-forces-{run.source.kind}-T{run.duration:g}s.png", png)

        self._guard(event, export)

    # -- drawing -------------------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Redraw from the session's current frame (under the hub's lock)."""
        session = self.session
        if session is not None and session.frame is not None and not getattr(self.view, "closed", False):
            self.render(session.frame, force=True)
            self.view.client.flush()

    def render(self, frame: Frame, force: bool = False) -> None:
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
        now = time.monotonic()
        due = not frame.in_drag or now - self._last_push >= 1.0 / CHART_HZ
        if (new_run or force or t != self._shown_t) and (due or new_run or force):
            self._shown_t = t
            self._last_push = now
            self._pushes += 1
            self.charts.show_time(t, forces_only=frame.in_drag and self._pushes % 2 == 1)
            self._draw_trace(run, t)
            if t is not None:
                self._put(self.time, float(np.clip(round(t, 4), 0.0, self.time.max)))
        if due or new_run or force:
            self.summary.content = self._summary(ps, run, self._shown_t if self._shown_t is not _UNSET else t)

    def _set_run(self, run) -> None:
        self._run = run
        self._shown_t = _UNSET
        self.charts.show_run(run, None)
        scene = self.view.client.scene
        sources = self._sources()
        self.choice.options = tuple(sources)
        if run is None:
            if self.runs.of(self.session).loading is None:
                self._put(self.choice, NONE)
            for handle in (self._path, self._trace):
                if handle is not None:
                    handle.visible = False
            return
        self._put(self.choice, _option(run.source))
        self._put(self.duration, round(run.duration, 6))
        self.duration.disabled = run.source.kind not in ("line", "circle")
        self.time.max = run.duration
        self.time.step = max(run.duration / 400.0, 1e-4)
        self._path = scene.add_line_segments(
            "/player/path", _segments(run.p, TRACE_Z, 400), PATH_COLOUR, thickness=2.5, thickness_units="screen"
        )
        if self._trace is None:
            self._trace = scene.add_line_segments(
                "/player/trace", _segments(run.p[:2], TRACE_Z + 0.0005, 1), TRACE_COLOUR, thickness=4.0,
                thickness_units="screen", visible=False,
            )

    def _draw_trace(self, run, t) -> None:
        if self._trace is None:
            return
        if run is None or t is None or t <= 0.0:
            if self._trace.visible:
                self._trace.visible = False
            return
        k = run.index_at(t)
        _, p_now, _, _ = run.state_at(t)
        pts = np.vstack([run.p[: k + 1], p_now[None]])
        self._trace.points = _segments(pts, TRACE_Z + 0.0005, 150)
        if not self._trace.visible:
            self._trace.visible = True

    def _summary(self, ps, run, t) -> str:
        esc = html.escape
        lines = []
        if ps.loading is not None:
            lines.append(f"<i>Computing {esc(ps.loading.label)} (closed form and Pinocchio)…</i>")
        if ps.status:
            lines.append(f'<span style="color:#991b1b">{esc(ps.status)}</span>')
        if run is None:
            if not lines:
                lines.append("No trajectory loaded: choose one above or upload a CSV.")
        else:
            diff = run.max_diff
            lines.append(
                f"<b>{esc(run.source.label)}</b>: peak |τ| = <span data-q='run-peak'>{num(run.peak, '.1f')}</span> N "
                "(closed form)"
            )
            lines.append(
                "Pinocchio − paper: max |Δτ| = "
                + (f"<span data-q='run-diff'>{num(diff, '.1e')}</span> N" if diff is not None else esc(run.ref_note))
            )
            if ps.previous is not None:
                label, peak = ps.previous
                ratio = f" (this / previous = {num(run.peak / peak, '.3f')})" if peak > 0 else ""
                lines.append(f"Previous run: {esc(label)}, peak {num(peak, '.1f')} N{ratio}")
            if ps.playing:
                where = "playing"
            elif t is None:
                where = "not on the path (moved by hand): press Play or move the time slider"
            else:
                where = "paused"
            t_text = num(t, ".3f") if t is not None else "—"
            lines.append(f"t = <span data-q='player-t'>{t_text}</span> s of {num(run.duration, '.3f')} s, {where}")
        return '<div style="font-size:0.85em;color:#334155;line-height:1.45">' + "<br>".join(lines) + "</div>"

    def close(self) -> None:
        """The tab went away (nothing to release: scene nodes go with the client)."""
