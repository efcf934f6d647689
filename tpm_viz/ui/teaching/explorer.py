"""The singularity explorer of one tab: a coloured workspace map on the floor and the manipulability ellipses
at the platform, with their legend and numbers in the *Explorer* tab.

Maps come from :class:`MapService`, one per hub: a parameter set's map (``workspace_map`` on 200 x 200 points
and its three colourings, ~45 ms) is computed once, in the background :class:`~.worker.Worker`, never inside a
callback or the hub's lock, and published to every tab showing those parameters when it is ready. Until then
a tab keeps its previous map hidden and says "computing". The ellipses (an SVD of the 2 x 2 ``J``) are
recomputed for every frame the tab draws (world coordinates, centred on the platform, in the tab's own scope);
they are hidden at singular poses.

The map kind and the ellipses are a per-tab view setting, like the other *Class & view* toggles.
"""

from __future__ import annotations

import html
import threading
import time
import weakref
from collections import OrderedDict

import numpy as np
import viser

from tpm_viz.app.overlays import MAP_KINDS, cached_map, colour_scale, ellipse_polylines, map_rgba
from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.text import num
from tpm_viz.classroom.worker import Worker
from tpm_viz.core import markup
from tpm_viz.core.errors import BusyError
from tpm_viz.core.markup import Html, Markdown
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.drawing import meshes
from tpm_viz.ui.worded import TabGui

__all__ = ["ELLIPSE_COLOURS", "ELLIPSE_SCALE", "ExplorerView", "MapService"]

MAP_N = 200
MAP_Z = 0.0003  # m, under the grid lines (0.0005) and the loci (0.0008), over the base plate (0)
ELLIPSE_SCALE = 0.12
"""Drawing scale of the ellipses [m per unit radius]: the unit circle (J = I, at p = 0) is 120 mm."""
ELLIPSE_CAP = 3.0
ELLIPSE_Z = meshes.PLATFORM_Z[1] + 0.004
ELLIPSE_COLOURS = {"velocity": (30, 58, 138), "force": (234, 88, 12)}  # dark blue (not the leg circles' blue)
STATUS = "<p style='margin:0;padding:0 0 4px;font-size:0.875em'>{text}</p>"
"""The map's status line (why it is unavailable), its text escaped (:func:`tpm_viz.core.markup.html`)."""
STATUS_BUSY = "<p style='margin:0;padding:0 0 4px;font-size:0.875em'><i>{text}</i></p>"
"""The map's status line while it is computed."""


class MapService:
    """Coloured maps per parameter set, computed in the background and cached (8 parameter sets)."""

    def __init__(self, worker: Worker) -> None:
        self.worker = worker
        self._lock = threading.Lock()
        self._maps: OrderedDict[Params, dict[str, np.ndarray]] = OrderedDict()
        self._pending: set[Params] = set()
        self._failed: dict[Params, Phrase] = {}  # why a map could not be computed (not retried)
        self.subscribers: weakref.WeakSet = weakref.WeakSet()
        self.last_seconds = float("nan")
        """Wall time of the last map computation [s] (for the benchmark)."""

    def get(self, params: Params, tab=None) -> dict[str, np.ndarray] | None:
        """The images of ``params`` (``kind -> (n, n, 4)`` uint8), or None while they are computed (as ``tab``'s
        job in the worker's fair queue: a tab's newer map replaces its pending one)."""
        with self._lock:
            images = self._maps.get(params)
            if images is not None:
                self._maps.move_to_end(params)
                return images
            if params in self._pending or params in self._failed:
                return None
            self._pending.add(params)
        self.worker.submit(
            "map" if tab is not None else ("map", params),
            lambda: self._compute(params),
            lambda r, e: self._done(params, r, e),
            tab=tab,
            dropped=lambda: self._dropped(params),
        )
        return None

    def failure(self, params: Params) -> Phrase | None:
        """Why the map of ``params`` could not be computed, or None."""
        with self._lock:
            return self._failed.get(params)

    def _compute(self, params: Params) -> dict[str, np.ndarray]:
        t0 = time.perf_counter()
        ws = cached_map(params, MAP_N)
        images = {kind: map_rgba(ws, kind) for kind in MAP_KINDS if kind != "off"}
        self.last_seconds = time.perf_counter() - t0
        return images

    def _dropped(self, params: Params) -> None:
        """The job of ``params`` will never run (its tab left or asked for another map): a tab still showing
        those parameters asks again."""
        with self._lock:
            self._pending.discard(params)
        for view in list(self.subscribers):
            view.map_ready(params)

    def _done(self, params: Params, images, error: Exception | None = None) -> None:
        if isinstance(error, BusyError):  # the queue was full: asked again at the tab's next frame
            with self._lock:
                self._pending.discard(params)
            return
        with self._lock:
            self._pending.discard(params)
            if images is None:
                self._failed[params] = reason(error) if error is not None else T("no map")
            else:
                self._maps[params] = images
                while len(self._maps) > 8:
                    self._maps.popitem(last=False)
        for view in list(self.subscribers):  # the map, or why there is none
            view.map_ready(params)


