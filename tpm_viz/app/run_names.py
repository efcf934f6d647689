"""The names of runs and references in words (:mod:`tpm_viz.core.words`): the paper's line and circle are named as the
*Trajectory* and *Reference* dropdowns name them (``line (Fig. 4)``, in the reader's language); any other name (an
uploaded file's) is shown as it is. The player's summary, the control lab's texts and the lab report share these."""

from __future__ import annotations

import re

from tpm_viz.core.words import Phrase, T

__all__ = ["PAPER_NAMES", "label_words", "reference_words"]

PAPER_NAMES = {"line": T("line (Fig. 4)"), "circle": T("circle (Fig. 5)")}
"""The paper's trajectories (``Trajectory.name``, ``Source.kind``) -> their names in words."""
_PAPER_LABEL = re.compile(r"(line|circle) \(Fig\. [45]\), T = (\S+) s")
"""A run label of the paper's line or circle, as :meth:`tpm_viz.app.runs.Source.paper` writes it."""


def reference_words(name: str) -> Phrase:
    """A trajectory's name (``"line"``, ``"circle"``, a file's name) in words."""
    return PAPER_NAMES[name] if name in PAPER_NAMES else Phrase("{name}", name=name)


def label_words(label: str) -> Phrase:
    """A run's label (``"line (Fig. 4), T = 0.2 s"``, ``"wave.csv, T = 1 s"``) in words: the same text in English."""
    match = _PAPER_LABEL.fullmatch(label)
    if match is None or PAPER_NAMES[match.group(1)].template != label.split(", T =")[0]:
        return Phrase("{name}", name=label)
    return Phrase("{name}, T = {duration} s", name=PAPER_NAMES[match.group(1)], duration=match.group(2))
