"""How one tab looks on its screen: the phone layout, presentation mode, and a camera framed for the tab's canvas.

**Layout.** On a wide screen the control panel is docked to the right edge (viser's dock, :func:`dock_panel`): the
3D canvas is the rest of the window, so the panel never hides the mechanism. On a phone (a window at most 36em
wide: viser's own breakpoint, where it shows the panel as a sheet along the bottom) the style sheet
:data:`PHONE_CSS` makes the sheet the full width and :data:`SHEET` of the height and shrinks the canvas to the part
above it (all but the sheet's handle while the sheet is collapsed), and makes every control at least :data:`TOUCH` CSS
pixels across (wide equations scroll sideways in their own boxes).
Either way the canvas is the free part of the screen, so the camera frames the mechanism in the whole canvas
(:mod:`tpm_viz.ui.widgets.framing`): the server only needs the canvas's aspect ratio, which each camera message carries.
The camera is framed again when that ratio changes (a rotated phone, a resized window, a collapsed panel), not
when the viewer orbits or zooms.

**Presentation mode** (a checkbox of the *Class & view* tab, per tab): the stage of a projector. The control panel
folds to its rail (viser's ``minimize``: the 3D canvas is then the whole screen but the rail) and one click on the rail
brings it back for the lecturer. A box of live numbers floats over the bottom of the canvas while the panel is folded
(a separate viser panel, shown by the style sheet only then; the framing keeps its band free): the pose status and
its warnings at :data:`BANNER_PX`, p, d, τ₁ and τ₂ with their bars at :data:`READOUT_PX` CSS pixels. With the panel
open, its readout is the same compact one (:data:`~.panel_css.FOLDED` left out) in large, dark type, the panel wider
(:data:`PRESENTATION_WIDTH`); thicker lines and larger labels in 3D (:mod:`.tabscene`), the player's charts with 18 px
dark axes (:data:`~.teaching.player.charts.LARGE`). All of it is this tab's own: the style sheet is an HTML element of
the tab's GUI, and every tab's GUI is its own.

Nothing here computes; the style sheets are constants, and the messages are words of :mod:`tpm_viz.core.words`.
"""

from __future__ import annotations

import math
import threading
from typing import Any

import numpy as np
import viser

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.markup import Html, html
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, T
from tpm_viz.drawing import meshes
from tpm_viz.ui.language import KEEP_ALL
from tpm_viz.ui.panel_css import FOLDED
from tpm_viz.ui.scene import camera_pose
from tpm_viz.ui.widgets.framing import LIVE_BAND, frame_box
from tpm_viz.viserkit.core import point_camera, widget_uuid

__all__ = [
    "BUTTON_TOUCH",
    "HANDLE",
    "LIVE_LABEL",
    "PANEL_WIDTH",
    "PHONE_CSS",
    "PRESENTATION_CSS",
    "PRESENTATION_WIDTH",
    "READOUT_PX",
    "SHEET",
    "TOUCH",
    "Look",
    "dock_panel",
    "frame_camera",
    "frame_row_css",
    "mechanism_box",
]

PANEL_WIDTH = 384
"""Width of the docked panel [CSS px] (viser's ``control_width="large"``, 24em)."""
PRESENTATION_WIDTH = 440
"""Width of the docked panel in presentation mode [CSS px]: the readouts at :data:`READOUT_PX` fit on one line."""
READOUT_PX = 22
"""Font size of the readouts and forces in presentation mode [CSS px] (at least 20 px on a 1024 x 768 projector)."""
SHEET = 0.45
"""Height of the panel's sheet on a phone [fraction of the window height]; the canvas is the rest above it."""
TOUCH = 24
"""Least width and height of a control on a phone [CSS px] (WCAG 2.2 target size, level AA)."""
BUTTON_TOUCH = 44
"""Least width and height of a button, tab or icon button on a phone [CSS px] (WCAG 2.2 target size, level AAA)."""
ASPECT_CHANGE = 0.01
"""Relative change of a canvas's aspect ratio that frames the camera again (a pixel of rounding does not)."""
RESIZE_ASKS = (0.3, 1.0, 3.0)
"""When, after the panel changes width [s], the tab is asked for its canvas size again (:meth:`Look.ask_canvas`):
viser's page reports a resize with the canvas's drawing-buffer size, which its renderer may not have updated yet."""
FOV_NUDGE = 2e-5
"""Relative change of the field of view [-] that makes the page send its camera (and canvas size) again: the least
that viser's camera setter does not drop as unchanged (``np.allclose``), a 0.002 % zoom that nobody sees."""
LIVE_WIDTH = 640
"""Width of the box of live numbers [CSS px] (presentation mode, while the panel is folded to its rail)."""
LIVE_GAP = 12
"""Gap between that box and the canvas's left and bottom edges [CSS px]."""
LIVE_CHROME = 64
"""Height of that box's frame [CSS px]: its grip, its tab and :data:`LIVE_GAP`; the box, frame included, stays
within the bottom :data:`~tpm_viz.ui.widgets.framing.LIVE_BAND` of the window that the framing keeps free."""
LIVE_LABEL = T("Warnings and forces")
"""Tab name of the box of banner and forces (presentation mode; shown in the tab's language by its handle)."""