def _legend(lang: Lang, text: str | Phrase | None) -> str:
    """A text of a legend (:func:`~tpm_viz.app.overlays.colour_scale`: words, or a number as text) in ``lang``,
    escaped."""
    return html.escape(text.render(lang) if isinstance(text, Phrase) else str(text or ""))


def colour_bar_html(kind: str, lang: Lang = Lang.EN) -> Html:
    """The legend of a map kind: a gradient (or swatches) with labelled stops, in ``lang``."""
    scale = colour_scale(kind)
    if not scale.stops:
        words = html.escape(say(lang, T("No map: the floor shows the in-stroke workspace.")))
        return Html(f'<div style="font-size:0.8em;color:#64748b">{words}</div>')

    def esc(text: str | Phrase | None) -> str:
        return _legend(lang, text)

    if kind == "workspace":
        body = "".join(
            f'<span style="display:inline-flex;align-items:center;gap:4px;margin-right:10px">'
            f'<span style="width:12px;height:12px;background:{c};border-radius:2px"></span>{esc(label)}</span>'
            for label, c in scale.stops
        )
    else:
        stops = ", ".join(c for _, c in scale.stops)
        labels = "".join(f"<span>{esc(label)}</span>" for label, _ in scale.stops)
        body = (
            f'<div style="height:12px;border-radius:2px;background:linear-gradient(to right, {stops})"></div>'
            f'<div style="display:flex;justify-content:space-between;font-variant-numeric:tabular-nums">{labels}</div>'
        )
    return Html(
        f'<div data-q="map-legend" style="font-size:0.8em;color:#334155;line-height:1.4">'
        f"<b>{esc(scale.title)}</b>{body}<div style='color:#64748b'>{esc(scale.note)}</div></div>"
    )


