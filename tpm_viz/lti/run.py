"""``tpm-viz serve --lti CONFIG.toml``: the LTI tool beside the app, in the same process (:class:`LtiPlug`).

Made before the app starts (:class:`LtiPlug`: the file, the key and the LTI port are checked first, so a mistake
exits with one line and no app), started once the app serves (:meth:`LtiPlug.start`: the store's LTI records,
the grade sender, the endpoints) and stopped with it. On start it prints, one line each, exactly what a lecturer
types into the LMS::

    LTI login URL: <url>
    LTI launch URL: <url>
    LTI JWKS URL: <url>
    LTI deep linking URL: <url>
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from tpm_viz.app.demos import Demo
from tpm_viz.classroom.launches import Tickets
from tpm_viz.classroom.network import Network
from tpm_viz.core.errors import InputError
from tpm_viz.lti.config import Config, read_config
from tpm_viz.lti.deeplinking import Catalogue, lessons_catalogue
from tpm_viz.lti.grades import GradeSender
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.launches import connect_browsers
from tpm_viz.lti.ledger import Ledger
from tpm_viz.lti.service import LtiServer, Tool, Urls, build_asgi

__all__ = ["LtiPlug", "announce"]


def announce(urls: Urls) -> list[str]:
    """The four lines printed on start."""
    return [
        f"LTI login URL: {urls.login}",
        f"LTI launch URL: {urls.launch}",
        f"LTI JWKS URL: {urls.jwks}",
        f"LTI deep linking URL: {urls.deeplink}",
    ]


class LtiPlug:
    """The LTI tool of one ``serve``: ``config_path``, the app's ``host``, its ``lessons`` (the picker's), the
    trusted proxies (``network``) and the exercises' catalogue once there is one."""

    def __init__(
        self,
        config_path: str | Path,
        host: str,
        lessons: Sequence[Demo],
        network: Network | None = None,
        exercises: Catalogue | None = None,
    ) -> None:
        self.config: Config = read_config(config_path)
        self.key = ToolKey.read(self.config.private_key)
        self.host = host
        self.network = network if network is not None else Network()
        self.catalogue = lessons_catalogue(lessons, exercises)
        self.tickets = Tickets()
        self.server = LtiServer(host, self.config.port)
        self.grades: GradeSender | None = None
        self.tool: Tool | None = None
        self.ledger: Ledger | None = None

    def start(self, app_url: str, store: Path | None) -> None:
        """Serve the endpoints and send grades; print the four URLs."""
        if store is None:
            raise InputError("the LTI tool keeps its records in the session store, and none could be opened")
        self.ledger = Ledger(store)
        connect_browsers(self.tickets, self.ledger)
        shown = "127.0.0.1" if self.host in ("0.0.0.0", "::", "") else self.host
        host = f"[{shown}]" if ":" in shown else shown
        urls = Urls(self.config.url or f"http://{host}:{self.server.port}", self.config.app_url or app_url)
        cookie = None if self.config.state_cookie is None else self.config.state_cookie.value == "required"
        self.tool = Tool(
            self.config, self.key, self.ledger, self.tickets, self.catalogue, urls, self.network,
            cookie_required=cookie,
        )  # fmt: skip
        self.grades = GradeSender(self.ledger, self.config, self.key, self.catalogue)
        self.grades.start()
        self.server.start(build_asgi(self.tool))
        for line in announce(urls):
            print(line, flush=True)
        if not urls.secure:
            print(
                "warning: the LTI URLs are plain http: an LMS in production needs https (a reverse proxy; "
                "docs/lti.md), and the login's cookie is then checked only when the browser sends it",
                file=sys.stderr,
                flush=True,
            )

    def stop(self) -> None:
        self.server.stop()
        if self.grades is not None:
            self.grades.stop()
        if self.ledger is not None:
            self.ledger.close()
