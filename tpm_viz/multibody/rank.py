"""Rank-revealing linear algebra (pure numpy, SVD) for the over-constrained multibody model.

A planar mechanism closed with 3D point constraints has more constraint rows than independent
constraints. These helpers reveal the numerical rank with an SVD and work with the row space
and null space, so that nothing depends on which redundant rows happen to be in the stack.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["RankedSvd", "ranked_svd"]

RANK_RTOL = 1e-9
"""Singular values below ``RANK_RTOL * σ_max`` count as zero."""


class RankedSvd(NamedTuple):
    """An SVD ``A = U diag(s) Vt`` with its numerical ``rank`` (see :data:`RANK_RTOL`)."""

    u: np.ndarray
    s: np.ndarray
    vt: np.ndarray
    rank: int

    @property
    def null_space(self) -> np.ndarray:
        """Orthonormal basis of the null space of ``A``, shape ``(n, n - rank)``."""
        return self.vt[self.rank :].T

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Minimum-norm least-squares solution ``x = A⁺ b`` on the revealed rank (``b``: (m,) or (m, k))."""
        r = self.rank
        scale = self.s[:r] if np.ndim(b) == 1 else self.s[:r, None]
        return self.vt[:r].T @ ((self.u[:, :r].T @ b) / scale)


def ranked_svd(a: np.ndarray, rtol: float = RANK_RTOL) -> RankedSvd:
    """Full SVD of ``a`` with its numerical rank (``σ_k > rtol σ_max``)."""
    u, s, vt = np.linalg.svd(a, full_matrices=True)
    rank = int(np.count_nonzero(s > rtol * s[0])) if s.size and s[0] > 0 else 0
    return RankedSvd(u, s, vt, rank)
