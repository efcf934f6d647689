"""The teaching layer of one tab, in one object: the trajectory player, the singularity explorer, the guided
demonstrations, the control lab and the motion planner, and the per-hub services they share (background workers,
map cache, trajectory runs).

:class:`~.client.ClientView` needs four calls: :meth:`Teaching.build_tabs` while its panel builds the tab group,
:meth:`Teaching.attach` once it has joined a session, :meth:`Teaching.render` for every frame (under the hub's
lock) and :meth:`Teaching.close`; :meth:`Teaching.switched` when the tab moves to another session.

A tab is built in two steps, so that a class reconnecting at once gets its mechanisms back first
(``benchmarks/bench_reconnect.py``): *Explorer* and *Demos* with the panel, the tabs of :data:`LATER` (*Player*,
*Exercises* and the panel's *Equations* in *Teach*; *Control*, *Planner* and *Design* in *Lab*) by
:meth:`Teaching.open`, which the tab hands to the hub's :class:`~tpm_viz.classroom.later.Later` (run once no tab has
arrived for a moment) and which runs at once for anyone who asks for one of those views (:attr:`Teaching.player`,
...). Each group's tabs are appended in their usual order, after the ones built first: the tab looks the same either
way. The lesson's exercises under its text in *Demos* are built with it (:mod:`.exercises`).
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import viser

from tpm_viz.app.lessons import DEMOS, PROBLEMS, Demo
from tpm_viz.classroom.later import Later
from tpm_viz.classroom.runhub import RunHub
from tpm_viz.classroom.session import Hub, Session, View
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.worker import Worker
from tpm_viz.ui.teaching.control.tab import ControlView
from tpm_viz.ui.teaching.design.tab import DesignView
from tpm_viz.ui.teaching.exercises.tab import TAB, ExercisesView
from tpm_viz.ui.teaching.explorer import ExplorerView, MapService
from tpm_viz.ui.teaching.lessons import DemosView
from tpm_viz.ui.teaching.planner.tab import PlannerView
from tpm_viz.ui.teaching.player.tab import PlayerView
from tpm_viz.ui.teaching.takeout.buttons import TakeOut, takeout_for
from tpm_viz.ui.worded import Tabs
from tpm_viz.viserkit.seen import tab_marker


def _open_if_open(opener: weakref.WeakMethod, group: str) -> None:
    """A deferred build that does not keep its tab alive: a tab that left before the quiet moment is freed at once
    (a storm of short visits leaves no waiting job holding a whole tab)."""
    open_ = opener()
    if open_ is not None:
        open_(group)


__all__ = ["LATER", "Services", "Teaching"]

LATER = {"teach": ("player",), "lab": ("control", "planner", "design")}
"""The groups whose tabs :meth:`Teaching.open` builds after the rest of the tab, and the views in them (the panel's
*Equations* follows the *Player*)."""


@dataclass
class Services:
    """What the tabs of one hub share."""

    worker: Worker
    """The fair queue of every tab's heavy jobs (runs, maps, control simulations, plans): tabs take turns."""
    maps: MapService
    runs: RunHub
    plans: Worker
    """The planner's worker: the same fair queue (a re-plan takes its tab's turn like any other job)."""
    lessons: tuple[Demo, ...] = field(default_factory=lambda: DEMOS)
    """The lessons of the *Demos* tab: the packaged ones, or a lecturer's (``tpm-viz serve --lessons DIR``)."""
    problems: tuple[str, ...] = field(default_factory=lambda: PROBLEMS)
    """One line per lesson file that was refused (``file:line: what is wrong``), shown in the tab."""
    later: Later | None = None
    """Where a tab's :data:`LATER` groups wait for a quiet moment (None: every tab is built whole at once)."""
    exercises: Any = None
    """The app's exercises (:class:`~tpm_viz.ui.teaching.exercises.desk.ExerciseDesk`), set by the app (None: the
    exercises show their prompts' place only)."""

    @classmethod
    def create(cls, hub: Hub, lessons: Sequence[Demo] = DEMOS, problems: Sequence[str] = PROBLEMS) -> Services:
        """The services of ``hub``: one fair worker pool for slow computations (maps, runs, control simulations,
        the planner's live re-plans), the floor maps, the runs and the lessons."""
        worker = Worker()
        runs = RunHub(hub, worker)
        return cls(worker, MapService(worker), runs, worker, tuple(lessons), tuple(problems), Later())