_PHONE = "(max-width: 36em)"  # viser's mobile breakpoint (Mantine's xs): the panel is a bottom sheet
_SHEET_CSS = '.mantine-Paper-root[style*="position: fixed"]'  # viser's sheet (its only fixed Paper)
_OPEN = 'div[style*="width: 20em"] > [aria-hidden="false"]'  # the sheet's contents, shown
_SHUT = 'div[style*="width: 20em"] > [aria-hidden="true"]'  # the sheet's contents, collapsed to its handle
HANDLE = 48
"""Height of the phone sheet's handle [CSS px] (viser: 3.5em of its 13.3 px type): the canvas is the rest while the
sheet is collapsed to it."""
_SHEET_PCT = round(SHEET * 100)
INSET = 16
"""Room at the right of the readout and the force column [CSS px]: the panel's scroll bar (11 px, drawn over its
content) and 5 px to spare, so "N" never touches the panel's edge."""
PHONE_CSS = Html(f"""<style>
div:has(> [data-q="banner"]) {{ padding-right: {INSET}px; }}
label wbr {{ display: none; }}
@media {_PHONE} {{
  [data-guide] > div > span {{ max-width: 100%; overflow-wrap: anywhere; }}
  {_SHEET_CSS} {{ width: 100% !important; left: 0 !important; right: 0 !important; }}
  {_SHEET_CSS} {{ max-height: {_SHEET_PCT}vh !important; }}
  {_SHEET_CSS}:has({_OPEN}) {{ height: {_SHEET_PCT}vh !important; }}
  {_SHEET_CSS} div[style*="width: 20em"] {{ width: 100% !important; }}
  div:has(> div > canvas[data-engine]) {{ height: {100 - _SHEET_PCT}vh !important; }}
  body:has({_SHEET_CSS} {_SHUT}) div:has(> div > canvas[data-engine]) {{
    height: calc(100vh - {HANDLE}px) !important; }}
}}
@media {_PHONE}, (pointer: coarse) {{
  .mantine-Slider-root {{ min-height: {TOUCH}px; }}
  .mantine-Slider-thumb {{ width: {TOUCH}px !important; height: {TOUCH}px !important; border-radius: 50% !important;
    background: #fff !important; }}
  .mantine-Checkbox-input, .mantine-Checkbox-inner {{ width: {TOUCH}px !important; height: {TOUCH}px !important; }}
  .mantine-Input-input {{ min-height: {TOUCH}px !important; }}
  .mantine-Button-root, .mantine-Tabs-tab {{ min-height: {BUTTON_TOUCH}px !important; }}
  .mantine-ActionIcon-root {{ min-width: {BUTTON_TOUCH}px !important; min-height: {BUTTON_TOUCH}px !important; }}
}}
</style>""")
"""The readout's room at the panel's edge (:data:`INSET`), the phone layout and touch targets (by viewport and
pointer: no switch), in every tab; labels break at spaces only (viser puts a ``<wbr>`` after each ``_`` and ``/``:
``F_max`` was cut after ``F_``)."""

BANNER_PX = 20
"""Font size of the pose status and its warnings in the box of live numbers [CSS px]."""

