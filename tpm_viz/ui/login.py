"""The *Presenter login* folder of one tab (presenter mode: :mod:`tpm_viz.classroom.access`).

viser 1.1.1 has no password input (its text field is a plain Mantine ``TextInput`` without an ``id`` or a
``type``), so the token field is masked by a style rule in the page (``-webkit-text-security: disc``, found by the
field's label: Chromium, Safari and Firefox 121+ draw dots) *and* cleared by the server as soon as it is read; the
hint says so. On a browser that ignores the rule the typed characters are visible until the button is pressed:
the lecturer can also present from the serving machine itself (classroom mode), where no token is typed at all.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.viserkit.core import widget_uuid
from tpm_viz.words import Lang, T, say

__all__ = ["LoginPanel", "mask_css"]


def mask_css(uuid: str) -> str:
    """A style rule that draws the characters of the text input labelled by ``uuid`` as dots."""
    scope = f'div:has(> div > p > label[for="{uuid}"])'
    return f"<style>{scope} input {{ -webkit-text-security: disc; text-security: disc; }}</style>"


class LoginPanel:
    """The *Presenter login* folder of one tab: a masked token field, a button and a status line."""

    def __init__(self, gui: viser.GuiApi, on_login: Callable[[Any], None]) -> None:
        with gui.add_folder("Presenter login", expand_by_default=False):
            self.status = gui.add_markdown(
                say(Lang.EN, T("Students: you watch the presenter here, or work on your own copy."))
            )
            self.token = gui.add_text(
                "Presenter token", "", hint="Shown as dots and cleared as soon as it is read; not for the projector"
            )
            self.mask = gui.add_html(mask_css(widget_uuid(self.token)))
            self.button = gui.add_button("Log in as presenter")
        self.button.on_click(on_login)

    def take(self) -> str:
        """The typed token, then clear the field (it never stays on screen after an attempt)."""
        value = self.token.value
        self.token.value = ""
        return value

    def show(self, text: str) -> None:
        self.status.content = text
