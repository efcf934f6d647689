"""The paper's closed form as a plant: platform accelerations from actuator forces (forward dynamics).

The inverse dynamics of eqs. (28)-(31) is affine in the platform acceleration: at a state ``(p, ṗ)``,
``τ = M(p) p̈ + h(p, ṗ)`` with ``M(p)`` [kg] the platform-to-actuator inertia (the forces for ``ṗ = 0`` and a unit
``p̈`` along each axis: its columns) and ``h(p, ṗ) = τ(p, ṗ, p̈ = 0)`` [N] the velocity terms. So the forward
dynamics is ``p̈ = M(p)⁻¹ (τ - h(p, ṗ))``: three evaluations of the closed form's steps (b)-(e)
(:func:`tpm_viz.paper.dynamics._procedure`, floats, ~4 µs each) and a 2 x 2 solve. The multibody package's
:class:`~tpm_viz.multibody.forward.PlatformPlant` is the same dynamics from Pinocchio's tree (the tests compare the
two, ``tests/paper/test_plant.py``); this one needs no Pinocchio, so the app layer may simulate with it (the
exercise that grades controller gains, :mod:`tpm_viz.app.exercises`).

Working mode only (eq. 4): ``c_i = l_a cos θ_i = sqrt(l_a² - p_j²)``. No gravity, no friction (as the closed form).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from tpm_viz.core.errors import SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.dynamics import SINGULAR_TOL, _procedure

__all__ = ["Acceleration", "closed_form_plant", "leg_cosines"]

Acceleration = Callable[[float, float, float, float, float, float], tuple[float, float]]
"""``f(p1, p2, ṗ1, ṗ2, τ1, τ2) -> (p̈1, p̈2)`` [m, m/s, N -> m/s²]: a plant, one state, floats."""


def leg_cosines(la: float, p1: float, p2: float) -> tuple[float, float]:
    """``c_i = l_a cos θ_i = sqrt(l_a² - p_j²)`` [m] (eq. 4, working mode) of a simulated platform at ``(p1, p2)``
    [m]. :class:`~tpm_viz.core.errors.UnreachablePoseError` once ``|p_j|`` reaches ``l_a`` (or a NaN: the motion
    diverged)."""
    la2 = la * la
    r1, r2 = la2 - p2 * p2, la2 - p1 * p1
    if not (r1 > 1e-12 * la2 and r2 > 1e-12 * la2):  # also catches NaN
        raise UnreachablePoseError(
            Phrase(
                "the simulated platform reached ({x}, {y}) mm: |p_j| must stay below l_a = {l_a} mm (unstable motion?)",
                x=fixed(p1, ".1f", 1e3),
                y=fixed(p2, ".1f", 1e3),
                l_a=fixed(la, ".1f", 1e3),
            )
        )
    return math.sqrt(r1), math.sqrt(r2)


def closed_form_plant(params: Params) -> Acceleration:
    """The forward dynamics ``p̈ = M(p)⁻¹ (τ - h(p, ṗ))`` of the closed form (module docstring) for ``params``.

    Raises :class:`~tpm_viz.core.errors.UnreachablePoseError` when ``|p_j| >= l_a`` (the platform left the working
    mode's domain: an unstable loop) and :class:`~tpm_viz.core.errors.SingularConfigurationError` at a singularity
    (eqs. 11-12), where ``M(p)`` cannot be inverted.
    """
    la = params.l_a
    la2 = la * la

    def acceleration(p1: float, p2: float, v1: float, v2: float, tau1: float, tau2: float) -> tuple[float, float]:
        c1, c2 = leg_cosines(la, p1, p2)
        if abs(c1 * c2) < SINGULAR_TOL * la2 or abs(c1 * c2 - p1 * p2) < SINGULAR_TOL * la2:
            raise SingularConfigurationError(Phrase("the simulated platform reached a singularity (eqs. 11-12)"))
        h = _procedure(params, p1, p2, v1, v2, 0.0, 0.0, c1, c2, 0.0, 0.0)
        m1 = _procedure(params, p1, p2, 0.0, 0.0, 1.0, 0.0, c1, c2, 0.0, 0.0)  # column 1 of M(p)
        m2 = _procedure(params, p1, p2, 0.0, 0.0, 0.0, 1.0, c1, c2, 0.0, 0.0)  # column 2 of M(p)
        a11, a21, a12, a22 = m1[10], m1[11], m2[10], m2[11]
        b1, b2 = tau1 - h[10], tau2 - h[11]
        det = a11 * a22 - a12 * a21
        return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a21 * b1) / det

    return acceleration
