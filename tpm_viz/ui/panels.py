"""The control panel of one browser tab: GUI handles built once, values written by :meth:`Panel.show`.

No maths here: the numbers come from a :class:`~tpm_viz.app.readouts.Readout`, formatted by :mod:`.text`.
Units in labels: mm, N, kg, s, degrees (SI inside; the scale factors come from ``PARAM_INFO``).

Typed numbers (the platform and actuator positions, the load vectors, the parameters) are text fields read through
:mod:`tpm_viz.ui.widgets.typed` (:class:`~.fields.TypedBox`: scientific notation and decimal commas, applied on Enter,
by *Apply* or after a quiet time, never per keystroke; the value in use always shown). Their groups hold values in the
units of their labels (mm, N, m/s, m/s², kg), as the transitions take them. Refusals and notes are shown next to the
control that caused them (:class:`~.fields.Note`); the line at the top of the panel is for the others (drags, the
classroom).

The actuators have both: a slider each, to drive by dragging (a phone's thumb), without viser's number box beside it
(that box drops the ``e`` of ``1.5e2`` and applies per keystroke: hidden by :func:`slider_css`), and the typed box
``d1, d2`` under them (:data:`ACTUATOR_HINT`), range-checked against the stroke ``[0, Δd]``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import viser

from tpm_viz.app.poses import DEMO_KINDS
from tpm_viz.app.readouts import LOAD_MODES, Load
from tpm_viz.app.state import AppState
from tpm_viz.app.transitions import MAX_ACCEL, MAX_FORCE, MAX_POSITION, MAX_SPEED
from tpm_viz.classroom.pacing import LIVE_NUMBERS_INTERVAL
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.text import legend_html
from tpm_viz.core.markup import Html, Markdown, html
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Lang
from tpm_viz.drawing.palette import hex_colour
from tpm_viz.ui.fields import Note, TypedBox
from tpm_viz.ui.panel_css import fold_css, slider_css
from tpm_viz.ui.widgets.typed import QUIET, Quantity, TypedField, TypedGroup, force_note
from tpm_viz.ui.worded import TabGui, Tabs, Worded, put, stored

__all__ = ["ACTUATOR_HINT", "ACTUATOR_LABELS", "GROUPS", "GUIDE_HTML", "PARAM_LABELS", "Panel", "slider_css"]

_UNSET = object()

PARAM_LABELS = {
    "a": "a, total size (mm)",
    "b": "b, platform offset (mm)",
    "l_a": "l_a, link length (mm)",
    "pivot_spacing": "pivot spacing (mm)",
    "stroke": "stroke Δd (mm)",
    "m_a": "m_a, slider (kg)",
    "m_b": "m_b, links of a leg (kg)",
    "m_p": "m_p, platform (kg)",
}
"""Panel label of each parameter, with its UI unit."""

DEMO_LABELS = {
    "inverse": "Near an inverse singularity",
    "direct": "Near the direct singularity",
    "stroke": "At a stroke end",
}

SHOW_LABELS = {
    "labels": "Labels O, A_i, B_i, P",
    "loci": "Workspace and singularities",
    "circles": "Circles, other mode",
    "forces": "Force arrows",
}


GROUPS = {"explore": "Explore", "teach": "Teach", "lab": "Lab", "setup": "Setup"}
"""The groups of tabs, by key, with their names: *Explore* (Move, Forces, Explorer), *Teach* (Demos, Player,
Equations), *Lab* (Control, Planner, Design), *Setup* (Parameters, Class & view). One row of groups and one row of
the open group's tabs: two rows of tabs at most, at 1024 px and in Korean too."""