PRESENTATION_CSS = Html(f"""<style>
div:has(> [data-q="banner"]) {{ color: #0f172a; padding-right: {INSET}px; }}
[data-q="banner"] {{ font-size: {BANNER_PX}px !important; }}
div:has(> [data-q="banner"]) td {{ font-size: 17px !important; color: #0f172a !important; }}
div:has(> [data-q="banner"]) > div:last-child, div:has(> [data-q="banner"]) > div:last-child div {{
  font-size: 17px !important; color: #0f172a !important; }}
div:has(> [data-q="banner"]) td [data-q], [data-q="tau1"], [data-q="tau2"] {{ font-size: {READOUT_PX}px !important; }}
div:has(> [data-q="banner"]) [style*="grid-template-columns"] {{ grid-template-columns: 1.4em 1fr 7.2em !important; }}
div:has(> [data-q="banner"]) [style*="grid-template-columns"] > span {{ white-space: nowrap; }}
.mantine-Paper-root label, .mantine-Button-label, .mantine-Tabs-tab, .mantine-Checkbox-label,
.mantine-Paper-root .mantine-Text-root {{ font-size: 15px !important; color: #0f172a; letter-spacing: 0 !important; }}
.uplot .u-title {{ font-size: 17px !important; color: #0f172a; }}
.uplot .u-legend {{ font-size: 15px !important; }}
.uplot .u-legend .u-label {{ color: #0f172a; }}
{", ".join(FOLDED)} {{ display: none; }}
[data-floating-window]:has([data-live]) {{ visibility: hidden; pointer-events: none; }}
body:has([data-dock-rail-root]) [data-floating-window]:has([data-live]) {{ visibility: visible; pointer-events: auto; }}
[data-live] {{ max-height: calc({round(LIVE_BAND * 100)}vh - {LIVE_CHROME}px); overflow-y: auto; }}
[data-live] [data-q="banner"] {{ font-size: {BANNER_PX}px !important; padding: 3px 8px !important; }}
[data-live] table {{ margin-top: 2px !important; }}
[data-live] tbody {{ display: flex; flex-wrap: wrap; column-gap: 1.2em; }}
@media {_PHONE} {{ div:has(> div > [data-live]) {{ display: none !important; }} }}
</style>""")
"""Presentation mode: large, dark type (the charts' titles and legends too; their axes are drawn on a canvas, sized by
:meth:`~.teaching.player.charts.Charts.set_presentation`); the box of banner and forces shown only while the panel is
collapsed."""


def frame_row_css(language: Any, button: Any) -> Html:
    """The panel's first row: the *Language* selector (``language``) and *Frame the mechanism* (``button``, the next
    control) side by side, 45 % and 55 % of the width (the root of the panel is a block: a float), so that the button
    costs no height above the tabs. Empty for a GUI without a page (a test's stand-in)."""
    try:
        selector, uuid = widget_uuid(language), widget_uuid(button)
    except AttributeError:
        return Html("")
    row = f'div:has(> div > div > p > label[for="{selector}"])'
    wrapper = f'div:has(> button[id="{uuid}"])'
    return Html(
        f"<style>{row} {{ float: left; width: 45%; }}"
        f" {wrapper} {{ margin-left: calc(45% + 4px) !important; }} {wrapper} ~ * {{ clear: both; }}"
        f" {wrapper} > button {{ width: 100%; }}</style>"
    )


def mechanism_box(params: Params) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners [m] of the box around the mechanism: the base plate up to the top of the pins."""
    lo, hi = meshes.base_extent(params)
    return np.array([lo, lo, -0.012]), np.array([hi, hi, meshes.PIN_Z[1]])


def _canvas(client: viser.ClientHandle) -> tuple[float, float] | None:
    """The tab's vertical field of view [rad] and canvas aspect ratio, or None before its canvas has a size."""
    try:
        camera = client.camera
        width, height, fov = camera.image_width, camera.image_height, float(camera.fov)
    except AssertionError:  # no camera message yet
        return None
    if width <= 0 or height <= 0 or not 0.0 < fov < math.pi:
        return None
    return fov, width / height


def frame_camera(client: viser.ClientHandle, params: Params, presentation: bool = False) -> float | None:
    """Point the tab's camera at the whole mechanism, framed for its canvas; return the aspect ratio framed for
    (None: the canvas has no size yet, and the default pose of :func:`~.scene.camera_pose` is used)."""
    canvas = _canvas(client)
    if canvas is None:
        position, look_at = camera_pose(params)
    else:
        framing = frame_box(*mechanism_box(params), canvas[0], canvas[1], presentation)
        position, look_at = framing.position, framing.look_at
    point_camera(client.camera, position, look_at)  # viser's two setters in one step (viserkit/core.py)
    return None if canvas is None else canvas[1]


def dock_panel(gui: Any, width: float = PANEL_WIDTH) -> None:
    """Dock the control panel to the right edge, ``width`` CSS pixels wide (``server.gui`` or a tab's ``gui``)."""
    panel = gui.main_panel
    panel.dock_right()
    panel.set_width(width)


