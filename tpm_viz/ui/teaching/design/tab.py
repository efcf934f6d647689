"""The *Design* tab of one browser tab: the atlas of designs as a heat map you click to load, and both arrangements
compared side by side (``docs/design.md``).

- **Map.** A task rectangle (mm, typed), an arrangement and two of ``a, b, l_a, Δd`` with ranges and counts (at most
  15 x 15): the designs are evaluated by :func:`tpm_viz.design.indices.evaluate` (every index, cycle time included) in
  the tab's turns of the fair worker, :data:`~.map.CHUNK` designs a job, a progress line meanwhile. The map is a grid
  of coloured cells on the Design area's floor (a click gives the cell), grey where infeasible, the best ringed.
- **Load.** Clicking a cell, typing its column and row (Enter), or *Load best design*: a perpendicular design
  becomes the tab's mechanism through the *Parameters* tab's path (:func:`tpm_viz.app.transitions.apply_params`,
  the tab's own copy or, for the presenter, the shared one); a parallel design is drawn in the comparison.
- **Compare.** :func:`tpm_viz.design.compare.compare` (hold the link, the footprint or the mass): the table of
  indices, and both mechanisms drawn beside each other with their task rectangles
  (:mod:`tpm_viz.ui.teaching.design.drawings`).

The Design area (:mod:`.scene`) is away from the live mechanism, hidden by *Back to the mechanism*.
"""

from __future__ import annotations

import numpy as np
import viser

from tpm_viz.app import transitions
from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.worker import Worker
from tpm_viz.core.errors import BusyError, InputError, TpmVizError
from tpm_viz.core.markup import Markdown, escape
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T, say
from tpm_viz.design.atlas import Row
from tpm_viz.design.compare import Hold
from tpm_viz.design.indices import Task
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.ui.fields import Note, TypedBox
from tpm_viz.ui.teaching.design import text
from tpm_viz.ui.teaching.design.compare import in_turns
from tpm_viz.ui.teaching.design.compare import start as start_comparison
from tpm_viz.ui.teaching.design.fields import count_field, length_field
from tpm_viz.ui.teaching.design.map import CHUNK, INDICES, MAX_COUNT, SWEPT, Axis, MapSpec, best_cell, colours
from tpm_viz.ui.teaching.design.map import values as map_values
from tpm_viz.ui.teaching.design.scene import PENDING, DesignScene, comparison_designs
from tpm_viz.ui.widgets.typed import TypedGroup
from tpm_viz.ui.worded import TabGui

__all__ = ["DesignView"]


def _internal_error(owner, exc: Exception) -> None:
    owner.view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__), resync=False)