GUIDE_LINES = (
    "Drag the blue square at the grey platform P in 3D (or type p in Move): the legs and the forces follow.",
    "Near a singularity: the grey buttons at the top of Move. The banner above the tabs turns amber or red.",
)
GUIDE_COLOURS = (
    (hex_colour("workspace"), "workspace"),
    (hex_colour("inverse"), "inverse singularity"),
    (hex_colour("direct"), "direct singularity"),
    (hex_colour("stroke"), "stroke end"),
    (hex_colour("circle"), "other assembly mode P′"),
)
"""The colours of the 3D view in the guide, by name, from the palette (the legend of the Move tab says more)."""
_CHIP = "<span style='display:inline-block;width:10px;height:10px;border-radius:2px;background:{}'></span>"
GUIDE_HTML = Html(
    "<div data-guide='1' style='font-size:0.85em;line-height:1.35'>"
    + "".join(f"<p style='margin:0 0 3px'>{line}</p>" for line in GUIDE_LINES)
    + "<div style='display:flex;flex-wrap:wrap;gap:2px 10px'>"
    + "".join(f"<span>{_CHIP.format(colour)} <span>{name}</span></span>" for colour, name in GUIDE_COLOURS)
    + "</div></div>"
)
"""The first visit's guide: what to drag, the singularities, the colours (templates of the catalogue)."""

PARAM_NAMES = {"pivot_spacing": "pivot spacing", "stroke": "stroke Δd"}
"""Name of a parameter in the notes of its field (the others: their own name)."""

VECTORS = {
    "p": (("p1", "p2"), "mm", MAX_POSITION * 1e3, ("Platform p1 (mm)", "Platform p2 (mm)")),
    "f_ext": (("f_x", "f_y"), "N", MAX_FORCE, ("Load f_x (N)", "Load f_y (N)")),
    "dp": (("ṗ1", "ṗ2"), "m/s", MAX_SPEED, ("Velocity ṗ1 (m/s)", "Velocity ṗ2 (m/s)")),
    "ddp": (("p̈1", "p̈2"), "m/s²", MAX_ACCEL, ("Acceleration p̈1 (m/s²)", "Acceleration p̈2 (m/s²)")),
}
"""The typed vectors: keys of their two fields, unit, largest magnitude accepted (the transitions' bounds) and
labels (the Forces tab: the external load ``f_ext`` on the platform in static mode, its velocity ``ṗ`` and
acceleration ``p̈`` in dynamic mode)."""
TYPED_HINT = "Scientific notation (1e-3) and decimal commas (0,5) work; Enter applies (or stop typing for a moment)"
ACTUATOR_LABELS = {"d1": "d1 (mm)", "d2": "d2 (mm)"}
"""Labels of the typed actuator positions (the sliders above them are "Actuator d1 (mm)", "Actuator d2 (mm)")."""
ACTUATOR_HINT = (
    "Actuator position along its rail, from 0 to the stroke Δd: 1.5e2, 150,5 and 0.15 m work; Enter applies "
    "(or stop typing for a moment)"
)
MESSAGE = "<p data-q='message' style='margin:0;padding:0 12px 8px;font-size:0.875em'><b>{text}</b></p>"
"""The tab's message line (:meth:`Panel.tell`), its text escaped (:func:`tpm_viz.core.markup.html`)."""
CLASS_LINE = "<p data-q='class-line' style='margin:0;padding:0 12px 8px;font-size:0.875em'>{text}</p>"
"""The classroom line of the *Class & view* tab (:meth:`~.client.ClientView.set_class_info`)."""
ACTUATOR_RESOLUTION = 1e-5
"""mm: an actuator position closer than this to 0 is shown as 0 (a pose may sit 1e-9 m beyond a stroke end)."""


def _ui(name: str, value_si: float) -> float:
    return round(value_si * PARAM_INFO[name]["ui_scale"], 6)


def _vector(name: str, values=(0.0, 0.0)) -> TypedGroup:
    """The group of a typed vector (:data:`VECTORS`), applied on Enter or after :data:`QUIET` seconds."""
    keys, unit, bound, _labels = VECTORS[name]
    quantities = [Quantity(key, unit, 1.0, -bound, bound, places=1 if unit == "mm" else None) for key in keys]
    return TypedGroup({q.name: TypedField(q, v) for q, v in zip(quantities, values, strict=True)}, quiet=QUIET)


