"""Fixtures shared by the UI and system tests (imported by their ``conftest.py``).

- ``app``: a :class:`tpm_viz.ui.app.TpmApp` on ``127.0.0.1``, port 0 (a free one); stopped afterwards.
- ``connect``: ``connect()`` opens a :class:`~tests.support.protocol.ProtocolClient` (viser's websocket protocol
  from Python, no browser) and returns ``(client, view)`` once the app built the tab's view.
- ``browser``: a Playwright Chromium context (Debian's ``/usr/bin/chromium``, fresh profile); the test is skipped
  when Chromium or Playwright is missing.
- ``whole_steps`` (for the whole run, automatic): a met :func:`~tests.support.protocol.wait_for` returns once the
  locked step that wrote the awaited value is over. The app writes a step's values one after another under the hub's
  lock (a picked cell, then its description; a commit, then each tab's widgets); a test reads them without that
  lock, so on a busy machine it could see the first value and not yet the next.
"""

from __future__ import annotations

import os
import tempfile
import weakref

import pytest

from tests.support import protocol
from tests.support.browser import CHROMIUM, CHROMIUM_ARGS
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.classroom.session import Hub
from tpm_viz.ui.app import TpmApp, build_server

__all__ = ["app", "browser", "connect", "open_tab", "whole_steps"]

STEP_BOUND = 30.0
"""Seconds a met wait waits at most for a hub's current step (a bound, not a speed)."""


@pytest.fixture(scope="session", autouse=True)
def whole_steps():
    """Every :class:`Hub` made in this run is known (weakly); a met ``wait_for`` takes and gives back its lock."""
    hubs: weakref.WeakSet[Hub] = weakref.WeakSet()
    made = Hub.__init__

    def tracked(self, *args, **kwargs) -> None:
        made(self, *args, **kwargs)
        hubs.add(self)

    def after_wait() -> None:
        for hub in list(hubs):
            if hub.lock.acquire(timeout=STEP_BOUND):
                hub.lock.release()

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Hub, "__init__", tracked)
        protocol.AFTER_WAITS.append(after_wait)
        try:
            yield
        finally:
            protocol.AFTER_WAITS.remove(after_wait)


@pytest.fixture
def app():
    """The app on a free loopback port."""
    server = build_server("127.0.0.1", 0)
    application = TpmApp(server)
    yield application
    application.stop()


def open_tab(app, opened: list[ProtocolClient]):
    """Open a protocol client on ``app`` (appended to ``opened``); ``(client, view)`` once its first render is done
    and its connection fully handled (its key nonce, classroom part, guide and class line)."""
    before = set(app.views)
    client = ProtocolClient(app.port)
    opened.append(client)
    new = wait_for(lambda: set(app.views) - before, what="the app to build a view for the client")
    view = app.views[next(iter(new))]
    wait_for(lambda: view.session.readout is not None and view in app.arrived, what="the first render, and the rest")
    return client, view


@pytest.fixture
def connect(app):
    """``connect()`` opens a protocol client and returns ``(client, view)`` once the app built its view."""
    opened: list[ProtocolClient] = []
    yield lambda: open_tab(app, opened)
    for client in opened:  # one at a time: each tab's departure is processed before the next one leaves
        count = len(app.views)
        client.close()
        wait_for(lambda count=count: len(app.views) < count, what="the app to drop the closed tab")


@pytest.fixture
def browser():
    """A headless Chromium context with a fresh profile; skips when Chromium or Playwright is missing."""
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with tempfile.TemporaryDirectory() as profile, sync_api.sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            profile,
            executable_path=CHROMIUM,
            args=CHROMIUM_ARGS,
            headless=True,
            viewport={"width": 1400, "height": 860},
        )
        try:
            yield context
        finally:
            context.close()
