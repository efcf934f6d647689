"""The parameter set of the 2-PPa TPM: geometry and masses, in SI units.

Defaults are the paper's prototype (Tables 1 and 2). Symbols follow the paper and
``docs/conventions.md``: the slider joint of leg ``i`` is ``A_i = (d_i - a) e_i``, the
platform-side joint is ``B_i = P - b e_i`` and ``|B_i - A_i| = l_a`` (eq. 2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Protocol

from tpm_viz.core.errors import InvalidParametersError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.words import Phrase

__all__ = ["PARAM_INFO", "Params", "geometry_problem"]

_RANGES = {"m": (1e-6, 100.0), "kg": (1e-9, 1e4)}
"""Supported magnitudes per unit: keeps every derived quantity (l_a², c_i³, ...) finite in float64."""


def _f(doc: str, unit: str, ui_unit: str, ui_scale: float, default: float) -> float:
    return field(default=default, metadata={"doc": doc, "unit": unit, "ui_unit": ui_unit, "ui_scale": ui_scale})


@dataclass(frozen=True)
class Params:
    """Validated, immutable parameters of the 2-PPa TPM (SI units).

    Build the paper's prototype with :meth:`Params.paper` and change fields with
    :meth:`replace`; every construction is validated and raises
    :class:`~tpm_viz.core.errors.InvalidParametersError` naming the field and the rule.
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
                raise InvalidParametersError(
                    Phrase("parameter {name} must be a number, got {got}", name=f.name, got=repr(value))
                )
            value = float(value)
            object.__setattr__(self, f.name, value)
            unit = f.metadata["ui_unit"]
            if not math.isfinite(value):
                raise InvalidParametersError(
                    Phrase(
                        "parameter {name} must be a finite number of {unit}, got {got}",
                        name=f.name,
                        unit=unit,
                        got=value,
                    )
                )
            if value <= 0.0:
                what = (
                    Phrase(
                        "parameter {name} must be positive, got {value} mm: it is a length, more than 0 mm",
                        name=f.name,
                        value=_ui(f.name, value),
                    )
                    if unit == "mm"
                    else Phrase(
                        "parameter {name} must be positive, got {value} kg: it is a mass, more than 0 kg",
                        name=f.name,
                        value=_ui(f.name, value),
                    )
                )
                raise InvalidParametersError(what)
            low, high = _RANGES[f.metadata["unit"]]
            if not low <= value <= high:
                raise InvalidParametersError(
                    Phrase(
                        "parameter {name} must be between {low} and {high} {unit}, got {value} {unit}: beyond that "
                        "range the computations lose their precision",
                        name=f.name,
                        low=_ui(f.name, low),
                        high=_ui(f.name, high),
                        value=_ui(f.name, value),
                        unit=unit,
                    )
                )
        problem = geometry_problem(self.a, self.b, self.l_a, self.stroke, self.pivot_spacing)
        if problem is not None:
            raise _geometry_error(problem)
        if self.pivot_spacing >= self.l_a:
            raise InvalidParametersError(
                Phrase(
                    "the pivot spacing must be less than the link length l_a = {l_a} mm, got {spacing} mm (or l_a more "
                    "than {spacing} mm): the two links of a parallelogram are drawn that far apart",
                    l_a=_ui("l_a", self.l_a),
                    spacing=_ui("pivot_spacing", self.pivot_spacing),
                )
            )

    @classmethod
    def paper(cls, **overrides: float) -> Params:
        """The paper's prototype (Tables 1-2), with optional keyword overrides in SI units."""
        return cls(**overrides)

    def replace(self, **changes: float) -> Params:
        """A validated copy with some fields changed (SI units). A geometry that leaves no pose inside the stroke
        is refused with the fix of a field that was changed first (:func:`geometry_problem`)."""
        unknown = set(changes) - set(PARAM_INFO)
        if unknown:
            raise InvalidParametersError(
                Phrase(
                    "unknown parameter {name}; known: {known}",
                    name=repr(sorted(unknown)[0]),
                    known=", ".join(PARAM_INFO),
                )
            )
        try:
            return dataclasses.replace(self, **changes)
        except InvalidParametersError as exc:
            if not getattr(exc, "geometry", False):
                raise
            new = {name: changes.get(name, getattr(self, name)) for name in ("a", "b", "l_a", "stroke")}
            changed = [name for name, value in new.items() if value != getattr(self, name)]
            spacing = changes.get("pivot_spacing", self.pivot_spacing)
            problem = geometry_problem(**new, pivot_spacing=spacing, prefer=changed)
            raise _geometry_error(problem if problem is not None else exc.args[0]) from None

    def with_overrides(self, overrides: Mapping[str, str | float]) -> Params:
        """A copy with ``NAME=VALUE`` style overrides (values may be strings, SI units)."""
        changes: dict[str, float] = {}
        for name, raw in overrides.items():
            if name not in PARAM_INFO:
                raise InvalidParametersError(
                    Phrase("unknown parameter {name}; known: {known}", name=repr(name), known=", ".join(PARAM_INFO))
                )
            try:
                changes[name] = float(raw)
            except (TypeError, ValueError):
                raise InvalidParametersError(
                    Phrase("parameter {name} must be a number, got {got}", name=name, got=repr(raw))
                ) from None
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


