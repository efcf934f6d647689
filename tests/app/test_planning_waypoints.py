"""The planner's waypoints are read with the one number parser (issue 40, item 1): each coordinate of ``x,y; x,y``
(mm) as :func:`tpm_viz.core.numbers.parse_number` reads it (scientific notation, the Unicode minus), a comma
separating the two; anything else is refused in one line naming the waypoint."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz.app.planning import parse_waypoints
from tpm_viz.core.errors import InputError


def test_coordinates_are_read_like_every_typed_number() -> None:
    got = parse_waypoints("−60,-40; 1e2, 4.0e1\n60 −40")
    np.testing.assert_allclose(got, [[-0.06, -0.04], [0.1, 0.04], [0.06, -0.04]], atol=1e-15)


@pytest.mark.parametrize("text", ["1,2,3; 4,5", "a,b; 1,2", "1e999,1; 2,2", "nan,1; 2,3", "inf,0; 1,1", "5; 1,2"])
def test_a_bad_waypoint_is_refused_naming_it(text: str) -> None:
    with pytest.raises(InputError, match=r"^waypoint 1 \(.*\) must be two numbers 'x,y' in mm$"):
        parse_waypoints(text)
