"""The typed sliders of the *Control* and *Planner* tabs (:class:`~tpm_viz.ui.widgets.typed_sliders.TypedSlider`):
label, the typed field's quantity (its name in messages, UI unit, accepted range = the slider's), step and first value.

Units as the tabs read them (:func:`.control.run.lab_setup`: ω_n in Hz, payload in kg, mass error in %, force
limit in N with 0 for none, rate in Hz, noise in µm; the planner: F_max in N, speed limit in m/s with 0 for none).
"""

from __future__ import annotations

from tpm_viz.ui.widgets.typed import Quantity
from tpm_viz.ui.widgets.typed_sliders import Setting

__all__ = ["CONTROL_SETTINGS", "PLANNER_SETTINGS"]

CONTROL_SETTINGS = {
    "wn": Setting("ω_n (Hz)", Quantity("ω_n", "Hz", lo=1.0, hi=60.0), 0.5, 20.0),
    "zeta": Setting("ζ", Quantity("ζ", lo=0.1, hi=2.0), 0.05, 1.0),
    "payload": Setting(
        "Payload (kg)",
        Quantity("payload", "kg", lo=0.0, hi=5.0),
        0.1,
        0.0,
        "On the platform, unknown to the controller",
    ),
    "mass_error": Setting(
        "Mass error (%)", Quantity("mass error", "%", lo=-50.0, hi=50.0), 1.0, 0.0, "Of m_a, m_b, m_p in the model"
    ),
    "force_limit": Setting("Force limit (N, 0 = none)", Quantity("force limit", "N", lo=0.0, hi=1000.0), 10.0, 0.0),
    "rate": Setting("Controller rate (Hz)", Quantity("controller rate", "Hz", lo=100.0, hi=5000.0), 100.0, 1000.0),
    "noise": Setting("Position noise (µm)", Quantity("position noise", "µm", lo=0.0, hi=50.0), 1.0, 0.0),
}
"""The control lab's settings, by the name of the :class:`~.control.tab.ControlView` attribute holding the slider."""

PLANNER_SETTINGS = {
    "force": Setting("F_max, force limit (N)", Quantity("F_max", "N", lo=20.0, hi=1000.0), 5.0, 200.0),
    "speed": Setting("Speed limit (m/s, 0 = none)", Quantity("speed limit", "m/s", lo=0.0, hi=5.0), 0.05, 0.0),
}
"""The planner's limits, by the name of the :class:`~.planner.tab.PlannerView` attribute holding the slider."""
