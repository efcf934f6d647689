"""The *Control* tab's runs without widgets: the setup from the widgets' values, the reference from the dropdown,
the simulations run in the background worker (one controller or all three on the same setup, timed), and a run as
a playable motion (the platform drawn at ``p_ref + k (p - p_ref)``, the error magnified ``k`` times)."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from tpm_viz.app.runs import Source
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.multibody.control import ControlRun, ControlSetup, simulate
from tpm_viz.paper.control import ControllerKind, Gains
from tpm_viz.paper.trajectories import trajectory_from_samples

__all__ = ["PAPER", "ControlMotion", "all_three", "lab_reference", "lab_setup", "timed", "upload_label"]

PAPER = {"line (Fig. 4)": "line", "circle (Fig. 5)": "circle"}


def lab_setup(kind: ControllerKind, wn, zeta, payload, mass_error_pct, force_limit, rate, noise_um) -> ControlSetup:
    """The :class:`ControlSetup` of the widgets' values (force limit 0: none; mass error % on all three masses)."""
    err = float(mass_error_pct) / 100.0
    limit = float(force_limit)
    return ControlSetup(
        controller=kind,
        gains=Gains(float(wn), float(zeta)),
        rate=float(rate),
        payload=float(payload),
        mass_error=(err, err, err),
        force_limit=None if limit <= 0 else limit,
        noise=float(noise_um) * 1e-6,
    )


def lab_reference(label: str, uploaded: Source | None):
    """``"line"``, ``"circle"`` or the Player's uploaded CSV as a :class:`Trajectory`, from a dropdown label."""
    if label in PAPER:
        return PAPER[label]
    if uploaded is not None and uploaded.knots is not None and label == upload_label(uploaded):
        t, p = uploaded.knots
        return trajectory_from_samples(t, p, name=uploaded.label.split(", T =")[0])
    raise InputError(Phrase("unknown reference {label}: upload a CSV in the Player first", label=repr(label)))


def upload_label(source: Source) -> str:
    return "your CSV: " + source.label.split(", T =")[0]


class ControlMotion:
    """A control run as a playable motion: the actual platform at ``p_ref + magnify (p - p_ref)``."""

    def __init__(self, params: Params, run: ControlRun, magnify: float = 1.0) -> None:
        self.params = params
        self.run = run
        self.duration = float(run.t[-1])
        self.magnify = magnify
        t = run.t if len(run.t) > 1 else np.array([0.0, 1.0])
        self._ddp_ref = np.gradient(run.dp_ref, t, axis=0) if len(run.t) > 1 else np.zeros_like(run.dp)
        self._ddp = np.gradient(run.dp, t, axis=0) if len(run.t) > 1 else np.zeros_like(run.dp)

    def _interp(self, arr: np.ndarray, t: float) -> np.ndarray:
        return np.array([np.interp(t, self.run.t, arr[:, 0]), np.interp(t, self.run.t, arr[:, 1])])

    def reference_at(self, t: float) -> np.ndarray:
        """``p_ref(t)`` [m]."""
        return self._interp(self.run.p_ref, t)

    def shown_path(self) -> np.ndarray:
        """The platform path as drawn ``(n, 2)`` [m]."""
        r = self.run
        return r.p_ref + self.magnify * (r.p - r.p_ref)

    def state_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r, k = self.run, self.magnify
        p_ref, p = self._interp(r.p_ref, t), self._interp(r.p, t)
        dp_ref, dp = self._interp(r.dp_ref, t), self._interp(r.dp, t)
        a_ref, a = self._interp(self._ddp_ref, t), self._interp(self._ddp, t)
        return p_ref + k * (p - p_ref), dp_ref + k * (dp - dp_ref), a_ref + k * (a - a_ref)


def timed(params: Params, reference, setup: ControlSetup) -> tuple[ControlRun, float]:
    t0 = time.perf_counter()
    run = simulate(params, reference, setup)
    return run, time.perf_counter() - t0


def all_three(params: Params, reference, setup: ControlSetup) -> dict[ControllerKind, tuple[ControlRun, float]]:
    return {k: timed(params, reference, dataclasses.replace(setup, controller=k)) for k in ControllerKind}