def _ui(name: str, value: float) -> str:
    """``value`` [SI] of field ``name`` in its UI unit (mm or kg), as a message shows it (without the unit)."""
    return fixed(value * PARAM_INFO[name]["ui_scale"], ".6g")


def _geometry_error(problem: Phrase) -> InvalidParametersError:
    exc = InvalidParametersError(problem)
    exc.geometry = True  # type: ignore[attr-defined]  # Params.replace rewords it for the field that changed
    return exc


def _beyond_reach(a: float, b: float, l_a: float, stroke: float) -> bool:
    """Eq. (4) over the reachable set ``|p_1|, |p_2| < l_a``: the sliders would need ``d_i > Δd`` everywhere."""
    return (a - b) - math.sqrt(2.0) * l_a >= stroke


def _behind_start(a: float, b: float, l_a: float, stroke: float) -> bool:
    """The sliders would need ``d_i < 0`` everywhere."""
    return (a - b) + l_a <= 0.0


class _Rule(Protocol):
    """A geometric rule of :func:`geometry_problem`: whether lengths ``a, b, l_a, stroke`` [m] break it."""

    def __call__(self, a: float, b: float, l_a: float, stroke: float) -> bool: ...


# (rule, field) -> whether the fix is a lower bound, and the exact bound [m] from (a, b, l_a, stroke)
_FIXES = {
    (_beyond_reach, "l_a"): (True, lambda a, b, la, s: (a - b - s) / math.sqrt(2.0)),
    (_beyond_reach, "stroke"): (True, lambda a, b, la, s: a - b - math.sqrt(2.0) * la),
    (_beyond_reach, "a"): (False, lambda a, b, la, s: b + s + math.sqrt(2.0) * la),
    (_beyond_reach, "b"): (True, lambda a, b, la, s: a - s - math.sqrt(2.0) * la),
    (_behind_start, "l_a"): (True, lambda a, b, la, s: b - a),
    (_behind_start, "a"): (True, lambda a, b, la, s: b - la),
    (_behind_start, "b"): (False, lambda a, b, la, s: a + la),
}


def _fits(values: dict[str, float], spacing: float) -> bool:
    """Whether lengths ``values`` [m] (a, b, l_a, stroke) pass every geometric rule (the pivot spacing's too)."""
    return not (_beyond_reach(**values) or _behind_start(**values)) and spacing < values["l_a"]


def _shown_bound(rule: _Rule, name: str, values: dict[str, float], spacing: float) -> str | None:
    """The fix's bound in mm, rounded to 0.1 mm on the accepted side: with that value (as typed, in mm) every
    geometric rule holds, and with the one 0.1 mm further back ``rule`` fails (the exact bound lies between them).
    None if changing ``name`` alone cannot make the set valid."""
    lower, bound = _FIXES[(rule, name)]
    edge = bound(*values.values())
    if name == "l_a":
        edge = max(edge, spacing)
    k = math.floor(edge * 1e4) if lower else math.ceil(edge * 1e4)  # in 0.1 mm
    for _ in range(100):
        if k > 0 and _fits({**values, name: (k / 10) * 1e-3}, spacing):
            return fixed(k / 10, ".1f")
        k += 1 if lower else -1
    return None


