"""The control panel of one browser tab: GUI handles built once, values written by :meth:`Panel.show`.

No maths here: the numbers come from a :class:`~tpm_viz.app.readouts.Readout`, formatted by :mod:`.text`.
Units in labels: mm, N, kg, s, degrees (SI inside; the scale factors come from ``PARAM_INFO``).
"""

from __future__ import annotations

import time

import viser

from tpm_viz.app.poses import DEMO_KINDS
from tpm_viz.app.readouts import LOAD_MODES, Load
from tpm_viz.app.state import AppState
from tpm_viz.params import PARAM_INFO, Params
from tpm_viz.ui.snapshot import Snapshot
from tpm_viz.ui.text import legend_html
from tpm_viz.words import Lang

__all__ = ["PARAM_LABELS", "Panel"]

LIVE_DASHBOARD_INTERVAL = 0.25
"""Shortest time [s] between two refreshes of the dashboard, ``p`` and ``d`` on the intermediate frames of a drag or
a playback (the scene itself moves at every frame; the frame where the motion stops is always shown). Each refresh
evaluates both models (closed form and Pinocchio, ~0.2 ms more), so that the two numbers shown side by side always
belong to the same state; 4 Hz keeps 30 tabs dragging at 20 Hz within the load target."""

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


def _ui(name: str, value_si: float) -> float:
    return round(value_si * PARAM_INFO[name]["ui_scale"], 6)


class Panel:
    """GUI handles of one tab (``client.gui``); callbacks are attached by the client view."""

    def __init__(self, gui: viser.GuiApi, state: AppState, extra_tabs=None) -> None:
        self._gui = gui
        self._shown_params: Params | None = None
        self._shown_load: Load | None = None
        self._written: dict[int, object] = {}
        self._dashboard_at = 0.0
        stroke_mm = state.params.stroke * 1e3
        self.dashboard = gui.add_html("")
        self.message = gui.add_markdown("")
        self.restore = gui.add_button(
            "Restore my own copy from before the drop",
            icon=viser.Icon.RESTORE,
            visible=False,
            hint="Your own copy, as it was when the connection dropped (kept 30 minutes)",
        )
        tabs = gui.add_tab_group()
        with tabs.add_tab("Move"):
            self.p = gui.add_vector2("Platform p (mm)", (0.0, 0.0), step=0.1, hint="Or drag the gizmo in 3D")
            self.d = [
                gui.add_slider(f"Actuator d{i + 1} (mm)", 0.0, stroke_mm, 0.1, 0.0, hint="Forward kinematics")
                for i in range(2)
            ]
            self.switch_mode = gui.add_button("Switch assembly mode", icon=viser.Icon.SWITCH_HORIZONTAL)
            self.home = gui.add_button("Home (p = 0)", icon=viser.Icon.HOME)
            self.demo = {k: gui.add_button(DEMO_LABELS[k], color="gray") for k in DEMO_KINDS}
        with tabs.add_tab("Forces"):
            self.load_mode = gui.add_dropdown("Load", LOAD_MODES, initial_value="static")
            self.f_ext = gui.add_vector2("External load on platform f_ext (N)", (0.0, 0.0), step=1.0)
            self.dp = gui.add_vector2("Platform velocity ṗ (m/s)", (0.0, 0.0), step=0.01)
            self.ddp = gui.add_vector2("Platform acceleration p̈ (m/s²)", (0.0, 0.0), step=0.1)
            gui.add_markdown("Trajectories (the paper's line and circle, your CSV): *Player* tab.")
        if extra_tabs is not None:  # the teaching layer's tabs (ui/teaching.py)
            extra_tabs(tabs)
        with tabs.add_tab("Parameters"):
            self.params = {
                name: gui.add_number(PARAM_LABELS[name], _ui(name, getattr(state.params, name)), step=0.01)
                for name in PARAM_LABELS
            }
            self.apply = gui.add_button("Apply parameters", icon=viser.Icon.CHECK)
            self.paper = gui.add_button("Paper values (Tables 1-2)", color="gray")
        with tabs.add_tab("Equations"):
            gui.add_markdown(
                "The paper's procedure (a)-(e) with the current numbers (refreshed when you release the platform "
                "and at every trajectory sample you pause on or scrub to)."
            )
            self.equations = gui.add_html("")
        with tabs.add_tab("Class & view"):
            self.own_copy = gui.add_checkbox(
                "Work on my own copy", False, hint="Off: everyone shares the lecturer's mechanism"
            )
            self.class_info = gui.add_markdown("")
            self.show_toggles = {k: gui.add_checkbox(label, True) for k, label in SHOW_LABELS.items()}
            gui.add_html(legend_html())
            self.frame_camera = gui.add_button("Snapshot the mechanism", icon=viser.Icon.FOCUS_CENTERED)

    def show(self, frame: Snapshot, lang: Lang = Lang.EN) -> None:
        """Write every value of the frame's state and readout into the widgets (viser skips unchanged ones), the
        dashboard's messages in ``lang``."""
        state, readout = frame.state, frame.readout
        now = time.monotonic()
        due = not frame.in_drag or now - self._dashboard_at >= LIVE_DASHBOARD_INTERVAL
        if due:  # mid-drag the numbers are refreshed at most 10 times a second (load: bench_load.py)
            self.dashboard.content = frame.dashboard_in(lang)
            self._dashboard_at = now
        if not frame.in_drag or not self.equations.content:
            self.equations.content = frame.equations
        stroke_mm = state.params.stroke * 1e3
        for i, slider in enumerate(self.d):
            if slider.max != stroke_mm:
                slider.max = stroke_mm
            if due:
                self._put(slider, min(max(round(float(readout.d[i]) * 1e3, 2), 0.0), stroke_mm))
        if due:
            self._put(self.p, (round(float(readout.p[0]) * 1e3, 2), round(float(readout.p[1]) * 1e3, 2)))
        if state.load != self._shown_load:
            self._shown_load = load = state.load
            self._put(self.load_mode, load.mode)
            self._put(self.f_ext, load.f_ext)
            self._put(self.dp, tuple(round(v, 6) for v in load.dp))
            self._put(self.ddp, tuple(round(v, 6) for v in load.ddp))
        if state.params != self._shown_params:
            self.show_params(state.params)

    def forget(self) -> None:
        """Write every widget again at the next :meth:`show` (after a refused input left the browser's value)."""
        self._shown_params = self._shown_load = None
        self._written.clear()

    def _put(self, handle, value) -> None:
        """Write a widget value and remember it (see :meth:`is_echo`)."""
        handle.value = value
        self._written[id(handle)] = handle.value

    def is_echo(self, *handles) -> bool:
        """Whether these widgets still hold the values the server wrote last: then a callback that reads them
        is a late duplicate of an event already applied, not new user input (viser only reports changes)."""
        return all(self._written.get(id(h), _UNSET) == h.value for h in handles)

    def show_params(self, params: Params) -> None:
        """Write the parameter inputs (also to revert a refused edit)."""
        self._shown_params = params
        for name, handle in self.params.items():
            handle.value = _ui(name, getattr(params, name))

    def read_params(self) -> dict[str, object]:
        """The raw values of the parameter inputs, in UI units (validated by the caller)."""
        return {name: handle.value for name, handle in self.params.items()}

    def tell(self, text: str) -> None:
        """Show a message to this tab only (empty text clears it)."""
        content = f"**{text}**" if text else ""
        if self.message.content != content:  # every commit clears it: skip viser's setter when already clear
            self.message.content = content
