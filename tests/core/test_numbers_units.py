"""One unit rule for typed numbers (issue 40, item 8): a field's unit may be typed after the number with the SI
prefixes kilo, milli and micro (and centi on lengths) on every unit the app accepts, and a unit of another quantity
is refused.

Expected values come from the powers of ten of the prefixes, written out here (not read from the module's table),
and from hand examples (``5 kN`` in N is 5000; ``0.15 m`` in mm is 150).
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import parse_quantity
from tpm_viz.ui.widgets.typed import Quantity

POWER = {"": 0, "k": 3, "m": -3, "µ": -6, "μ": -6, "u": -6}
"""Each prefix's power of ten (SI brochure, table 7)."""
BASES = ("N", "m", "s", "Hz", "g", "m/s")
"""Units of the app's fields without their prefixes (N: forces, mm: lengths, s: times, Hz: rates, kg: masses)."""


@pytest.mark.parametrize(
    ("text", "unit", "value"),
    [
        ("5 kN", "N", 5000.0),  # was "not a number" in an N box
        ("5kN", "N", 5000.0),
        ("0,5 kN", "N", 500.0),
        ("0.15 m", "mm", 150.0),
        ("15 cm", "mm", 150.0),
        ("20 µm", "mm", 0.02),
        ("20 um", "mm", 0.02),
        ("2 mm", "µm", 2000.0),
        ("1 kHz", "Hz", 1000.0),
        ("250 ms", "s", 0.25),
        ("500 g", "kg", 0.5),
        ("2 kg", "kg", 2.0),
        ("300 mm/s", "m/s", 0.3),
        ("−3 mm", "mm", -3.0),
        ("1e-3 m", "mm", 1.0),
        ("2e-1", "s", 0.2),
    ],
)
def test_a_unit_with_a_prefix_is_read_in_the_fields_unit(text: str, unit: str, value: float) -> None:
    assert parse_quantity(text, "x", unit) == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize(
    ("text", "unit"),
    [("5 m", "N"), ("3 s", "mm"), ("3 m", "m/s"), ("5 kN", "%"), ("5 kN", ""), ("5 k", "N"), ("5 MN", "N")],
)
def test_a_unit_of_another_quantity_or_no_unit_is_refused(text: str, unit: str) -> None:
    with pytest.raises(InputError, match=r"^x"):  # one line naming the field (and the units that fit)
        parse_quantity(text, "x", unit)


@given(
    x=st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
    typed=st.sampled_from(sorted(POWER)),
    field=st.sampled_from(sorted(POWER)),
    base=st.sampled_from(BASES),
)
def test_every_prefix_pair_scales_by_its_powers_of_ten(x: float, typed: str, field: str, base: str) -> None:
    value = parse_quantity(f"{x!r} {typed}{base}", "x", field + base)
    assert value == pytest.approx(x * 10.0 ** (POWER[typed] - POWER[field]), rel=1e-12, abs=1e-300)


def test_the_typed_fields_read_the_rule_and_refuse_what_overflows() -> None:
    force = Quantity("F_max", "N", lo=20.0, hi=1000.0)
    assert force.read("0.5 kN") == 500.0
    with pytest.raises(InputError, match=r"F_max: 5000 N is out of range; type a value from 20 to 1000 N"):
        force.read("5 kN")
    length = Quantity("p1", "mm", 1e-3)
    assert length.read("0.15 m") == pytest.approx(0.15)
    with pytest.raises(InputError, match="too large"):
        length.read("1e306 km")
    assert math.isfinite(length.read("1e300 mm"))
