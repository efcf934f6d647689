"""Names in figures, drawn as they were typed: a file name such as ``x$\\frac{$.csv`` or ``$x^2$`` is text, never
matplotlib's mathtext (which crashed the report and the clip on the first, and set the second as maths).

:func:`name_props` are the properties of every matplotlib ``Text`` that shows a user's text (a run's label, a file
name): ``parse_math=False``, and a font list that adds an installed Hangul font after matplotlib's own (matplotlib
falls back glyph by glyph along the list, so ``한국어.csv`` is drawn in Hangul where such a font exists).
:func:`quiet_glyphs` silences matplotlib's one warning per missing glyph while a figure with such text is drawn (a
machine without a Hangul font draws boxes, as any program would, without ten lines on the terminal).
"""

from __future__ import annotations

import contextlib
import functools
import warnings
from collections.abc import Iterator
from typing import Any

from matplotlib import font_manager, rcParams

__all__ = ["HANGUL_FONTS", "name_props", "quiet_glyphs"]

HANGUL_FONTS = (
    "NanumGothic",
    "NanumBarunGothic",
    "Noto Sans CJK KR",
    "Noto Sans KR",
    "Malgun Gothic",
    "Apple SD Gothic Neo",
    "AppleGothic",
)
"""Fonts with Hangul, in the order they are preferred (the report's style sheet names the same ones)."""


@functools.cache
def _families() -> tuple[str, ...]:
    """matplotlib's default sans-serif font, then the first installed Hangul font (if any)."""
    installed = {font.name for font in font_manager.fontManager.ttflist}
    first = next((name for name in rcParams["font.sans-serif"] if name in installed), "DejaVu Sans")
    hangul = next((name for name in HANGUL_FONTS if name in installed), None)
    return (first,) if hangul is None else (first, hangul)


def name_props() -> dict[str, Any]:
    """Keyword properties of a ``Text`` that shows a user's text (see the module docstring)."""
    return {"parse_math": False, "fontfamily": list(_families())}


@contextlib.contextmanager
def quiet_glyphs() -> Iterator[None]:
    """Draw without matplotlib's "Glyph ... missing from font(s)" warnings (every other warning is kept)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from font", category=UserWarning)
        yield
