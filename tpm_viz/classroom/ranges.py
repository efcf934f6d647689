"""Physically meaningful ranges of what a session file or a share link carries (:mod:`.sessionfile` reads both).

A share link is made by anyone (its token holds no secret), so every number in it is checked as a browser's typed
value would be: finite is not enough (``p = 1e308`` samples opened without a word). :func:`within` refuses a value
outside its range in one line naming the field; :func:`check_samples` holds an uploaded trajectory's samples to the
upload's own limits (:func:`tpm_viz.app.inputs.read_upload`). Every refusal is a :class:`~tpm_viz.InputError` with a
:class:`~tpm_viz.core.words.Phrase` (the tab says it in its language).
"""

from __future__ import annotations

import numpy as np

from tpm_viz.app.inputs import MAX_UPLOAD_POSITION, MAX_UPLOAD_SECONDS
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase
from tpm_viz.paper.spline import CubicSpline

__all__ = ["check_samples", "within"]


def within(value: float | tuple[float, float], name: str, where: str, span: tuple[float, float], unit: str) -> None:
    """Refuse (one line naming the field and its range) a value outside ``span`` [``unit``]."""
    low, high = span
    if not all(low <= v <= high for v in (value if isinstance(value, tuple) else (value,))):
        raise InputError(
            Phrase(
                "session file: {where}{name} must be from {low:g} to {high:g} {unit}",
                where=where,
                name=name,
                low=low,
                high=high,
                unit=unit,
            )
        )


def check_samples(t: np.ndarray, p: np.ndarray) -> None:
    """Refuse an uploaded trajectory's samples (``t`` (n,) [s] increasing, ``p`` (n, 2) [m], finite) that reach
    beyond :data:`~tpm_viz.app.inputs.MAX_UPLOAD_POSITION`, last longer than
    :data:`~tpm_viz.app.inputs.MAX_UPLOAD_SECONDS` or are so close in time that the spline's velocities or
    accelerations are not finite (as :func:`tpm_viz.app.inputs.read_upload` refuses an upload)."""
    if not np.all(np.abs(p) <= MAX_UPLOAD_POSITION):
        raise InputError(
            Phrase("session file: the uploaded trajectory goes beyond {most:g} m", most=MAX_UPLOAD_POSITION)
        )
    with np.errstate(all="ignore"):
        span = float(t[-1] - t[0])
        if not span <= MAX_UPLOAD_SECONDS:
            raise InputError(
                Phrase("session file: the uploaded trajectory lasts more than {most:g} s", most=MAX_UPLOAD_SECONDS)
            )
        spline = CubicSpline(t, p)
        if not (np.all(np.isfinite(spline(t, 1))) and np.all(np.isfinite(spline(t, 2)))):
            raise InputError(
                Phrase(
                    "session file: the uploaded trajectory's samples are too close in time (its velocities or "
                    "accelerations are not finite)"
                )
            )
