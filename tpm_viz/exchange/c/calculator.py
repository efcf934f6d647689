"""The page calculator: the closed form in a browser as ``window.tpm``, for the offline lesson page.

Two assets, both in ``assets/calculator/`` (installed as ``tpm_viz.assets``): the WebAssembly module of the generated
C (:mod:`.wasm`) and ``tpm_calculator.js``, which instantiates it from base64 and defines ``window.tpm``
(``inverseKinematics``, ``inverseDynamics``, ``evaluate``; its header and ``docs/realtime.md`` document them). The
script checks the inputs and refuses what the app refuses, in the app's words: :data:`WORDS` lists every English
template it uses (each one the app's or the library's own, plus two of its own) so that the Korean catalogue covers
them, and :func:`calculator_assets` writes the script's configuration into it: the paper's parameters, the app's move
limits and warning thresholds (:mod:`tpm_viz.paper.status`) and the Korean templates of :data:`WORDS`.
"""

from __future__ import annotations

import base64
import dataclasses
import json
from importlib import resources
from typing import NamedTuple

from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase, T, catalogue
from tpm_viz.exchange.c.wasm import shipped
from tpm_viz.paper.status import MOVE_LIMITS, WARN

__all__ = ["SCRIPT", "WORDS", "CalculatorAssets", "calculator_assets"]

SCRIPT = "tpm_calculator.js"
"""The script's file name in ``assets/calculator/``."""
_CONFIG_SLOT = "/*@tpm-config@*/ null"

WORDS: tuple[Phrase, ...] = (
    # the pose, as the app places a trajectory sample (tpm_viz.app.moves.place, why_not)
    T("refused: {why}"),
    T(
        "out of reach: a leg of length l_a = {l_a} mm cannot reach the platform there (|p1| and |p2| must stay "
        "below l_a)"
    ),
    T(
        "actuator {i} would leave its stroke: slider {i} would have to be at d{i} = {d} mm, beyond its end-stops at 0 "
        "and {stroke} mm"
    ),
    T(
        "leg {i} would come too close to an inverse singularity: its links would stand almost perpendicular to rail "
        "{i}, where actuator {i} loses its authority along them ({value}eq. 11)"
    ),
    T(
        "the platform would come too close to the direct singularity, where it gains a degree of freedom: it loses "
        "its stiffness in one direction and the actuator forces grow without bound for a load along it; {kind} "
        "({value}eq. 12)"
    ),
    T("the leg circles coincide"),
    T("the two assembly modes merge"),
    # typed pairs (tpm_viz.app.readouts.Load) and the forces (tpm_viz.paper.kinematics.finite_result)
    T("{name} must be two numbers, got {got}"),
    T("{name} must be finite, got ({x:g}, {y:g})"),
    T("{what} overflowed: the inputs are too large for finite results"),
    T("the actuator forces"),
    # parameters (tpm_viz.core.params, as tpm_viz.app.lesson_files words a refused set)
    T("parameters refused: {why}"),
    T("unknown parameter {name}; known: {known}"),
    T("parameter {name} must be a number, got {got}"),
    T("parameter {name} must be a finite number of {unit}, got {got}"),
    T("parameter {name} must be positive, got {value} mm: it is a length, more than 0 mm"),
    T("parameter {name} must be positive, got {value} kg: it is a mass, more than 0 kg"),
    T(
        "parameter {name} must be between {low} and {high} {unit}, got {value} {unit}: beyond that range the "
        "computations lose their precision"
    ),
    T(
        "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go beyond d = Δd "
        "(the rule is a − b − √2 l_a < Δd)"
    ),
    T(
        "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go behind d = 0 "
        "(the rule is a − b + l_a > 0)"
    ),
    T("{fix} ({alternative})"),
    T("change a, b, l_a, the stroke Δd or the pivot spacing"),
    T("l_a must be at least {bound} mm with a = {a} mm, b = {b} mm and the stroke Δd = {stroke} mm"),
    T("the stroke Δd must be at least {bound} mm with a = {a} mm, b = {b} mm and l_a = {l_a} mm"),
    T("a must be at most {bound} mm with b = {b} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm"),
    T("b must be at least {bound} mm with a = {a} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm"),
    T("l_a must be at least {bound} mm with a = {a} mm and b = {b} mm"),
    T("a must be at least {bound} mm with b = {b} mm and l_a = {l_a} mm"),
    T("b must be at most {bound} mm with a = {a} mm and l_a = {l_a} mm"),
    T("or l_a at least {bound} mm"),
    T("or the stroke Δd at least {bound} mm"),
    T("or a at least {bound} mm"),
    T("or a at most {bound} mm"),
    T("or b at least {bound} mm"),
    T("or b at most {bound} mm"),
    T(
        "the pivot spacing must be less than the link length l_a = {l_a} mm, got {spacing} mm (or l_a more than "
        "{spacing} mm): the two links of a parallelogram are drawn that far apart"
    ),
    # the script's own
    T("the parameters must be an object of named numbers (SI units), got {got}"),
    T("the calculator refused this state (code {code})"),
)
"""Every template ``tpm_calculator.js`` renders (``P("...")`` in the script; a test checks the two agree)."""


class CalculatorAssets(NamedTuple):
    """What a page inlines: the script (its configuration written in) and the module as base64."""

    js: str
    wasm_b64: str

    def html(self) -> str:
        """Both as HTML: the module in ``<script id="tpm-wasm" type="application/wasm;base64">`` (data, not run),
        then the script, which finds it there; ``window.tpm`` is ready when ``window.tpmReady`` resolves."""
        return (
            f'<script id="tpm-wasm" type="application/wasm;base64">{self.wasm_b64}</script>\n'
            f"<script>\n{self.js}</script>\n"
        )


def _config() -> dict[str, object]:
    ko = catalogue(Lang.KO)
    return {
        "defaults": dataclasses.asdict(Params.paper()),
        "limits": {
            "min_cos": MOVE_LIMITS.inverse,
            "min_det": MOVE_LIMITS.direct,
            "warn_cos": WARN.inverse,
            "warn_det": WARN.direct,
        },
        "ko": {p.template: ko[p.template] for p in WORDS if p.template in ko},
    }


def calculator_assets() -> CalculatorAssets:
    """The script (``assets/calculator/tpm_calculator.js`` with :func:`_config` written in, every ``<`` of the
    configuration as ``\\u003c`` so that no text can close the page's ``<script>``) and ``tpm_2ppa.wasm`` as base64."""
    source = (resources.files("tpm_viz.assets") / "calculator" / SCRIPT).read_text(encoding="utf-8")
    config = json.dumps(_config(), ensure_ascii=False, sort_keys=True).replace("<", "\\u003c")
    assert source.count(_CONFIG_SLOT) == 1, f"{SCRIPT}: one configuration slot {_CONFIG_SLOT!r}"
    js = source.replace(_CONFIG_SLOT, config)
    return CalculatorAssets(js, base64.b64encode(shipped()).decode("ascii"))
