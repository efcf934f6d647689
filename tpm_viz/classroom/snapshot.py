"""One committed state as every view draws it, with the drawing data computed once for all views.

A shared mechanism may be on many tabs: the readout (all the numbers), the joint positions, the link transforms
and the dashboard HTML are the same for all of them, so they are computed at most once per commit.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import cached_property

import numpy as np

from tpm_viz.app.equations import errata_html, procedure_html
from tpm_viz.app.readouts import Readout
from tpm_viz.app.state import AppState
from tpm_viz.classroom.text import dashboard_html
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html, html
from tpm_viz.core.words import Lang, say
from tpm_viz.drawing import meshes
from tpm_viz.paper.dynamics import inverse_dynamics_detail
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.kinematics import MechanismPose, mechanism_pose

__all__ = ["Snapshot"]


class Snapshot:
    """``state`` and its ``readout``; derived drawing data are cached properties."""

    def __init__(self, state: AppState, readout: Readout, in_drag: bool = False) -> None:
        self.state = state
        self.readout = readout
        self.in_drag = in_drag
        """True for the intermediate frames of a gizmo drag (views may skip costly, non-essential parts)."""
        self.numbers_every: float | None = None
        """Mid-drag, the shortest time [s] between two refreshes of a panel's numbers, or None: the panel's own
        (a busy server draws the mechanism at every commit and the numbers less often,
        :mod:`tpm_viz.classroom.pacing`)."""
        self.complete_readout: Callable[[], Readout] | None = None
        """For a live frame whose ``readout`` lacks the reference forces: computes the readout with them."""
        self._dashboards: dict[Lang, Html] = {}
        self._equations: dict[Lang, Html] = {}
        self.made_at = time.monotonic()
        self.numbers: Snapshot = self
        """The frame whose numbers the dashboard shows: this one, or mid-drag a recent one (:meth:`follow`)."""

    def follow(self, previous: Snapshot | None, within: float) -> None:
        """Mid-drag, let the dashboard show the numbers of ``previous``'s numbers frame if that frame is less than
        ``within`` [s] older than this one. A dashboard is refreshed a few times a second mid-drag, and each tab's
        at its own commit (watching tabs in turn, :func:`~tpm_viz.classroom.pacing.watch_slot`): without this, nearly
        every
        commit of a watched drag would compute the reference (Pinocchio) forces for some tab's dashboard."""
        if self.in_drag and previous is not None and previous.in_drag:
            if self.made_at - previous.numbers.made_at < within:
                self.numbers = previous.numbers

    @cached_property
    def displayed_readout(self) -> Readout:
        """The readout the dashboard shows: always with the reference (Pinocchio) forces beside the closed form."""
        return self.readout if self.complete_readout is None else self.complete_readout()

    @cached_property
    def mechanism(self) -> MechanismPose:
        """Every joint of the pose [m] (``A_i``, ``B_i``, the four links)."""
        return mechanism_pose(self.state.params, self.readout.p, self.readout.d)

    @cached_property
    def links(self) -> tuple[np.ndarray, np.ndarray]:
        """World positions (4, 3) and orientations (4, 4) of the links, as float32 for the batched mesh."""
        positions, wxyzs = meshes.link_instances(self.mechanism)
        return positions.astype(np.float32), wxyzs.astype(np.float32)

    @property
    def equations(self) -> Html:
        """The paper's procedure (a)-(e) with this state's numbers (MathML), and the errata, in English."""
        return self.equations_in(Lang.EN)

    def equations_in(self, lang: Lang) -> Html:
        """The paper's procedure (a)-(e) with this state's numbers (MathML), and the errata, their words in ``lang``
        (built once per language)."""
        if lang not in self._equations:
            state = self.state
            dp, ddp, f_ext = state.load.motion()
            try:
                res = inverse_dynamics_detail(state.params, state.pose.p, dp, ddp, f_ext, d=state.pose.d)
                jac = jacobians(state.params, state.pose.p, state.pose.d)
                body = procedure_html(state.params, res, jac, f_ext, lang)
            except TpmVizError as exc:
                body = html("<p>{why}</p>", why=say(lang, exc))
            self._equations[lang] = body + errata_html(lang)
        return self._equations[lang]

    @cached_property
    def dashboard(self) -> Html:
        """The HTML of the always-visible top of the panel (its messages in English)."""
        return self.dashboard_in(Lang.EN)

    def dashboard_in(self, lang: Lang) -> Html:
        """The HTML of the always-visible top of the panel, its messages in ``lang`` (built once per language, from the
        numbers frame :attr:`numbers`)."""
        numbers = self.numbers
        if lang not in numbers._dashboards:
            numbers._dashboards[lang] = dashboard_html(numbers.state, numbers.displayed_readout, lang)
        return numbers._dashboards[lang]
