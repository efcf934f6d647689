"""Velocity and force manipulability ellipses of the 2-PPa TPM (from ``J``, eq. 10; statics eq. 13).

- Velocity ellipse: the platform velocities reached with unit actuator speed, ``{ṗ : |J ṗ| <= 1}``.
  With the SVD ``J = U Σ Vᵀ`` its semi-axes are ``1/σ_k`` [m/s per m/s] along the columns ``v_k`` of ``V``.
- Force ellipse: the platform forces produced by unit actuator forces, ``{f = Jᵀ τ : |τ| <= 1}``:
  semi-axes ``σ_k`` [N per N] along the same ``v_k``. The two ellipses are dual: long where the other is short.

Near the inverse singularity (``cos θ_i -> 0``) ``J`` blows up: the velocity ellipse collapses and the force
ellipse grows; near the direct singularity (``det J_x -> 0``) ``J`` loses rank: the velocity ellipse grows along
the uncontrolled direction.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.jacobians import jacobians

__all__ = ["Ellipse", "ManipulabilityEllipses", "ellipse_outline", "manipulability_ellipses"]


class Ellipse(NamedTuple):
    """An ellipse: unit ``axes`` as columns ``(2, 2)`` and semi-axis lengths ``radii`` ``(2,)``."""

    axes: np.ndarray
    radii: np.ndarray


class ManipulabilityEllipses(NamedTuple):
    velocity: Ellipse  # radii in (m/s) per (m/s) of actuator speed
    force: Ellipse  # radii in N per N of actuator force


def manipulability_ellipses(params: Params, p: ArrayLike, max_ratio: float = 1e6) -> ManipulabilityEllipses:
    """Both ellipses at one platform position ``p`` [m], working mode.

    Raises :class:`SingularConfigurationError` when ``J`` is singular or its condition number exceeds
    ``max_ratio`` (the ellipses would be degenerate or unbounded).
    """
    j = jacobians(params, p).j
    if j.shape != (2, 2) or not np.all(np.isfinite(j)):
        raise SingularConfigurationError(Phrase("manipulability ellipses need one regular pose (cos θ_i != 0)"))
    _, sigma, vt = np.linalg.svd(j)
    if sigma[-1] <= sigma[0] / max_ratio:
        raise SingularConfigurationError(
            Phrase("manipulability ellipses are degenerate at the direct singularity (eq. 12)")
        )
    axes = vt.T  # columns v_k
    return ManipulabilityEllipses(velocity=Ellipse(axes, 1.0 / sigma), force=Ellipse(axes, sigma.copy()))


def ellipse_outline(ellipse: Ellipse, centre: ArrayLike = (0.0, 0.0), scale: float = 1.0, n: int = 64) -> np.ndarray:
    """``(n, 2)`` points on the ellipse (closed: first point repeated last), scaled by ``scale``."""
    phi = np.linspace(0.0, 2.0 * np.pi, n)
    unit = np.stack([np.cos(phi), np.sin(phi)], -1)
    return np.asarray(centre, float) + scale * (unit * ellipse.radii) @ ellipse.axes.T
