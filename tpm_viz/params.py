"""The parameter set of the 2-PPa TPM: geometry and masses, in SI units.

Defaults are the paper's prototype (Tables 1 and 2). Symbols follow the paper and
``docs/conventions.md``: the slider joint of leg ``i`` is ``A_i = (d_i - a) e_i``, the
platform-side joint is ``B_i = P - b e_i`` and ``|B_i - A_i| = l_a`` (eq. 2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from tpm_viz.errors import InvalidParametersError

__all__ = ["PARAM_INFO", "Params"]

_RANGES = {"m": (1e-6, 100.0), "kg": (1e-9, 1e4)}
"""Supported magnitudes per unit: keeps every derived quantity (l_a², c_i³, ...) finite in float64."""


def _f(doc: str, unit: str, ui_unit: str, ui_scale: float, default: float):
    return field(default=default, metadata={"doc": doc, "unit": unit, "ui_unit": ui_unit, "ui_scale": ui_scale})


@dataclass(frozen=True)
class Params:
    """Validated, immutable parameters of the 2-PPa TPM (SI units).

    Build the paper's prototype with :meth:`Params.paper` and change fields with
    :meth:`replace`; every construction is validated and raises
    :class:`~tpm_viz.errors.InvalidParametersError` naming the field and the rule.
    """

    a: float = _f("total size a (Table 1): rail i starts at -a e_i", "m", "mm", 1e3, 0.482)
    """Total size ``a`` [m]: slider joint ``A_i = (d_i - a) e_i``."""
    b: float = _f("platform offset b (Table 1): B_i = P - b e_i", "m", "mm", 1e3, 0.092)
    """Platform offset ``b`` [m]: platform joint ``B_i = P - b e_i``."""
    l_a: float = _f("link length l_a (Table 1)", "m", "mm", 1e3, 0.260)
    """Parallelogram link length ``l_a`` [m]."""
    m_a: float = _f("slider mass m_a (Table 2)", "kg", "kg", 1.0, 0.95)
    """Mass of one slider with its coupler ``m_a`` [kg]."""
    m_b: float = _f("mass of both links of one parallelogram m_b (Table 2)", "kg", "kg", 1.0, 0.84)
    """Mass of the two links of one parallelogram together ``m_b`` [kg] (2 x 0.42 kg)."""
    m_p: float = _f("platform mass m_p (Table 2)", "kg", "kg", 1.0, 2.21)
    """Mass of the moving platform ``m_p`` [kg]."""
    stroke: float = _f("actuator stroke Δd (Table 1): 0 <= d_i <= Δd", "m", "mm", 1e3, 0.300)
    """Actuator stroke ``Δd`` [m]: ``0 <= d_i <= Δd``."""
    pivot_spacing: float = _f("pivot spacing of the two parallelogram links", "m", "mm", 1e3, 0.060)
    """Distance between the two parallel links of one parallelogram [m] (drawing only)."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InvalidParametersError(f"parameter {f.name} must be a number, got {value!r}")
            value = float(value)
            object.__setattr__(self, f.name, value)
            if not math.isfinite(value):
                raise InvalidParametersError(f"parameter {f.name} must be finite, got {value}")
            if value <= 0.0:
                raise InvalidParametersError(f"parameter {f.name} must be positive, got {value:g} {f.metadata['unit']}")
            low, high = _RANGES[f.metadata["unit"]]
            if not low <= value <= high:
                raise InvalidParametersError(
                    f"parameter {f.name} = {value:g} {f.metadata['unit']} is outside the supported range "
                    f"{low:g} to {high:g} {f.metadata['unit']}"
                )
        k = self.offset
        # Eq. (4): d_i = p_i + (a - b) - sqrt(l_a^2 - p_j^2). Over the reachable set
        # |p_1|, |p_2| < l_a the pairs (d_1, d_2) that both lie in [0, stroke] exist iff
        # a - b - sqrt(2) l_a < stroke and a - b + l_a > 0 (extremes on the diagonal p_1 = p_2).
        if k + self.l_a <= 0.0:
            raise InvalidParametersError(
                f"no reachable pose: a - b + l_a = {k + self.l_a:g} m must be positive "
                "(the sliders would need d_i < 0 everywhere)"
            )
        if k - math.sqrt(2.0) * self.l_a >= self.stroke:
            raise InvalidParametersError(
                f"no reachable pose: a - b - sqrt(2) l_a = {k - math.sqrt(2.0) * self.l_a:g} m "
                f"must be below the stroke {self.stroke:g} m (the sliders would need d_i > stroke)"
            )
        if self.pivot_spacing >= self.l_a:
            raise InvalidParametersError(
                f"parameter pivot_spacing ({self.pivot_spacing:g} m) must be smaller than l_a ({self.l_a:g} m)"
            )

    @classmethod
    def paper(cls, **overrides: float) -> Params:
        """The paper's prototype (Tables 1-2), with optional keyword overrides in SI units."""
        return cls(**overrides)

    def replace(self, **changes: float) -> Params:
        """A validated copy with some fields changed (SI units)."""
        unknown = set(changes) - set(PARAM_INFO)
        if unknown:
            raise InvalidParametersError(f"unknown parameter {sorted(unknown)[0]!r}; known: {', '.join(PARAM_INFO)}")
        return dataclasses.replace(self, **changes)

    def with_overrides(self, overrides: Mapping[str, str | float]) -> Params:
        """A copy with ``NAME=VALUE`` style overrides (values may be strings, SI units)."""
        changes: dict[str, float] = {}
        for name, raw in overrides.items():
            if name not in PARAM_INFO:
                raise InvalidParametersError(f"unknown parameter {name!r}; known: {', '.join(PARAM_INFO)}")
            try:
                changes[name] = float(raw)
            except (TypeError, ValueError):
                raise InvalidParametersError(f"parameter {name} must be a number, got {raw!r}") from None
        return self.replace(**changes)

    @property
    def offset(self) -> float:
        """``a - b`` [m]: with it, ``c_i = p_i - d_i + (a - b) = l_a cos θ_i`` (eq. 23) and the working-mode
        inverse kinematics is ``d_i = p_i + (a - b) - sqrt(l_a² - p_j²)`` (eq. 4)."""
        return self.a - self.b

    @property
    def moving_mass(self) -> float:
        """Total moving mass ``2 m_a + 2 m_b + m_p`` [kg] (both sliders, both parallelograms, the platform)."""
        return 2.0 * self.m_a + 2.0 * self.m_b + self.m_p


PARAM_INFO: dict[str, dict] = {f.name: dict(f.metadata) for f in dataclasses.fields(Params)}
"""Per-field documentation: ``doc``, SI ``unit``, ``ui_unit`` and ``ui_scale`` (SI -> UI)."""
