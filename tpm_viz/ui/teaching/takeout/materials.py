"""The :class:`~.recording.Material` of each teaching tab's current run, read under the hub's lock.

- Player: the loaded run (:class:`tpm_viz.app.runs.Run`, its Pinocchio forces already computed) as it is.
- Control: the actual platform path and the applied forces of the last simulation; the report is of the
  reference path, with the control lab's results as a section.
- Planner: the plan sampled at :data:`~.recording.APP_FRAMES` uniform times with its forces; the report is of the
  planned path, with the plan's results as a section.
"""

from __future__ import annotations

import numpy as np

from tpm_viz.core.words import Phrase, T
from tpm_viz.media.report import Section
from tpm_viz.ui.teaching.takeout.recording import APP_FRAMES, Material, frames_of, report_of_path

__all__ = ["control_material", "planner_material", "player_material"]


def _stem(text: str) -> str:
    return "".join(c if c.isalnum() or c in "-." else "-" for c in text).strip("-")[:60] or "run"


def player_material(player) -> Material | None:
    """The Player's loaded run (None when there is none or it is being recomputed)."""
    session = player.session
    if session is None:
        return None
    run = player.runs.of(session).run
    if run is None or run.params != session.state.params:
        return None
    return Material(
        clip=run,
        title=run.source.label,
        stem=_stem(f"tpm-{run.source.kind}-T{run.duration:g}s"),
        report=lambda: (run, ()),
    )


def control_material(control) -> Material | None:
    """The Control tab's last simulation (None before the first)."""
    run, motion = control.run, control.player.motion
    if run is None or motion is None:
        return None
    params, setup = motion.params, run.setup
    title = f"{setup.controller.value} on {run.name}, ω_n = {setup.gains.wn:g} Hz, ζ = {setup.gains.zeta:g}"
    limit = setup.force_limit
    section = Section(
        T("Control lab"),
        (
            (T("controller"), setup.controller.value, ""),
            (T("reference"), str(run.name), ""),
            (T("natural frequency ω_n"), setup.gains.wn, "Hz"),
            (T("damping ratio ζ"), setup.gains.zeta, ""),
            (T("controller rate"), setup.rate, "Hz"),
            (T("payload unknown to the controller"), setup.payload, "kg"),
            (T("mass error of the model"), 100.0 * setup.mass_error[0], "%"),
            (T("force limit"), limit if limit is not None else T("none"), "N" if limit is not None else ""),
            (T("RMS tracking error"), run.rms_error * 1e3, "mm"),
            (T("largest tracking error"), run.max_error * 1e3, "mm"),
            (T("peak applied force"), run.peak_force, "N"),
            (T("time in saturation"), run.time_in_saturation * 1e3, "ms"),
        ),
    )
    t, p_ref = np.asarray(run.t), np.asarray(run.p_ref)
    label = str(Phrase("reference of the control lab: {name}", name=run.name))
    return Material(
        clip=frames_of(params, t, run.p, run.tau),
        title=title,
        stem=_stem(f"tpm-control-{setup.controller.value}-{run.name}"),
        report=lambda: (report_of_path(params, t, p_ref, label), (section,)),
    )


def planner_material(planner) -> Material | None:
    """The Planner tab's current plan (None before the first)."""
    result, motion = planner.result, planner.player.motion
    if result is None or motion is None:
        return None
    params, plan = motion.params, result.plan
    t = np.linspace(0.0, plan.duration, APP_FRAMES)
    samples = plan.sample(t)
    limits = plan.limits
    speed = limits.speed
    section = Section(
        T("Planner"),
        (
            (T("path"), str(result.kind), ""),
            (T("force limit F_max"), limits.force, "N"),
            (T("speed limit"), speed if speed is not None else T("none"), "m/s" if speed is not None else ""),
            (T("motion time of one cycle"), result.cycle_time, "s"),
            (T("cycles per minute"), result.per_minute, "1/min"),
            (T("peak planned force"), float(np.max(np.abs(samples.tau))), "N"),
        ),
    )
    title = f"plan: {result.kind}, F_max = {limits.force:g} N, {plan.duration:.3f} s"
    label = str(Phrase("planned path: {name}", name=result.kind))
    return Material(
        clip=frames_of(params, t, samples.p, samples.tau),
        title=title,
        stem=_stem(f"tpm-plan-{result.kind}-F{limits.force:g}N"),
        report=lambda: (report_of_path(params, t, samples.p, label), (section,)),
    )
