"""Hypothesis strategies shared by the tests: valid parameter sets and regular states (SI units)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st

from tpm_viz import InvalidParametersError, Params


@st.composite
def params_sets(draw) -> Params:
    """Random valid parameter sets around the paper's prototype (lengths 0.5x-2x, masses 0.1x-10x)."""
    l_a = draw(st.floats(0.12, 0.5))
    a = draw(st.floats(0.2, 1.0))
    b = draw(st.floats(0.02, 0.2))
    stroke = draw(st.floats(0.1, 0.8))
    masses = {k: draw(st.floats(0.05, 10.0)) for k in ("m_a", "m_b", "m_p")}
    try:
        return Params(a=a, b=b, l_a=l_a, stroke=stroke, pivot_spacing=0.2 * l_a, **masses)
    except InvalidParametersError:
        assume(False)
        raise


@st.composite
def regular_states(draw, params: Params, margin: float = 0.25):
    """A platform state (p, ṗ, p̈) [m, m/s, m/s²] away from both singularities (working mode)."""
    la = params.l_a
    p = np.array([draw(st.floats(-0.85 * la, 0.85 * la)), draw(st.floats(-0.85 * la, 0.85 * la))])
    cos1, cos2 = math.sqrt(1 - (p[1] / la) ** 2), math.sqrt(1 - (p[0] / la) ** 2)
    det_jx = cos1 * cos2 - p[0] * p[1] / la**2
    assume(min(cos1, cos2) > margin and abs(det_jx) > margin)
    dp = np.array([draw(st.floats(-2, 2)), draw(st.floats(-2, 2))])
    ddp = np.array([draw(st.floats(-30, 30)), draw(st.floats(-30, 30))])
    return p, dp, ddp


def random_states(params, count: int, seed: int):
    """Seeded (numpy) regular platform states ``(p, ṗ, p̈)``: ``|p_j| <= 0.85 l_a``, cos θ_i and det J_x above
    0.25 (SI units)."""
    rng, la, out = np.random.default_rng(seed), params.l_a, []
    while len(out) < count:
        p = rng.uniform(-0.85 * la, 0.85 * la, 2)
        cos1, cos2 = math.sqrt(1 - (p[1] / la) ** 2), math.sqrt(1 - (p[0] / la) ** 2)
        if min(cos1, cos2) > 0.25 and abs(cos1 * cos2 - p[0] * p[1] / la**2) > 0.25:
            out.append((p, rng.uniform(-2, 2, 2), rng.uniform(-30, 30, 2)))
    return out
