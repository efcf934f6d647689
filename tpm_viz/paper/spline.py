"""Natural cubic splines in numpy: smooth derivatives of sampled platform paths.

A user's trajectory arrives as timed samples ``(t_k, p_k)``. We interpolate each coordinate
with the C² natural cubic spline (second derivative zero at both ends) and differentiate
the spline exactly, which gives continuous velocity and acceleration without the noise
amplification of finite differences. The tridiagonal system is solved by the Thomas
algorithm (O(n)).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["CubicSpline"]


class CubicSpline:
    """Natural cubic spline through ``(t, y)``; ``y`` has shape ``(n, m)``; ``t`` strictly increasing."""

    def __init__(self, t: ArrayLike, y: ArrayLike) -> None:
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float)
        if y.ndim == 1:
            y = y[:, None]
        if t.ndim != 1 or y.shape[0] != t.shape[0]:
            raise InputError(f"spline needs t of shape (n,) and y of shape (n, m), got {t.shape} and {y.shape}")
        if t.size < 2:
            raise InputError(Phrase("a spline needs at least 2 samples, got {n}", n=t.size))
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
            raise InputError(Phrase("spline samples contain a non-finite value (NaN or inf)"))
        h = np.diff(t)
        if np.any(h <= 0):
            k = int(np.argmax(h <= 0)) + 1
            raise InputError(
                Phrase(
                    "time must increase strictly: t[{k}] = {later:g} s after t[{before}] = {earlier:g} s",
                    k=k,
                    later=float(t[k]),
                    before=k - 1,
                    earlier=float(t[k - 1]),
                )
            )
        self.t, self.y, self._h = t, y, h
        self.m = self._second_derivatives(h, y)

    @staticmethod
    def _second_derivatives(h: np.ndarray, y: np.ndarray) -> np.ndarray:
        n = y.shape[0]
        m = np.zeros_like(y)
        if n < 3:
            return m
        slope = np.diff(y, axis=0) / h[:, None]
        rhs = 6.0 * (slope[1:] - slope[:-1])  # (n-2, m)
        diag = 2.0 * (h[:-1] + h[1:])
        off = h[1:-1]
        # Thomas algorithm on the symmetric tridiagonal system for m[1:-1].
        cp = np.zeros(n - 2)
        dp = np.zeros_like(rhs)
        cp[0] = off[0] / diag[0] if n > 3 else 0.0
        dp[0] = rhs[0] / diag[0]
        for k in range(1, n - 2):
            denom = diag[k] - off[k - 1] * cp[k - 1]
            cp[k] = off[k] / denom if k < n - 3 else 0.0
            dp[k] = (rhs[k] - off[k - 1] * dp[k - 1]) / denom
        inner = np.zeros_like(rhs)
        inner[-1] = dp[-1]
        for k in range(n - 4, -1, -1):
            inner[k] = dp[k] - cp[k] * inner[k + 1]
        m[1:-1] = inner
        return m

    def __call__(self, tq: ArrayLike, nu: int = 0) -> np.ndarray:
        """Value (``nu=0``), first or second derivative (``nu=1, 2``) at times ``tq``; shape ``(..., m)``."""
        tq = np.asarray(tq, dtype=float)
        k = np.clip(np.searchsorted(self.t, tq, side="right") - 1, 0, self.t.size - 2)
        h = self._h[k][..., None]
        a = (self.t[k + 1][..., None] - tq[..., None]) / h
        b = (tq[..., None] - self.t[k][..., None]) / h
        y0, y1, m0, m1 = self.y[k], self.y[k + 1], self.m[k], self.m[k + 1]
        if nu == 0:
            return a * y0 + b * y1 + ((a**3 - a) * m0 + (b**3 - b) * m1) * h**2 / 6.0
        if nu == 1:
            return (y1 - y0) / h + ((1 - 3 * a**2) * m0 + (3 * b**2 - 1) * m1) * h / 6.0
        if nu == 2:
            return a * m0 + b * m1
        raise ValueError(f"nu must be 0, 1 or 2, got {nu}")