def _fix(rule: _Rule, name: str, bound: str, values: dict[str, float]) -> Phrase:
    """The fix of one field, as a whole clause with the other values."""
    mm = {k: _ui(k, v) for k, v in values.items()}
    a, b, l_a, stroke = mm["a"], mm["b"], mm["l_a"], mm["stroke"]
    if rule is _beyond_reach:
        if name == "l_a":
            return Phrase(
                "l_a must be at least {bound} mm with a = {a} mm, b = {b} mm and the stroke Δd = {stroke} mm",
                bound=bound,
                a=a,
                b=b,
                stroke=stroke,
            )
        if name == "stroke":
            return Phrase(
                "the stroke Δd must be at least {bound} mm with a = {a} mm, b = {b} mm and l_a = {l_a} mm",
                bound=bound,
                a=a,
                b=b,
                l_a=l_a,
            )
        if name == "a":
            return Phrase(
                "a must be at most {bound} mm with b = {b} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm",
                bound=bound,
                b=b,
                l_a=l_a,
                stroke=stroke,
            )
        return Phrase(
            "b must be at least {bound} mm with a = {a} mm, l_a = {l_a} mm and the stroke Δd = {stroke} mm",
            bound=bound,
            a=a,
            l_a=l_a,
            stroke=stroke,
        )
    if name == "l_a":
        return Phrase("l_a must be at least {bound} mm with a = {a} mm and b = {b} mm", bound=bound, a=a, b=b)
    if name == "a":
        return Phrase("a must be at least {bound} mm with b = {b} mm and l_a = {l_a} mm", bound=bound, b=b, l_a=l_a)
    return Phrase("b must be at most {bound} mm with a = {a} mm and l_a = {l_a} mm", bound=bound, a=a, l_a=l_a)


def _alternative(rule: _Rule, name: str, bound: str) -> Phrase:
    """The fix of one field, short (the second choice offered)."""
    lower = _FIXES[(rule, name)][0]
    if name == "l_a":
        return Phrase("or l_a at least {bound} mm", bound=bound)
    if name == "stroke":
        return Phrase("or the stroke Δd at least {bound} mm", bound=bound)
    if name == "a":
        return (
            Phrase("or a at least {bound} mm", bound=bound) if lower else Phrase("or a at most {bound} mm", bound=bound)
        )
    return Phrase("or b at least {bound} mm", bound=bound) if lower else Phrase("or b at most {bound} mm", bound=bound)


def geometry_problem(
    a: float, b: float, l_a: float, stroke: float, pivot_spacing: float = 0.0, prefer: Iterable[str] = ()
) -> Phrase | None:
    """Why no pose of ``a, b, l_a, stroke`` [m] fits in the stroke, phrased as the fix (None if one does).

    Eq. (4): ``d_i = p_i + (a - b) - sqrt(l_a² - p_j²)``. Over the reachable set ``|p_1|, |p_2| < l_a`` the pairs
    ``(d_1, d_2)`` that both lie in ``[0, Δd]`` exist iff ``a - b - √2 l_a < Δd`` and ``a - b + l_a > 0`` (the
    extremes are on the diagonal ``p_1 = p_2``). The fix is the bound of one field that makes the whole set valid
    (``pivot_spacing`` [m] < ``l_a`` included) with the others kept, in mm rounded to 0.1 mm on the accepted side:
    the first of ``prefer`` (the fields just changed) that can, then a second choice; then what it means, then the
    rule.
    """
    values = {"a": float(a), "b": float(b), "l_a": float(l_a), "stroke": float(stroke)}
    for rule in (_beyond_reach, _behind_start):
        if not rule(**values):
            continue
        names = dict.fromkeys(n for n in (*prefer, "l_a", "stroke", "a", "b") if (rule, n) in _FIXES)
        bounds = {n: _shown_bound(rule, n, values, float(pivot_spacing)) for n in names}
        usable = [(n, bound) for n, bound in bounds.items() if bound is not None]
        if not usable:  # one field alone cannot fix it (the pivot spacing is in the way)
            fix = Phrase("change a, b, l_a, the stroke Δd or the pivot spacing")
        else:
            fix = _fix(rule, usable[0][0], usable[0][1], values)
        if len(usable) > 1:
            fix = Phrase("{fix} ({alternative})", fix=fix, alternative=_alternative(rule, *usable[1]))
        if rule is _beyond_reach:
            return Phrase(
                "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go beyond "
                "d = Δd (the rule is a − b − √2 l_a < Δd)",
                fix=fix,
            )
        return Phrase(
            "{fix}: otherwise there is no reachable pose inside the stroke, the sliders would have to go behind "
            "d = 0 (the rule is a − b + l_a > 0)",
            fix=fix,
        )
    return None
