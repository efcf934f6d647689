"""The *Presenter login* folder of one tab (presenter mode: :mod:`tpm_viz.app.access`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import viser

__all__ = ["LoginPanel"]


class LoginPanel:
    """The *Presenter login* folder of one tab: a token field, a button and a status line."""

    def __init__(self, gui: viser.GuiApi, on_login: Callable[[Any], None]) -> None:
        with gui.add_folder("Presenter login", expand_by_default=False):
            self.status = gui.add_markdown("Students: you watch the presenter here, or work on your own copy.")
            self.token = gui.add_text("Presenter token", "", hint="Cleared as soon as it is read")
            self.button = gui.add_button("Log in as presenter")
        self.button.on_click(on_login)

    def take(self) -> str:
        """The typed token, then clear the field (it never stays on screen after an attempt)."""
        value = self.token.value
        self.token.value = ""
        return value

    def show(self, text: str) -> None:
        self.status.content = text
