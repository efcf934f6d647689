"""The *Presenter login* folder of one tab (presenter mode: :mod:`tpm_viz.classroom.access`).

viser 1.1.1 has no password input (its text field is a plain Mantine ``TextInput`` without an ``id`` or a
``type``), so the token field is masked by a style rule in the page (``-webkit-text-security: disc``, found by the
field's label: Chromium, Safari and Firefox 121+ draw dots) *and* cleared by the server as soon as it is read; the
hint says so. On a browser that ignores the rule the typed characters are visible until the button is pressed:
the lecturer can also present from the serving machine itself (classroom mode), where no token is typed at all.

Enter logs in, like the button. The field is viser's multi-line text input drawn as one line (the typed fields'
:data:`~tpm_viz.ui.fields.ONE_LINE_CSS`), so Enter is a line break in the field's text and arrives with the whole
token, however fast the keys came (viser's page throttles its messages and keeps only the latest: a form's submit
could overtake the last keystrokes). A text with a line break is a login attempt with the text before it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tpm_viz.core.markup import Html, Markdown
from tpm_viz.core.words import Lang, T, say
from tpm_viz.ui.fields import one_line
from tpm_viz.ui.worded import TabGui
from tpm_viz.viserkit.core import widget_uuid

__all__ = ["LoginPanel", "mask_css"]


def mask_css(uuid: str) -> Html:
    """A style rule that draws the characters of the text input labelled by ``uuid`` (viser's uuid: hex digits) as
    dots."""
    scope = f'div:has(> div > p > label[for="{"".join(c for c in uuid if c.isalnum() or c == "-")}"])'
    return Html(
        f"<style>{scope} input, {scope} textarea {{ -webkit-text-security: disc; text-security: disc; }}</style>"
    )


class LoginPanel:
    """The *Presenter login* folder of one tab: a masked token field, a button and a status line."""

    def __init__(self, gui: TabGui, on_login: Callable[[Any], None]) -> None:
        with gui.add_folder("Presenter login", expand_by_default=False):
            self.status = gui.add_markdown(
                Markdown(say(Lang.EN, T("Students: you watch the presenter here, or work on your own copy.")))
            )
            self.token = gui.add_text(
                "Presenter token",
                "",
                hint="Shown as dots and cleared as soon as it is read; not for the projector. Enter logs in",
                multiline=True,
            )
            self.mask = gui.add_html(mask_css(widget_uuid(self.token)))
            self.button = gui.add_button("Log in as presenter")
        self.button.on_click(on_login)
        self.token.on_update(lambda event: self._on_key(event, on_login))

    def _on_key(self, event: Any, on_login: Callable[[Any], None]) -> None:
        """A keystroke in the token field: Enter (a line break in the text) logs in, as the button does."""
        if getattr(event, "client", None) is not None and "\n" in str(self.token.value).replace("\r", "\n"):
            on_login(event)

    def take(self) -> str:
        """The typed token, then clear the field (it never stays on screen after an attempt)."""
        value = one_line(self.token.value)
        self.token.value = ""
        return str(value)

    def show(self, text: str) -> None:
        """The status line: ``text`` is an English Markdown template of the code (shown in the tab's language by its
        handle), never a user's words."""
        self.status.content = Markdown(text)