def _vector_box(gui, name: str, values=(0.0, 0.0), hint: str = TYPED_HINT) -> TypedBox:
    keys, _unit, _bound, labels = VECTORS[name]
    return TypedBox(gui, _vector(name, values), dict(zip(keys, labels, strict=True)), dict.fromkeys(keys, hint))


def _actuators(stroke_mm: float, d_mm) -> TypedGroup:
    """The typed actuator positions (mm), each in the stroke ``[0, Δd]``, applied on Enter or after :data:`QUIET`."""
    return TypedGroup(
        {
            key: TypedField(Quantity(key, "mm", 1.0, 0.0, stroke_mm, ACTUATOR_RESOLUTION, places=1), float(value))
            for key, value in zip(ACTUATOR_LABELS, d_mm, strict=True)
        },
        quiet=QUIET,
    )


def _params_group(params: Params) -> TypedGroup:
    """The parameter fields (UI units: mm, kg), applied together by Enter or *Apply parameters* only."""
    return TypedGroup(
        {
            name: TypedField(Quantity(PARAM_NAMES.get(name, name), PARAM_INFO[name]["ui_unit"]), _ui(name, value))
            for name, value in ((name, getattr(params, name)) for name in PARAM_LABELS)
        }
    )


class Panel:
    """GUI handles of one tab (its :class:`~.worded.TabGui`); callbacks are attached by the client view."""

    def __init__(
        self, gui: TabGui, state: AppState, extra_tabs=None, later: Callable[[str], object] | None = None
    ) -> None:
        """``extra_tabs(group, tabs)`` adds the teaching layer's tabs of each group; with ``later`` (which builds a
        group's deferred tabs: :meth:`.teaching.tabs.Teaching.open`) the *Equations* tab waits for
        :meth:`add_equations`, after the *Player*."""
        self._gui = gui
        self._later = later
        self._equations: Worded | None = None  # the Equations tab's text (None until that tab is built)
        self._shown_params: Params | None = None
        self._shown_load: Load | None = None
        self._written: dict[int, object] = {}
        self._dashboard_at = 0.0
        stroke_mm = state.params.stroke * 1e3
        self.frame_camera = gui.add_button("Frame the mechanism", icon=viser.Icon.FOCUS_CENTERED, color="gray")
        self.guide = gui.add_folder("Start here", visible=False)
        """The first visit's guide (what to drag, the colours, the singularities): shown by :mod:`.guide`."""
        with self.guide:
            gui.add_html(GUIDE_HTML)
            self.guide_done = gui.add_button("Got it", icon=viser.Icon.CHECK, hint="Not shown again in this browser")
        self.dashboard = gui.add_html("")
        self.message = gui.add_html("")
        """The tab's message line (:meth:`tell`): text only, however it was made (a share link's label, a file
        name, what was typed)."""
        self.restore = gui.add_button(
            "Restore my own copy from before the drop",
            icon=viser.Icon.RESTORE,
            visible=False,
            hint="Your own copy, as it was when the connection dropped (kept 30 minutes)",
        )
        self.groups = gui.add_tab_group()
        """The four groups of tabs (:data:`GROUPS`), each a tab holding a tab group of its own: two rows at most."""
        self.tabs: dict[str, Tabs] = {}
        explore = self.groups.add_tab(GROUPS["explore"], icon=viser.Icon.HAND_FINGER)
        with explore:
            tabs = self.tabs["explore"] = gui.add_tab_group()
        move = tabs.add_tab("Move")
        with move:
            self.p = _vector_box(gui, "p", hint="Or drag the gizmo in 3D")
            self.demo = {k: gui.add_button(DEMO_LABELS[k], color="gray") for k in DEMO_KINDS}
            self.d = [
                gui.add_slider(f"Actuator d{i + 1} (mm)", 0.0, stroke_mm, 0.1, 0.0, hint="Forward kinematics")
                for i in range(2)
            ]
            self.d_css = gui.add_html(slider_css(self.d))
            d_mm = [float(x) * 1e3 for x in state.pose.d]
            self.d_typed = TypedBox(
                gui, _actuators(stroke_mm, d_mm), ACTUATOR_LABELS, dict.fromkeys(ACTUATOR_LABELS, ACTUATOR_HINT)
            )
            self.switch_mode = gui.add_button("Switch assembly mode", icon=viser.Icon.SWITCH_HORIZONTAL)
            self.home = gui.add_button("Home (p = 0)", icon=viser.Icon.HOME)
            self.move_note = Note(gui)
            gui.add_html(legend_html())
        forces = tabs.add_tab("Forces")
        with forces:
            self.load_mode = gui.add_dropdown("Load", LOAD_MODES, initial_value="static")
            self.f_ext = _vector_box(gui, "f_ext")
            self.dp = _vector_box(gui, "dp")
            self.ddp = _vector_box(gui, "ddp")
            self.forces_note = Note(gui)
            gui.add_markdown(Markdown("Trajectories (the paper's line and circle, your CSV): *Player* tab."))
        extra = extra_tabs if extra_tabs is not None else (lambda group, tabs: None)
        extra("explore", tabs)  # the teaching layer's tabs of each group (ui/teaching/tabs.py)
        self.fold = gui.add_html(fold_css(explore, (move, forces)))
        with self.groups.add_tab(GROUPS["teach"], icon=viser.Icon.SCHOOL):
            tabs = self.tabs["teach"] = gui.add_tab_group()
        extra("teach", tabs)
        if later is None:
            self.add_equations()
        with self.groups.add_tab(GROUPS["lab"], icon=viser.Icon.FLASK):
            tabs = self.tabs["lab"] = gui.add_tab_group()
        extra("lab", tabs)
        with self.groups.add_tab(GROUPS["setup"], icon=viser.Icon.SETTINGS):
            tabs = self.tabs["setup"] = gui.add_tab_group()
        with tabs.add_tab("Parameters"):
            self.params = TypedBox(gui, _params_group(state.params), PARAM_LABELS, note=False)
            self.apply = gui.add_button("Apply parameters", icon=viser.Icon.CHECK)
            self.paper = gui.add_button("Paper values (Tables 1-2)", color="gray")
            self.params.add_note(gui)
        with tabs.add_tab("Class & view"):
            self.own_copy = gui.add_checkbox(
                "Work on my own copy", False, hint="Off: everyone shares the lecturer's mechanism"
            )
            self.class_info = gui.add_html("")
            self.show_toggles = {k: gui.add_checkbox(label, True) for k, label in SHOW_LABELS.items()}
            self.presentation = gui.add_checkbox(
                "Presentation mode", False, hint="Large type, thick lines and a wider panel: for a projector"
            )

    def show(self, frame: Snapshot, lang: Lang = Lang.EN) -> None:
        """Write every value of the frame's state and readout into the widgets (viser skips unchanged ones), the
        dashboard's messages in ``lang``."""
        state, readout = frame.state, frame.readout
        now = time.monotonic()
        every = LIVE_NUMBERS_INTERVAL if frame.numbers_every is None else frame.numbers_every
        due = not frame.in_drag or now - self._dashboard_at >= every
        if due:  # mid-drag the numbers are refreshed at most 4 times a second, less on a busy server (bench_load.py)
            self.dashboard.content = frame.dashboard_in(lang)
            self._dashboard_at = now
        equations = self._equations
        if equations is not None and (not frame.in_drag or not equations.content):
            equations.content = frame.equations_in(lang)
        stroke_mm = state.params.stroke * 1e3
        for i, slider in enumerate(self.d):
            if slider.max != stroke_mm:
                slider.max = stroke_mm
            if due:
                self._put(slider, min(max(round(float(readout.d[i]) * 1e3, 2), 0.0), stroke_mm))
        self.d_typed.group.limit(0.0, stroke_mm)
        if due:
            self.p.show({"p1": float(readout.p[0]) * 1e3, "p2": float(readout.p[1]) * 1e3})
            self.d_typed.show({"d1": float(readout.d[0]) * 1e3, "d2": float(readout.d[1]) * 1e3})
        if state.load != self._shown_load:
            self._shown_load = load = state.load
            self._put(self.load_mode, load.mode)
            for box, values in ((self.f_ext, load.f_ext), (self.dp, load.dp), (self.ddp, load.ddp)):
                box.show(dict(zip(box.group.fields, map(float, values), strict=True)))
        if state.params != self._shown_params:
            self.show_params(state.params)
        if due:
            tau = readout.forces.tau
            self.forces_note.notes = (note,) if (note := force_note(_largest(tau))) is not None else ()
            self.draw_notes(lang, now)

    @property
    def equations(self) -> Worded:
        """The *Equations* tab's text (the tab built now if it was not yet)."""
        if self._equations is None and self._later is not None:
            self._later("teach")
        if self._equations is None:
            raise AttributeError("the Equations tab is not built (the tab is closed or still being built)")
        return self._equations

    def add_equations(self, frame: Snapshot | None = None, lang: Lang = Lang.EN) -> None:
        """The *Equations* tab, last of the *Teach* group, with ``frame``'s numbers in ``lang`` (once)."""
        if self._equations is not None:
            return
        with self.tabs["teach"].add_tab("Equations"):
            self._gui.add_markdown(
                Markdown(
                    "The paper's procedure (a)-(e) with the current numbers (refreshed when you release the platform "
                    "and at every trajectory sample you pause on or scrub to)."
                )
            )
            self._equations = self._gui.add_html("" if frame is None else frame.equations_in(lang))

    def draw_notes(self, lang: Lang, now: float | None = None) -> None:
        """Every note of the panel, in ``lang`` (viser gets only the changed ones)."""
        for box in self.boxes().values():
            box.draw(lang, now)
        for note in (self.move_note, self.forces_note):
            note.draw(lang)

    def boxes(self) -> dict[str, TypedBox]:
        """The typed boxes of the panel, by the name of what they hold."""
        return {
            "p": self.p,
            "d": self.d_typed,
            "f_ext": self.f_ext,
            "dp": self.dp,
            "ddp": self.ddp,
            "params": self.params,
        }

    def forget(self, inputs: bool = True) -> None:
        """Write every widget again at the next :meth:`show` (``inputs=False``: not over what the page sent since)."""
        self._shown_params = self._shown_load = None
        if inputs:
            self._written.clear()

    def _put(self, handle, value) -> None:
        """Write a widget value and remember it (see :meth:`is_echo`), never over a value the page sent since
        (:mod:`tpm_viz.viserkit.inputs`): that input's callback applies it (or refuses it and shows the state
        again); writing first would make it look like an echo and lose it."""
        if self._written.get(id(handle), _UNSET) == value and handle.value != value:
            return
        if put(handle, value):
            self._written[id(handle)] = stored(handle)

    def is_echo(self, *handles) -> bool:
        """Whether these widgets still hold the values the server wrote last: then a callback that reads them
        is a late duplicate of an event already applied, not new user input (viser only reports changes)."""
        return all(self._written.get(id(h), _UNSET) == h.value for h in handles)

    def show_params(self, params: Params, force: bool = False) -> None:
        """Write the parameters in use into their fields (``force``: over what is typed there, e.g. after *Paper
        values*)."""
        self._shown_params = params
        self.params.show({name: _ui(name, getattr(params, name)) for name in PARAM_LABELS}, force)

    def tell(self, text: str) -> None:
        """Show a message to this tab only (empty text clears it), as text: whatever it quotes is never markup."""
        content = html(MESSAGE, text=text) if text else Html("")
        if self.message.content != content:  # every commit clears it: skip viser's setter when already clear
            self.message.content = content


def _largest(tau) -> float | None:
    """The largest ``|τ_i|`` [N], or None if the forces are unknown."""
    if tau is None:
        return None
    return max(abs(float(t)) for t in tau)
