"""One exercise in one place of a tab (the *Exercises* tab, or under its lesson's text in *Demos*): the prompt, an
answer box, *Use current pose* (pose answers), *Submit*, and the result.

The answer box is a one-line text in a form, like the app's typed numbers (:mod:`tpm_viz.ui.fields`): Enter reaches
the server as a line break at the end of the whole text (or as the form's submit) and submits it, so no keystroke is
lost in viser's input throttle. The widgets are made through the tab's :class:`~tpm_viz.ui.worded.TabGui` (their
fixed texts in its language); the prompt and the result are HTML written by :mod:`.text`. The card holds no state:
its owner (:class:`~.tab.ExercisesView`) keeps a :class:`~.text.Mine` per exercise and draws every card of it.
"""

from __future__ import annotations

from typing import Any, Protocol

import viser

from tpm_viz.app.exercises.model import Kind
from tpm_viz.core.words import Lang, T
from tpm_viz.ui.fields import one_line
from tpm_viz.ui.teaching.exercises.text import Mine, prompt_html, result_html
from tpm_viz.ui.worded import TabGui
from tpm_viz.viserkit.core import removed

__all__ = ["Card", "Owner"]

ANSWER = T("Answer")
ANSWER_HINT = T("Type your answer as anywhere in the app (units, decimal commas); Enter submits it")
USE_POSE = T("Use current pose")
POSE_HINT = T("Write the platform's position p1; p2 in mm into the answer: drag the platform first")
SUBMIT = T("Submit")


class Owner(Protocol):
    """What a card's buttons call (the tab's :class:`~.tab.ExercisesView`)."""

    def on_key(self, card: Card, event: Any) -> None: ...

    def on_submit(self, card: Card, event: Any) -> None: ...

    def on_pose(self, card: Card, event: Any) -> None: ...


class Card:
    """The widgets of one exercise (see the module docstring), built in the current GUI container."""

    def __init__(self, gui: TabGui, mine: Mine, owner: Owner) -> None:
        self.id = mine.exercise.id
        self.box = False
        """Whether the card is under the lesson's text in *Demos* (else in the *Exercises* tab)."""
        lang = gui.lang
        self.prompt = gui.add_html(prompt_html(mine, lang))
        self.form = gui.add_form(None)
        with self.form:
            self.answer = gui.add_text(ANSWER.template, "", hint=ANSWER_HINT.template, multiline=True)
        self.pose = None
        if mine.exercise.kind is Kind.POSE:
            self.pose = gui.add_button(USE_POSE.template, icon=viser.Icon.CURRENT_LOCATION, hint=POSE_HINT.template)
            self.pose.on_click(lambda event: owner.on_pose(self, event))
        self.submit = gui.add_button(SUBMIT.template, icon=viser.Icon.SEND)
        self.result = gui.add_html(result_html(mine, lang))
        self.answer.on_update(lambda event: owner.on_key(self, event))
        self.form.on_submit(lambda event: owner.on_submit(self, event))
        self.submit.on_click(lambda event: owner.on_submit(self, event))
        self.draw(mine, lang)

    @property
    def gone(self) -> bool:
        """Whether the card's widgets were removed (its folder closed, the lesson changed)."""
        return removed(self.result.handle)

    def text(self) -> str:
        """The answer as typed (without the line break of an Enter)."""
        return str(one_line(self.answer.value))

    def entered(self) -> bool:
        """Whether Enter reached the box as a line break: written back without it (then submit)."""
        text = self.text()
        if text != self.answer.value:
            self.answer.value = text
            return True
        return False

    def write(self, text: str) -> None:
        """Put ``text`` in the answer box (the page shows it: viser sends only a change)."""
        if self.answer.value == text:
            self.answer.value = text + " "
        self.answer.value = text

    def draw(self, mine: Mine, lang: Lang) -> None:
        """Show ``mine`` (viser gets only what changed)."""
        prompt = prompt_html(mine, lang)
        result = result_html(mine, lang)
        if self.prompt.content != prompt:
            self.prompt.content = prompt
        if self.result.content != result:
            self.result.content = result
        closed = mine.prompt is None or mine.grading or mine.left == 0
        if self.submit.disabled != closed:
            self.submit.disabled = closed
        if self.answer.disabled != (mine.left == 0):
            self.answer.disabled = mine.left == 0

    def retell(self, mine: Mine, lang: Lang) -> None:
        """The tab's language changed (its fixed texts were relabelled): the prompt and result again, in it."""
        self.draw(mine, lang)

    def remove(self) -> None:
        """Take the card's widgets out of the tab."""
        for handle in (self.prompt, self.form, self.pose, self.submit, self.result):
            if handle is not None and not removed(handle.handle):
                handle.remove()
