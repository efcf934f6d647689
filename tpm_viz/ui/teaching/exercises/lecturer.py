"""*Exercise results* in the *Lecturer* folder (:mod:`tpm_viz.ui.lecturer`): the live table of the class's answers,
the CSV download, and the class-wide seed (an exam on the wall: every student gets the same numbers).

Widgets only: the app's :class:`~.desk.ExerciseDesk` decides who sees it (the tabs the app treats as the lecturer's,
:meth:`tpm_viz.ui.room.Room.lecturer`), draws the table (debounced) and does what the buttons ask, checking again
that the tab is the lecturer's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import viser

from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.resultsdb import Summary
from tpm_viz.core.words import Phrase, T
from tpm_viz.ui.teaching.exercises.text import table_html
from tpm_viz.ui.worded import TabGui
from tpm_viz.viserkit.core import removed

__all__ = ["FOLDER", "ResultsSection", "status_phrase"]

FOLDER = T("Exercise results")
SEED = T("Class seed")
SEED_HINT = T("A whole number from 0: fix it and every student answers with the same numbers (an exam on the wall)")
FIX = T("Fix this seed for the class")
UNFIX = T("A variant per student again")
DOWNLOAD = T("Download results (CSV)")
CSV_NAME = "tpm-viz-results.csv"


def status_phrase(seed: int | None) -> Phrase:
    """Whose numbers the students answer with."""
    if seed is None:
        return T("A variant per student: everybody answers with their own numbers.")
    return Phrase("Class seed {seed}: every student answers with the same numbers.", seed=seed)


class Desk(Protocol):
    """What the section's buttons ask of the app (:class:`~.desk.ExerciseDesk`)."""

    def fix(self, view: Any, seed: object) -> None: ...

    def download(self, view: Any) -> None: ...


class ResultsSection:
    """The section of one lecturer's tab, built in the current container (the *Lecturer* folder)."""

    def __init__(self, gui: TabGui, desk: Desk, view: Any, seed: int | None) -> None:
        self.view = view
        self.folder = gui.add_folder(FOLDER.template, expand_by_default=True)
        with self.folder:
            self.table = gui.add_html(table_html((), 0, status_phrase(seed), gui.lang))
            self.download = gui.add_button(DOWNLOAD.template, icon=viser.Icon.DOWNLOAD)
            self.seed = gui.add_text(SEED.template, "" if seed is None else str(seed), hint=SEED_HINT.template)
            self.fix = gui.add_button(FIX.template, icon=viser.Icon.LOCK)
            self.unfix = gui.add_button(UNFIX.template, icon=viser.Icon.LOCK_OPEN)
        self.download.on_click(lambda event: self._on(event, desk.download, view))
        self.fix.on_click(lambda event: self._on(event, desk.fix, view, self.seed.value))
        self.unfix.on_click(lambda event: self._on(event, desk.fix, view, None))

    @property
    def gone(self) -> bool:
        """Whether the section was removed (the presenter logged out: the *Lecturer* folder went)."""
        return removed(self.table.handle)

    @guarded
    def _on(self, event: Any, action: Any, *args: Any) -> None:
        if getattr(event, "client", None) is not None and not getattr(self.view, "closed", False):
            action(*args)

    def show(self, lines: Sequence[Summary], total: int, seed: int | None) -> None:
        """The table (the latest ``lines`` of ``total``) and the seed in force, in the tab's language (under the hub's
        lock); viser gets only what changed."""
        content = table_html(lines, total, status_phrase(seed), self.view.lang)
        if self.table.content != content:
            self.table.content = content
        if seed is not None and str(self.seed.value).strip() != str(seed):
            self.seed.value = str(seed)  # the seed in force (unfixed: the field keeps the last one, to fix it again)