class Teaching:
    """Player, explorer and demonstrations of one tab (``view`` is its :class:`~.client.ClientView`)."""

    def __init__(self, view: View, services: Services) -> None:
        self.view = view
        self.services = services
        if services.later is not None:
            services.later.arrived()  # a tab is being built: the deferred tabs of the others wait
        self._player = PlayerView(view, self.services.runs)
        self.explorer = ExplorerView(view, self.services.maps)
        self.demos = DemosView(
            view, services.runs, self.explorer, lambda: self.player.speed_value(), services.lessons, services.problems
        )
        self._control = ControlView(view, self.services.worker, self.services.runs)
        self._planner = PlannerView(view, self.services.plans)
        self._design = DesignView(view, self.services.worker)  # the Design studio (ui/teaching/design/tab.py)
        self.exercises = ExercisesView(view, services, services.lessons, lambda: self.demos.index)
        """The exercises: under the lesson's text in *Demos*, and the *Exercises* tab (ui/teaching/exercises/)."""
        self._takeouts: list[TakeOut] = []  # Record clip and Download report of the player, control and planner
        self._tabs: dict[str, Tabs] = {}  # the tab groups of LATER's groups, to build them in
        self.waiting: set[str] = set()
        """The groups of :data:`LATER` not built yet (:meth:`open` builds one)."""
        self._attached = False
        self.open_tabs: frozenset[str] = frozenset()
        """The marked tabs the page shows now (:meth:`shown`): ``player``, ``control``, ``planner``, ``design``."""

    # -- the views of the deferred tabs: built when asked for --------------------------------------------------
    @property
    def player(self) -> PlayerView:
        """The *Player* tab (built now if it was not yet: :meth:`open`)."""
        self.open("teach")
        return self._player

    @property
    def control(self) -> ControlView:
        """The *Control* tab (built now if it was not yet)."""
        self.open("lab")
        return self._control

    @property
    def planner(self) -> PlannerView:
        """The *Planner* tab (built now if it was not yet)."""
        self.open("lab")
        return self._planner

    @property
    def design(self) -> DesignView:
        """The *Design* tab (built now if it was not yet)."""
        self.open("lab")
        return self._design

    @property
    def takeouts(self) -> list[TakeOut]:
        """*Record clip* and *Download report* of the player, control and planner (every tab built now)."""
        for group in LATER:
            self.open(group)
        return self._takeouts

    def built(self, group: str) -> bool:
        """Whether ``group``'s tabs exist (the groups not in :data:`LATER` always do)."""
        return group not in self.waiting

    # -- building --------------------------------------------------------------------------------------------
    def build_tabs(self, group: str, tabs: Tabs) -> None:
        """Add this layer's tabs of ``group`` (a key of :data:`~tpm_viz.ui.panels.GROUPS`) to its tab group:
        *Explorer* (the maps) in *explore*; *Demos*, *Player* and *Exercises* in *teach* (before the panel's
        *Equations*); *Control*, *Planner* and *Design* in *lab*. The tabs of :data:`LATER` are left to :meth:`open`
        when the services defer them (:attr:`Services.later`)."""
        gui = self.view.gui
        if group == "explore":
            with tabs.add_tab("Explorer", icon=viser.Icon.MAP):
                self.explorer.build(gui)
        if group == "teach":
            with tabs.add_tab("Demos", icon=viser.Icon.SCHOOL):
                self.demos.build(gui)
                self.exercises.lesson_box(gui)  # the lesson's exercises, under its text
        if group in LATER:
            self._tabs[group] = tabs
            if self.services.later is None:
                self._build(group)
            else:
                self.waiting.add(group)

    def _build(self, group: str) -> None:
        """The tabs of ``group`` in :data:`LATER`, appended to its tab group."""
        gui, tabs, worker = self.view.gui, self._tabs[group], self.services.worker
        if group == "teach":
            with tabs.add_tab("Player", icon=viser.Icon.PLAYER_PLAY):
                gui.add_html(tab_marker("player"))  # the page says when the tab is shown (ui/seen.py)
                self._player.build(gui)
                self._takeouts.append(takeout_for(self.view, worker, self._player, "player", gui))
            with tabs.add_tab(TAB.template, icon=viser.Icon.CHECKLIST) as tab:
                self.exercises.build(gui, tab)
        if group == "lab":
            with tabs.add_tab("Control", icon=viser.Icon.ADJUSTMENTS):
                gui.add_html(tab_marker("control"))
                self._control.build(gui)
                self._takeouts.append(takeout_for(self.view, worker, self._control, "control", gui))
            with tabs.add_tab("Planner", icon=viser.Icon.ROUTE):
                gui.add_html(tab_marker("planner"))
                self._planner.build(gui)
                self._takeouts.append(takeout_for(self.view, worker, self._planner, "planner", gui))
            with tabs.add_tab("Design", icon=viser.Icon.RULER_MEASURE):
                gui.add_html(tab_marker("design"))
                self._design.build(gui)

    def open(self, group: str) -> bool:
        """Build the tabs of ``group`` (a key of :data:`LATER`) now if they are not yet, drawn from the session's
        current frame, in presentation mode if the tab is in it (takes the hub's lock; idempotent). True: built
        now; False: built already, or the tab is closed or still being built (its panel does not exist yet)."""
        view = self.view
        with view.hub.locked():
            panel = getattr(view, "panel", None)
            if group not in self.waiting or panel is None or getattr(view, "closed", False):
                return False
            self.waiting.discard(group)
            with view.client.atomic():
                self._build(group)
                frame = view.session.frame
                if group == "teach":
                    panel.add_equations(frame, view.lang)
                if getattr(getattr(view, "look", None), "presentation", False):
                    self._present(group, True)
                if self._attached:
                    self._attach(group)
                if frame is not None:
                    for name in LATER[group]:
                        getattr(self, f"_{name}").render(frame)
            view.client.flush()
        return True

    def _attach(self, group: str) -> None:
        """The views of a built ``group`` of :data:`LATER` for the session the tab has joined."""
        if group == "teach":
            with self.view.hub.locked():
                self._player.refresh()
        if group == "lab":
            self._control.attach()
            self._planner.attach()

    def attach(self) -> None:
        """The tab has joined its session: draw the session's run (the first render came before that); the groups
        not built yet wait for a quiet moment (:attr:`Services.later`)."""
        self._attached = True
        for group in LATER:
            if self.built(group):
                self._attach(group)
        later = self.services.later
        if later is not None:
            later.arrived()
            for group in LATER:
                if not self.built(group):
                    later.add(functools.partial(_open_if_open, weakref.WeakMethod(self.open), group))

    def switched(self, old: Session) -> None:
        """The tab moved from ``old`` to its current session (own copy on / off)."""
        with self.view.hub.locked():
            self.services.runs.adopt(self.view.session, old)
            self._abandon(old)
            self.run_changed()

    def _abandon(self, session: Session) -> None:
        """``session`` lost its last tab: a private copy's pending jobs (a run of a 20,000-row upload) are dropped,
        not computed for nobody while they keep the copy and its tab's page alive (what the tab had is kept by
        :class:`~tpm_viz.classroom.away.Away`, its trajectory as a source, loaded again if it comes back)."""
        if not session.shared and not session.views:
            self.services.worker.leave(session)

    def run_changed(self) -> None:
        """The session's run changed: redraw the player (if its tab exists: it draws the run when built)."""
        if self.built("teach"):
            self._player.refresh()

    def shown(self, names: frozenset[str]) -> None:
        """The marked tabs the page shows now (:mod:`tpm_viz.ui.seen`; under the hub's lock): the drawing of a tab
        just opened comes to the front of the scene (the Player's trace, the Control lab's run, the Planner's path
        and forces), and the explorer's ellipses are left out while the Planner is shown. A refusal (a student on
        the shared mechanism: the plan cannot be shown on it) is raised after the drawing changed."""
        opened, self.open_tabs = names - self.open_tabs, names
        frame = self.view.session.frame
        if frame is not None:
            self.explorer.render(frame)
        if "player" in opened and self.built("teach"):
            self._player.opened()
        if "control" in opened and self.built("lab"):
            self._control.opened()
        if "planner" in opened and self.built("lab"):
            self._planner.opened()

    def render(self, frame: Snapshot) -> None:
        """Draw the teaching layer's part of ``frame`` (under the hub's lock)."""
        if self.built("teach"):
            self._player.render(frame)
        self.explorer.render(frame)
        self.demos.render(frame)
        self.exercises.render(frame)
        if self.built("lab"):
            self._control.render(frame)
            self._planner.render(frame)
            self._design.render(frame)

    def set_presentation(self, on: bool) -> None:
        """Presentation mode on or off for every chart of the tab (player, control, planner)."""
        for group in LATER:
            if self.built(group):
                self._present(group, on)

    def _present(self, group: str, on: bool) -> None:
        if group == "teach":
            self._player.charts.set_presentation(on)
        if group == "lab":
            for chart in (*self._control.charts, *self._planner.charts):
                chart.set_presentation(on)

    def words_changed(self) -> None:
        """The tab's language changed: the texts the tabs wrote themselves, again in it (under the hub's lock)."""
        if self.built("teach"):
            self._player.refresh()
        self.demos.retell()
        self.exercises.retell()
        if self.services.exercises is not None:
            self.services.exercises.retell(self.view)
        if self.built("lab"):
            self._control.retell()
            self._planner.retell()
            self._design.retell()
        self.explorer.retell()

    def close(self) -> None:
        """The tab went away."""
        self._player.close()
        self.explorer.close()
        self._control.player.stop()
        self._planner.player.stop()
        self.services.worker.leave(self.view)  # its pending maps, simulations and plans are dropped
        self._abandon(self.view.session)