class Look:
    """The look of one tab (``view``: its :class:`~.client.ClientView`): its style sheet, presentation mode, the
    box of banner and forces, and the camera framing that follows the canvas's aspect ratio."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self.presentation = False
        self._aspect: float | None = None  # the canvas aspect the camera was last framed for
        self._asks: list[threading.Timer] = []
        self._nudge = 1.0
        gui = view.gui
        self.style = gui.add_html(PHONE_CSS)
        self.row = gui.add_html(frame_row_css(view.words.selector, view.panel.frame_camera))
        """*Language* and *Frame the mechanism* on one row (its own style sheet)."""
        self.live: Any = None  # the box of banner and forces (a viser panel), made when first needed
        self.live_html: Any = None
        self.live_style: Any = None
        view.client.camera.on_update(self._on_camera)
        view.panel.presentation.on_update(self._on_presentation)

    # -- the camera ---------------------------------------------------------------------------------------------
    def frame(self, params: Params) -> None:
        """Frame the camera on the mechanism for this tab's canvas (under the hub's lock)."""
        self._aspect = frame_camera(self.view.client, params, self.presentation)

    @guarded
    def _on_camera(self, camera: Any) -> None:
        """A camera message: frame again if the canvas's aspect ratio changed (not for an orbit or a zoom)."""
        canvas = _canvas(camera.client)
        if canvas is None:
            return
        if self._aspect is not None and abs(canvas[1] / self._aspect - 1.0) <= ASPECT_CHANGE:
            return
        view = self.view
        with view.hub.locked():
            if view.closed:
                return
            view.frame_camera(view.session.state.params)
            view.client.flush()

    def ask_canvas(self) -> None:
        """Ask the page for its camera and canvas size again, :data:`RESIZE_ASKS` after a change of the panel's
        width: an answer with another aspect ratio frames the camera again (:meth:`_on_camera`)."""
        for timer in self._asks:
            timer.cancel()
        self._asks = [threading.Timer(delay, self._ask) for delay in RESIZE_ASKS]
        for timer in self._asks:
            timer.daemon = True
            timer.start()

    @guarded
    def _ask(self) -> None:
        view = self.view
        with view.hub.locked():
            if view.closed:
                return
            camera = view.client.camera
            try:
                fov = float(camera.fov)
            except AssertionError:  # no camera message yet: the first one frames the camera
                return
            self._nudge = -self._nudge  # up, then back: viser's page answers a new field of view with its camera
            camera.fov = fov * (1.0 + self._nudge * FOV_NUDGE)
            view.client.flush()

    def close(self) -> None:
        """The tab went away: no more questions to its page."""
        for timer in self._asks:
            timer.cancel()
        self._asks = []

    # -- presentation mode -------------------------------------------------------------------------------------
    @guarded
    def _on_presentation(self, event: Any) -> None:
        if getattr(event, "client", None) is None:  # the server's own write, echoed
            return
        view = self.view
        with view.hub.locked():
            if view.closed:
                return
            self.set_presentation(bool(view.panel.presentation.value))
            view.client.flush()

    def set_presentation(self, on: bool) -> None:
        """Turn presentation mode on or off for this tab (under the hub's lock)."""
        on = bool(on)
        if on == self.presentation:
            return
        self.presentation = on
        client = self.view.client
        self.style.content = PHONE_CSS + (PRESENTATION_CSS if on else "")
        dock_panel(client.gui, PRESENTATION_WIDTH if on else PANEL_WIDTH)
        if on:  # the controls fold to the rail for the audience; one click on the rail brings them back
            client.gui.main_panel.minimize()
        else:
            client.gui.main_panel.expand()
        if on and self.live is None:
            self.live = self.view.gui.add_panel()
            with self.live.add_tab(LIVE_LABEL.template):
                self.live_html = self.view.gui.add_html("")
                # the panel's style sheets are unmounted with it when it collapses: this box carries its own
                self.live_style = self.view.gui.add_html("")
                # the panel's *Frame the mechanism*, one tap away with the panel folded too
                frame = self.view.gui.add_button("Frame the mechanism", icon=viser.Icon.FOCUS_CENTERED, color="gray")
                frame.on_click(self.view.on_frame)
            self.live.float(x=LIVE_GAP, y=-LIVE_GAP, width=LIVE_WIDTH)
        if self.live is not None:
            self.live.visible = on
        self.view.scene.set_presentation(on)
        teaching = getattr(self.view, "teaching", None)  # None only while the tab is being built
        if teaching is not None:
            teaching.set_presentation(on)
        self.show()
        self.view.frame_camera(self.view.session.state.params)
        self.ask_canvas()

    def show(self) -> None:
        """Copy the panel's dashboard into the box of banner and forces (presentation mode only)."""
        if not self.presentation or self.live_html is None:
            return
        content = html('<div data-live="1">{dashboard}</div>', dashboard=self.view.panel.dashboard.content)
        if self.live_html.content != content:
            self.live_html.content = content
        style = PRESENTATION_CSS + (KEEP_ALL if self.view.lang is Lang.KO else "")
        if self.live_style.content != style:
            self.live_style.content = style
