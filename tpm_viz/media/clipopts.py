"""A clip's options, checked before anything heavy is imported: its frame size [px] and frame rate [frames/s].

Standard library only, so that ``tpm-viz clip`` refuses a bad ``--size``, ``--fps`` or output name in a moment, before
matplotlib, Pillow, PyAV and Pinocchio load (:mod:`.clips` draws the frames, :mod:`.videos` encodes them).
"""

from __future__ import annotations

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["DEFAULT_FPS", "DEFAULT_SIZE", "FORMATS", "MAX_FPS", "MAX_SIZE", "MIN_SIZE", "SIZE_PRESETS"]
__all__ += ["check_fps", "parse_size"]

MIN_SIZE, MAX_SIZE = (320, 180), (1920, 1080)
"""Smallest and largest frame ``(width, height)`` [px]."""
DEFAULT_SIZE = (800, 450)
SIZE_PRESETS = {"640×360": (640, 360), "800×450": (800, 450), "1280×720": (1280, 720), "1920×1080": (1920, 1080)}
"""Frame sizes offered in the app [px]."""
DEFAULT_FPS, MAX_FPS = 20, 50
"""Frame rate [frames/s]: default and most (a GIF stores delays in 10 ms steps)."""
FORMATS = ("gif", "mp4")
"""The clip formats, by file name ending."""


def parse_size(text: str) -> tuple[int, int]:
    """``"WxH"`` (also ``W×H``) [px] within :data:`MIN_SIZE`-:data:`MAX_SIZE`; one-line :class:`InputError`."""
    parts = str(text).lower().replace("×", "x").split("x")
    try:
        width, height = (int(s.strip()) for s in parts)
    except ValueError:
        raise InputError(
            Phrase("the size must be WIDTHxHEIGHT in pixels (e.g. 800x450), got {got}", got=repr(text))
        ) from None
    if not (MIN_SIZE[0] <= width <= MAX_SIZE[0] and MIN_SIZE[1] <= height <= MAX_SIZE[1]):
        raise InputError(
            Phrase(
                "the size must be from {lo} to {hi} pixels, got {got}",
                lo=f"{MIN_SIZE[0]}x{MIN_SIZE[1]}",
                hi=f"{MAX_SIZE[0]}x{MAX_SIZE[1]}",
                got=f"{width}x{height}",
            )
        )
    return width, height


def check_fps(fps: object) -> int:
    """A whole number of frames per second from 1 to :data:`MAX_FPS`; one-line :class:`InputError`."""
    if isinstance(fps, bool) or not isinstance(fps, int | float) or fps != int(fps) or not 1 <= fps <= MAX_FPS:
        raise InputError(
            Phrase(
                "the frame rate must be a whole number from 1 to {hi} frames/s, got {got}", hi=MAX_FPS, got=repr(fps)
            )
        )
    return int(fps)
