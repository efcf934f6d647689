"""The teaching layer of one tab, in one object: the trajectory player, the singularity explorer, the guided
demonstrations, the control lab and the motion planner, and the per-hub services they share (background workers,
map cache, trajectory runs).

:class:`~.client.ClientView` needs four calls: :meth:`Teaching.build_tabs` while its panel builds the tab group,
:meth:`Teaching.attach` once it has joined a session, :meth:`Teaching.render` for every frame (under the hub's
lock) and :meth:`Teaching.close`; :meth:`Teaching.switched` when the tab moves to another session.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import viser

from tpm_viz.app.lessons import DEMOS, PROBLEMS, Demo
from tpm_viz.classroom.session import Hub, Session, View
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.worker import Worker
from tpm_viz.ui.teaching.control import ControlView
from tpm_viz.ui.teaching.design import DesignView
from tpm_viz.ui.teaching.explorer import ExplorerView, MapService
from tpm_viz.ui.teaching.lessons import DemosView
from tpm_viz.ui.teaching.planner import PlannerView
from tpm_viz.ui.teaching.player import PlayerView
from tpm_viz.ui.teaching.playing import RunHub
from tpm_viz.ui.teaching.takeout import TakeOut, takeout_for

__all__ = ["Services", "Teaching"]


@dataclass
class Services:
    """What the tabs of one hub share."""

    worker: Worker
    """The fair queue of every tab's heavy jobs (runs, maps, control simulations, plans): tabs take turns."""
    maps: MapService
    runs: RunHub
    plans: Worker
    """The planner's worker: the same fair queue (a re-plan takes its tab's turn like any other job)."""
    lessons: tuple[Demo, ...] = DEMOS
    """The lessons of the *Demos* tab: the packaged ones, or a lecturer's (``tpm-viz serve --lessons DIR``)."""
    problems: tuple[str, ...] = PROBLEMS
    """One line per lesson file that was refused (``file:line: what is wrong``), shown in the tab."""

    @classmethod
    def create(cls, hub: Hub, lessons: Sequence[Demo] = DEMOS, problems: Sequence[str] = PROBLEMS) -> Services:
        """The services of ``hub``: one fair worker pool for slow computations (maps, runs, control simulations,
        the planner's live re-plans), the floor maps, the runs and the lessons."""
        worker = Worker()
        return cls(worker, MapService(worker), RunHub(hub, worker), worker, tuple(lessons), tuple(problems))


class Teaching:
    """Player, explorer and demonstrations of one tab (``view`` is its :class:`~.client.ClientView`)."""

    def __init__(self, view: View, services: Services) -> None:
        self.view = view
        self.services = services
        self.player = PlayerView(view, self.services.runs)
        self.explorer = ExplorerView(view, self.services.maps)
        self.demos = DemosView(
            view, services.runs, self.explorer, self.player.speed_value, services.lessons, services.problems
        )
        self.control = ControlView(view, self.services.worker, self.services.runs)
        self.planner = PlannerView(view, self.services.plans)
        self.design = DesignView(view, self.services.worker)  # the Design studio (ui/teaching/design.py)
        self.takeouts: list[TakeOut] = []  # Record clip and Download report of the player, control and planner

    def build_tabs(self, group: str, tabs: viser.GuiTabGroupHandle) -> None:
        """Add this layer's tabs of ``group`` (a key of :data:`~tpm_viz.ui.panels.GROUPS`) to its tab group:
        *Explorer* (the maps) in *explore*; *Demos* and *Player* in *teach* (before the panel's *Equations*);
        *Control* and *Planner* in *lab*."""
        gui = self.view.client.gui
        if group == "explore":
            with tabs.add_tab("Explorer", icon=viser.Icon.MAP):
                self.explorer.build(gui)
        if group == "teach":
            with tabs.add_tab("Demos", icon=viser.Icon.SCHOOL):
                self.demos.build(gui)
            with tabs.add_tab("Player", icon=viser.Icon.PLAYER_PLAY):
                self.player.build(gui)
                self.takeouts.append(takeout_for(self.view, self.services.worker, self.player, "player", gui))
        if group == "lab":
            with tabs.add_tab("Control", icon=viser.Icon.ADJUSTMENTS):
                self.control.build(gui)
                self.takeouts.append(takeout_for(self.view, self.services.worker, self.control, "control", gui))
            with tabs.add_tab("Planner", icon=viser.Icon.ROUTE):
                self.planner.build(gui)
                self.takeouts.append(takeout_for(self.view, self.services.worker, self.planner, "planner", gui))
            with tabs.add_tab("Design", icon=viser.Icon.RULER_MEASURE):
                self.design.build(gui)

    def attach(self) -> None:
        """The tab has joined its session: draw the session's run (the first render came before that)."""
        with self.view.hub.lock:
            self.player.refresh()
        self.control.attach()
        self.planner.attach()

    def switched(self, old: Session) -> None:
        """The tab moved from ``old`` to its current session (own copy on / off)."""
        with self.view.hub.lock:
            self.services.runs.adopt(self.view.session, old)
            self.player.refresh()

    def render(self, frame: Snapshot) -> None:
        """Draw the teaching layer's part of ``frame`` (under the hub's lock)."""
        self.player.render(frame)
        self.explorer.render(frame)
        self.demos.render(frame)
        self.control.render(frame)
        self.planner.render(frame)
        self.design.render(frame)

    def set_presentation(self, on: bool) -> None:
        """Presentation mode on or off for every chart of the tab (player, control, planner)."""
        self.player.charts.set_presentation(on)
        for chart in (*self.control.charts, *self.planner.charts):
            chart.set_presentation(on)

    def words_changed(self) -> None:
        """The tab's language changed: the texts the tabs wrote themselves, again in it (under the hub's lock)."""
        self.player.refresh()
        self.demos.retell()
        self.control.retell()
        self.planner.retell()
        self.explorer.retell()
        self.design.retell()

    def close(self) -> None:
        """The tab went away."""
        self.player.close()
        self.explorer.close()
        self.control.player.stop()
        self.planner.player.stop()
        self.services.worker.leave(self.view)  # its pending maps, simulations and plans are dropped
