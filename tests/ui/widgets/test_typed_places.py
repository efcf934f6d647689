"""The Move tab's fields write what the readout shows (issue 40, item 8): one decimal of a millimetre, never ``-0.0``
(they showed six digits, ``-0.633189``, beside a readout of ``-0.6``). The readout's own formatter is
:func:`tpm_viz.classroom.text.num`; the fields are :class:`~tpm_viz.ui.widgets.typed.Quantity` with ``places=1``."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from tpm_viz.classroom.text import num
from tpm_viz.ui.widgets.typed import Quantity

MOVE = Quantity("p1", "mm", 1.0, -1e4, 1e4, places=1)


def test_examples_of_the_issue() -> None:
    assert MOVE.text(-0.633189) == "-0.6"
    assert MOVE.text(-130.001) == "-130.0"
    assert MOVE.text(-0.04) == "0.0"  # never -0.0
    assert Quantity("T", "s").text(0.2) == "0.2"  # other fields: six significant digits, as before


@given(st.floats(min_value=-10.0, max_value=10.0, allow_nan=False))
def test_the_field_shows_what_the_readout_shows(metres: float) -> None:
    mm = metres * 1e3  # the panel's value in use (mm) and the readout's (m, scaled to mm) from the same pose
    assert MOVE.text(mm) == num(metres, ".1f", 1e3)
    assert MOVE.means(MOVE.text(mm), mm)  # the text written reads back as the value in use (it is not re-sent)
