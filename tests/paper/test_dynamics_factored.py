"""The closed form's regrouped terms (``_procedure``, issue 27) against the forms printed below eqs. (29) and (31)
and the printed row of eq. (14): the same numbers, state by state, on seeded random parameters and states."""

from __future__ import annotations

import numpy as np

from tests.support.strategies import random_states
from tpm_viz.core.params import Params
from tpm_viz.paper.dynamics import _procedure, _v_leg, _w_leg
from tpm_viz.paper.jacobians import eq14_row
from tpm_viz.paper.kinematics import inverse_kinematics, leg_components


def printed(params: Params, p1, p2, dp1, dp2, ddp1, ddp2, c1, c2, f1, f2):
    """Steps (b)-(e) composed from the printed expressions (eqs. 9, 14, 29, 31)."""
    dd1, dd2 = dp1 + p2 * dp2 / c1, dp2 + p1 * dp1 / c2
    ddd1 = eq14_row(p1, p2, dp1, dp2, ddp1, ddp2, c1, dd1)
    ddd2 = eq14_row(p2, p1, dp2, dp1, ddp2, ddp1, c2, dd2)
    mp, ma, mb = params.m_p, params.m_a, params.m_b
    v1 = _v_leg(mp, mb, p1, p2, dp1, dp2, ddp1, c1, c2, dd1, dd2, ddd2) - f1
    v2 = _v_leg(mp, mb, p2, p1, dp2, dp1, ddp2, c2, c1, dd2, dd1, ddd1) - f2
    det = 4.0 * (c1 * c2 - p1 * p2)
    lam1, lam2 = (2.0 * c2 * v1 - 2.0 * p1 * v2) / det, (2.0 * c1 * v2 - 2.0 * p2 * v1) / det
    w1, w2 = _w_leg(ma, mb, p2, dp1, dp2, ddp2, c1, ddd1), _w_leg(ma, mb, p1, dp2, dp1, ddp1, c2, ddd2)
    return dd1, dd2, ddd1, ddd2, v1, v2, w1, w2, lam1, lam2, w1 + 2.0 * lam1 * c1, w2 + 2.0 * lam2 * c2


def test_the_regrouped_procedure_is_the_printed_one():
    rng = np.random.default_rng(11)
    for la, mb in ((0.26, 0.84), (0.12, 9.0), (0.5, 0.05)):
        params = Params.paper(l_a=la, m_b=mb, a=0.482 * la / 0.26 + 0.1, pivot_spacing=0.2 * la)
        for p, dp, ddp in random_states(params, 200, seed=int(rng.integers(1 << 30))):
            d = inverse_kinematics(params, p)
            c, _ = leg_components(params, p, d)
            f = rng.normal(0, 20, 2)
            args = (params, p[0], p[1], dp[0], dp[1], ddp[0], ddp[1], c[0], c[1], f[0], f[1])
            got, want = np.array(_procedure(*args)).reshape(6, 2), np.array(printed(*args)).reshape(6, 2)
            # norm-wise per quantity (ḋ, d̈, v, w, λ, τ): both legs of one quantity share a unit and a scale
            assert np.all(np.max(np.abs(got - want), 1) <= 1e-12 * np.max(np.abs(want), 1))
