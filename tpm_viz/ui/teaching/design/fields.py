"""The typed fields of the *Design* tab's task, axes and cell pick (mm shown, m held)."""

from __future__ import annotations

from tpm_viz.ui.teaching.design.map import MAX_COUNT
from tpm_viz.ui.widgets.typed import Quantity, TypedField

__all__ = ["count_field", "length_field"]


def length_field(name: str, value_m: float) -> TypedField:
    """A typed length of the map's task or axes: shown in mm, held in m, within ±5 m."""
    return TypedField(Quantity(name, "mm", 1e-3, -5000.0, 5000.0), value_m)


def count_field(value: int) -> TypedField:
    """A typed count of cells (or a column/row number): 1 to :data:`MAX_COUNT`."""
    return TypedField(Quantity("count", "", 1.0, 1.0, float(MAX_COUNT)), float(value))