class ExplorerView:
    """Explorer widgets and scene nodes of one tab."""

    def __init__(self, view, maps: MapService) -> None:
        self.view = view
        self.maps = maps
        self.kind = "off"
        self.ellipses_on = False
        self._image = None
        self._image_key: tuple[Params, str] | None = None
        self._map_drawn: tuple[Params, str] | None = (
            None  # (params, kind) the legend and floor last showed: nothing to send while unchanged
        )
        self._ellipses: dict[str, viser.LineSegmentsHandle] = {}
        self._frame: Snapshot | None = None
        maps.subscribers.add(self)

    def build(self, gui: TabGui) -> None:
        """The *Explorer* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            Markdown(
                "Colour the floor with a map of the workspace and draw the manipulability ellipses at the platform. "
                "The loci stay on top: red arcs cos(θ1+θ2) = 0 (eq. 12), amber square |p_j| = l_a (eq. 11)."
            )
        )
        self.map_kind = gui.add_dropdown("Floor map", tuple(MAP_KINDS.values()), initial_value=MAP_KINDS["off"])
        self.legend = gui.add_html(colour_bar_html("off", self.view.lang))
        self.status = gui.add_html("")
        self.ellipses = gui.add_checkbox(
            "Manipulability ellipses", False, hint="Velocity (dark blue) and force (orange) ellipses at the platform"
        )
        self.readout = gui.add_html("")
        self.map_kind.on_update(self._on_kind)
        self.ellipses.on_update(self._on_ellipses)

    # -- settings ------------------------------------------------------------------------------------------
    def set(self, kind: str | None = None, ellipses: bool | None = None) -> None:
        """Change the settings from the server (a demonstration); call under the hub's lock."""
        if kind is not None:
            self.kind = kind
            self.map_kind.value = MAP_KINDS[kind]
        if ellipses is not None:
            self.ellipses_on = bool(ellipses)
            self.ellipses.value = self.ellipses_on
        if self._frame is not None:
            self.render(self._frame)

    @guarded
    def _on_kind(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        kinds = {label: kind for kind, label in MAP_KINDS.items()}
        with self.view.hub.locked():
            self.set(kind=kinds.get(self.map_kind.value, "off"))
            self.view.client.flush()

    @guarded
    def _on_ellipses(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        with self.view.hub.locked():
            self.set(ellipses=bool(self.ellipses.value))
            self.view.client.flush()

    # -- drawing -------------------------------------------------------------------------------------------
    def map_ready(self, params: Params) -> None:
        """A map finished computing (worker thread): draw it if this tab shows those parameters."""
        with self.view.hub.locked():
            if getattr(self.view, "closed", False) or self._frame is None:
                return
            if self._frame.state.params == params:
                self._draw_map(params)
                self.view.client.flush()

    def render(self, frame: Snapshot) -> None:
        """Draw the explorer's part of ``frame`` (under the hub's lock)."""
        self._frame = frame
        self._draw_map(frame.state.params)
        self._draw_ellipses(frame)

    def _draw_map(self, params: Params) -> None:
        scene = self.view.client.scene
        kind = self.kind
        if self._map_drawn == (params, kind):
            return
        self.legend.content = colour_bar_html(kind, self.view.lang)
        self.view.scene.set_region_hidden(kind != "off")  # the workspace floor would cover the map
        if kind == "off":
            self._map_drawn = (params, kind)
            self.status.content = ""
            if self._image is not None and self._image.visible:
                self._image.visible = False
            return
        images = self.maps.get(params, self.view)
        if images is None:
            failure = self.maps.failure(params)
            lang = self.view.lang
            computing = T("Computing the map for these parameters…")
            unavailable = Phrase("Map unavailable: {why}", why=failure) if failure else None
            if unavailable:
                self.status.content = markup.html(STATUS, text=say(lang, unavailable))
            else:
                self.status.content = markup.html(STATUS_BUSY, text=say(lang, computing))
            if self._image is not None:
                self._image.visible = False
            return
        self.status.content = ""
        self._map_drawn = (params, kind)
        if self._image_key == (params, kind) and self._image is not None:
            if not self._image.visible:
                self._image.visible = True
            return
        size = 2 * params.l_a * (MAP_N / (MAP_N - 1))  # each grid point owns one cell
        self._image = scene.add_image(
            "/explorer/map",
            images[kind],
            size,
            size,
            format="png",
            position=(0.0, 0.0, MAP_Z),
            cast_shadow=False,
            receive_shadow=False,
        )
        self._image_key = (params, kind)

    def _draw_ellipses(self, frame: Snapshot) -> None:
        state = frame.state
        drawing = None
        if self.ellipses_on:
            drawing = ellipse_polylines(state.params, state.pose.p, ELLIPSE_SCALE, ELLIPSE_CAP)
        scene = self.view.client.scene
        planner = "planner" in getattr(getattr(self.view, "teaching", None), "open_tabs", ())
        for name in ("velocity", "force"):
            handle = self._ellipses.get(name)
            if drawing is None or planner:  # the Planner shows its own path and forces (ui/seen.py)
                if handle is not None and handle.visible:
                    handle.visible = False
                continue
            pts = getattr(drawing, name)
            pts = pts + np.asarray(frame.readout.p)  # world coordinates: drawn in the tab's own scope
            segs = np.zeros((len(pts) - 1, 2, 3), dtype=np.float32)
            segs[:, 0, :2], segs[:, 1, :2] = pts[:-1], pts[1:]
            segs[..., 2] = ELLIPSE_Z + (0.001 if name == "force" else 0.0)
            if handle is None:
                self._ellipses[name] = scene.add_line_segments(
                    f"/explorer/ellipse_{name}",
                    segs,
                    ELLIPSE_COLOURS[name],
                    thickness=3.0,
                    thickness_units="screen",
                )
            else:
                handle.points = segs
                if not handle.visible:
                    handle.visible = True
        self.readout.content = self._readout_html(frame, drawing)

    def _readout_html(self, frame: Snapshot, drawing) -> Html:
        if not self.ellipses_on:
            return Html("")
        r, lang = frame.readout, self.view.lang
        head = say(
            lang,
            Phrase(
                "det J_x = {det}, condition number of J = {cond}", det=num(r.det_jx, ".3f"), cond=num(r.cond, ".2f")
            ),
        )
        if drawing is None:
            body = say(lang, T("Ellipses hidden: J is singular (or nearly) at this pose."))
        else:
            v, f = drawing.velocity_radii, drawing.force_radii
            velocity = Phrase(
                "<span style='color:#1e3a8a'>velocity ellipse</span> semi-axes {low} × {high} (m/s per m/s of actuator "
                "speed)",
                low=num(v.min(), ".3f"),
                high=num(v.max(), ".3f"),
            )
            force = Phrase(
                "<span style='color:#ea580c'>force ellipse</span> semi-axes {low} × {high} (N per N of actuator force)",
                low=num(f.min(), ".3f"),
                high=num(f.max(), ".3f"),
            )
            scale = (
                Phrase(
                    "drawn at {mm:.0f} mm per unit, radii clipped at {cap:g}", mm=ELLIPSE_SCALE * 1e3, cap=ELLIPSE_CAP
                )
                if drawing.clipped
                else Phrase("drawn at {mm:.0f} mm per unit", mm=ELLIPSE_SCALE * 1e3)
            )
            body = "<br>".join(say(lang, x) for x in (velocity, force, scale))
        return Html(
            f'<div data-q="ellipses" style="font-size:0.8em;color:#334155;line-height:1.4">{head}<br>{body}</div>'
        )

    def retell(self) -> None:
        """The tab's language changed: the legend and the map's status again, in it (under the hub's lock)."""
        self._map_drawn = None
        if self._frame is not None:
            self._draw_map(self._frame.state.params)
        else:
            self.legend.content = colour_bar_html(self.kind, self.view.lang)

    def close(self) -> None:
        """The tab went away."""
        self.maps.subscribers.discard(self)