class DesignView:
    """Design widgets, jobs and scene nodes of one tab (``view``: its :class:`~tpm_viz.ui.client.ClientView`)."""

    def __init__(self, view, worker: Worker) -> None:
        self.view = view
        self.worker = worker
        self.task = Task(-0.05, 0.05, -0.05, 0.05)
        self.axes = {"x": ("a", 0.40, 0.56, 7), "y": ("l_a", 0.20, 0.30, 7)}  # name, from, to [m], count
        self.spec: MapSpec | None = None
        self.rows: list[Row | None] = []
        self.done = 0
        self.error: Phrase | None = None
        self.picked: int | None = None
        self.compared: list[Row] = []
        self.compare_note: Phrase | None = None
        self._request = 0
        self._compare_request = 0
        self.loaded_parallel: Params | None = None
        self.scene = DesignScene(view.client)
        self._hold = Hold.LINK

    # -- widgets -------------------------------------------------------------------------------------------
    def build(self, gui: TabGui) -> None:
        """The *Design* tab's widgets (inside the tab's context)."""
        gui.add_markdown(Markdown(text.INTRO))
        self.arrangement = gui.add_dropdown(
            "Arrangement", tuple(a.value for a in Arrangement), initial_value="perpendicular"
        )
        self.task_box = TypedBox(
            gui, TypedGroup({k: length_field(k, v) for k, v in self._task_values().items()}), text.TASK_LABELS
        )
        names = tuple(SWEPT)
        self.x_name = gui.add_dropdown("Across: parameter", names, initial_value="a")
        self.y_name = gui.add_dropdown("Up: parameter", names, initial_value="l_a")
        fields = {}
        for axis in ("x", "y"):
            _name, lo, hi, count = self.axes[axis]
            fields[f"{axis}_from"], fields[f"{axis}_to"] = length_field("from", lo), length_field("to", hi)
            fields[f"{axis}_count"] = count_field(count)
        self.range_box = TypedBox(gui, TypedGroup(fields), text.RANGE_LABELS)
        self.index = gui.add_dropdown(
            "Colour by", tuple(i.label for i in INDICES.values()), initial_value=INDICES["gci"].label
        )
        self.compute = gui.add_button("Compute map", icon=viser.Icon.GRID_DOTS)
        self.note = Note(gui)
        self.progress = gui.add_html("")
        self.legend = gui.add_html("")
        self.pick_box = TypedBox(gui, TypedGroup({"column": count_field(1), "row": count_field(1)}), text.PICK_LABELS)
        self.load_cell = gui.add_button("Load this design", icon=viser.Icon.CHECK)
        self.load_best = gui.add_button("Load best design", icon=viser.Icon.STAR)
        self.cell = gui.add_html("")
        self.hold = gui.add_dropdown("Compare holding equal", tuple(text.HOLDS), initial_value="link")
        self.case = gui.add_dropdown("Draw", ("given", "optimum"), initial_value="given")
        self.compare_button = gui.add_button("Compare arrangements", icon=viser.Icon.SCALE)
        self.compare_status = gui.add_html("")
        self.table = gui.add_html("")
        self.look = gui.add_button("Look at the design area", icon=viser.Icon.EYE)
        self.back = gui.add_button("Back to the mechanism", icon=viser.Icon.HOME, color="gray")
        typing = self.view.typing
        typing.add(self.task_box, self._apply_task)
        typing.add(self.range_box, self._apply_ranges)
        typing.add(self.pick_box, self._apply_pick)
        self.compute.on_click(lambda e: self._user(e, self._compute))
        self.load_cell.on_click(lambda e: self._user(e, lambda: self._apply_pick(self.pick_box.group.read())))
        self.load_best.on_click(lambda e: self._user(e, self._load_best))
        self.compare_button.on_click(lambda e: self._user(e, self._compare))
        self.look.on_click(lambda e: self._user(e, self._look))
        self.back.on_click(lambda e: self._user(e, self._back))
        self.arrangement.on_update(lambda e: self._user(e, self._arrangement_changed))
        self.index.on_update(lambda e: self._user(e, self._redraw))
        self.case.on_update(lambda e: self._user(e, self._draw_comparison))
        self.x_name.on_update(lambda e: self._user(e, self._axis_changed, "x"))
        self.y_name.on_update(lambda e: self._user(e, self._axis_changed, "y"))

    @guarded(on_error=_internal_error)
    def _user(self, event, fn, *args) -> None:
        """A control of the tab: ``fn(*args)`` under the hub's lock; a refusal in the tab's note."""
        view = self.view
        if getattr(event, "client", None) is None or view.closed or getattr(view, "session", None) is None:
            return
        after = None
        with view.hub.locked():
            try:
                after = fn(*args)
            except TpmVizError as exc:
                self.note.tell(exc, view.lang)
            else:
                self.note.tell(None, view.lang)
            view.client.flush()
        if callable(after):  # a job to submit, outside the lock (the worker's done callbacks take it)
            after()

    def _task_values(self) -> dict[str, float]:
        t = self.task
        return {"x0": t.x0, "x1": t.x1, "y0": t.y0, "y1": t.y1}

    def _apply_task(self, values) -> None:
        if not (values["x0"] < values["x1"] and values["y0"] < values["y1"]):
            raise InputError(T("the task needs x0 < x1 and y0 < y1"))
        self.task = Task(values["x0"], values["x1"], values["y0"], values["y1"])
        self.task_box.show(self._task_values())

    def _apply_ranges(self, values) -> None:
        axes = {}
        for axis, handle in (("x", self.x_name), ("y", self.y_name)):
            count = values[f"{axis}_count"]
            if count != int(count):
                raise InputError(Phrase("a count is a whole number from 1 to {most}", most=MAX_COUNT))
            lo, hi = values[f"{axis}_from"], values[f"{axis}_to"]
            Axis(str(handle.value), lo, hi, int(count))  # refused here, not when computing
            axes[axis] = (str(handle.value), lo, hi, int(count))
        self.axes = axes
        self.range_box.show(values)

    def _axis_changed(self, axis: str) -> None:
        """A new swept parameter: its range from 0.8 to 1.2 times the mechanism's value, the count kept."""
        name = str((self.x_name if axis == "x" else self.y_name).value)
        value = float(getattr(self.view.session.state.params, name))
        count = self.axes[axis][3]
        self.axes[axis] = (name, 0.8 * value, 1.2 * value, count)
        lo, hi = self.axes[axis][1:3]
        self.range_box.show({f"{axis}_from": lo, f"{axis}_to": hi}, force=True)

    def _arrangement_changed(self) -> None:
        """Another arrangement: the task keeps its size, centred on that arrangement's home pose."""
        kind = Arrangement.parse(self.arrangement.value)
        params = self.view.session.state.params
        try:
            home = arr.home(kind, params)
        except TpmVizError:
            return
        self.task = self.task.centred_at(float(home[0]), float(home[1]))
        self.task_box.show(self._task_values(), force=True)

    # -- the map -------------------------------------------------------------------------------------------
    def _settled(self, *boxes: TypedBox) -> None:
        for box in boxes:
            self.view.typing.settle(box)
            if box.group.problem():
                raise InputError(T("fix the fields marked in red first"))

    def _compute(self):
        self._settled(self.task_box, self.range_box)
        x, y = (Axis(*self.axes[a]) for a in ("x", "y"))
        spec = MapSpec(Arrangement.parse(self.arrangement.value), self.view.session.state.params, self.task, x, y)
        self.spec, self.rows, self.done, self.error, self.picked = spec, [None] * spec.size, 0, None, None
        self._request += 1
        request = self._request
        self.pick_box.group.limit(1.0, float(max(x.count, y.count)))
        self._show_area(on_map=True)
        self._redraw()
        return lambda: self._next(request, spec, 0)

    def _next(self, request: int, spec: MapSpec, start: int) -> None:
        """Submit the chunk of designs from ``start`` as this tab's job (outside the lock)."""
        self.worker.submit(
            "design-map",
            lambda: spec.rows(start, start + CHUNK),
            lambda rows, error: self._chunk(request, spec, start, rows, error),
            tab=self.view,
        )

    def _chunk(self, request: int, spec: MapSpec, start: int, rows, error) -> None:
        """A chunk is done (worker thread): store it, draw the map, submit the next one."""
        more = False
        with self.view.hub.locked():
            if self.view.closed or request != self._request:
                return
            if error is not None:
                why = T("the server is busy: press Compute map again") if isinstance(error, BusyError) else None
                self.error = Phrase("Map stopped: {why}", why=why or reason(error))
            else:
                self.rows[start : start + len(rows)] = rows
                self.done = start + len(rows)
                more = self.done < spec.size
            self._redraw()
            self.view.client.flush()
        if more:
            self._next(request, spec, start + len(rows))

    def _index(self) -> str:
        return next((k for k, i in INDICES.items() if i.label == self.index.value), "gci")

    def _redraw(self) -> None:
        """The map's cells, marks, legend, progress and picked design (under the lock)."""
        spec, lang = self.spec, self.view.lang
        if spec is None:
            return
        index = self._index()
        vals = map_values(self.rows, index)
        cols, span = colours(vals, index)
        busy = self.done < spec.size and self.error is None
        self.progress.content = text.progress_html(self.done, spec.size, busy, lang, self.error)
        feasible = int(np.isfinite(vals).sum())
        self.legend.content = text.legend_html(index, span, feasible, self.done, lang) if self.done else ""
        if self.picked is not None:
            self.cell.content = text.cell_html(spec, self.picked, self.rows[self.picked], lang)
        if self.scene.area is not None:
            best = best_cell(vals, index) if not busy else None
            cols[[row is None for row in self.rows]] = PENDING
            self.scene.draw_map(spec, cols, best, self.picked, self._on_cell)

    # -- loading -------------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_cell(self, event) -> None:
        k = getattr(event, "instance_index", None)
        if k is None or getattr(event, "client", None) is None:
            return
        if event.client.client_id != self.view.client.client_id:
            return
        self._user(event, self.load, int(k))

    def _apply_pick(self, values) -> None:
        spec = self.spec
        if spec is None:
            raise InputError(T("compute a map first"))
        column, row = int(values["column"]), int(values["row"])
        if not (column == values["column"] and row == values["row"]):
            raise InputError(T("type whole numbers for the column and the row"))
        if not (1 <= column <= spec.x.count and 1 <= row <= spec.y.count):
            raise InputError(
                Phrase("the map has columns 1 to {nx} and rows 1 to {ny}", nx=spec.x.count, ny=spec.y.count)
            )
        self.pick_box.show(values)
        self.load(spec.index_of(column - 1, row - 1))

    def _load_best(self) -> None:
        if self.spec is None:
            raise InputError(T("compute a map first"))
        best = best_cell(map_values(self.rows, self._index()), self._index())
        if best is None:
            raise InputError(T("no design of the map covers the task"))
        self.load(best)

    def load(self, k: int) -> None:
        """Pick design ``k`` and load it: a perpendicular one into the tab's mechanism, a parallel one into the
        comparison (under the lock)."""
        spec = self.spec
        if spec is None or not 0 <= k < spec.size:
            raise InputError(T("compute a map first"))
        self.picked = k
        column, row = spec.cell(k)
        self.pick_box.show({"column": float(column + 1), "row": float(row + 1)}, force=True)
        self._redraw()
        found = self.rows[k]
        if found is None:
            raise InputError(T("that design is not computed yet"))
        if not found.get("feasible"):
            why = found.get("why") or ""
            raise InputError(Phrase("that design is infeasible ({why}): not loaded", why=why))
        lengths = {name: float(found[name]) for name in SWEPT}
        view = self.view
        if spec.arrangement is Arrangement.PERPENDICULAR:
            session = view.session
            new = transitions.apply_params(session.state, {n: v * 1e3 for n, v in lengths.items()})
            view.hub.authorize(view, session)
            view.tell("")
            session.play_token += 1
            view.hub.commit(session, new, origin=view)
        else:
            self.loaded_parallel = spec.base.replace(**lengths)
            self.compared = []
            self._draw_comparison()

    # -- comparison ----------------------------------------------------------------------------------------
    def _compare(self):
        self._settled(self.task_box)
        params, task, hold = self.view.session.state.params, self.task, Hold.parse(self.hold.value)
        self._compare_request += 1
        request = self._compare_request
        self.compare_note = T(
            "Comparing: each arrangement at these dimensions and at its own optimum, found by a global search "
            "(a few minutes; the other tabs keep working meanwhile)…"
        )
        self.compare_status.content = escape(say(self.view.lang, self.compare_note))
        self._show_area()
        wanted = lambda: request == self._compare_request and not self.view.closed  # noqa: E731
        evaluate = in_turns(self.worker, self.view, "design-compare", wanted)
        done = lambda rows, error: self._compared(request, hold, rows, error)  # noqa: E731
        return lambda: start_comparison(params, task, hold, evaluate, done)

    def _compared(self, request: int, hold: Hold, rows, error) -> None:
        with self.view.hub.locked():
            if self.view.closed or request != self._compare_request:
                return
            if error is not None:
                self.compare_note = Phrase("No comparison: {why}", why=reason(error))
            else:
                self.compare_note, self.compared = None, list(rows)
                self._hold = hold
            self.retell()
            self._draw_comparison()
            self.view.client.flush()

    def _draw_comparison(self) -> None:
        """Both mechanisms beside the map (under the lock)."""
        labels = {kind: say(self.view.lang, text.ARRANGEMENTS[kind.value]) for kind in Arrangement}
        designs = comparison_designs(
            self.compared,
            str(self.case.value),
            self.view.session.state.params,
            self.task,
            self.loaded_parallel,
            self.spec,
        )
        self.scene.draw_comparison(designs, labels)

    # -- the area and the camera ---------------------------------------------------------------------------
    def _show_area(self, on_map: bool = False) -> None:
        """Show the Design area with the comparison; the camera goes there the first time (to the map, framed
        large, when a map is being computed: ``on_map``)."""
        first = self.scene.show()
        self._draw_comparison()
        if on_map or first:
            self.scene.look_map() if on_map else self.scene.look()

    def _look(self) -> None:
        self._show_area()
        self.scene.look_map() if self.spec is not None else self.scene.look()

    def _back(self) -> None:
        self.scene.hide()
        self.view.frame_camera(self.view.session.state.params)

    # -- per frame, language -------------------------------------------------------------------------------
    def render(self, frame) -> None:
        """The tab's mechanism changed: the comparison shows it (under the lock; nothing sent otherwise)."""
        if self.scene.shown:
            self._draw_comparison()

    def retell(self) -> None:
        """The tab's language changed: every text of the tab again, in it (under the hub's lock)."""
        lang = self.view.lang
        self._redraw()
        self.compare_status.content = escape(say(lang, self.compare_note) if self.compare_note is not None else "")
        self.table.content = text.table_html(self.compared, text.HOLDS[self._hold.value], lang) if self.compared else ""
        self._draw_comparison()
