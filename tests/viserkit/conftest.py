"""A bare viser server with tpm-viz's patches on it, or some of them skipped (``serve(skip={...})``), and raw tabs."""

from __future__ import annotations

import contextlib

import pytest

from tests.support.fixtures import app, connect, whole_steps
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.viserkit.adapter import Installed, install, new_server

__all__ = ["app", "connect", "serve", "tab", "whole_steps"]


@pytest.fixture
def serve():
    """``serve(skip=..., handshake=None, patched=True)`` -> ``(server, installed or None)``; stopped afterwards."""
    made: list = []

    def start(skip=frozenset(), handshake=None, patched=True):
        server = new_server(handshake=handshake, host="127.0.0.1", port=0, verbose=False)
        installed = install(server, skip=skip) if patched else None
        made.append((server, installed))
        return server, installed

    yield start
    for server, installed in reversed(made):
        if isinstance(installed, Installed):
            installed.remove()
        with contextlib.suppress(Exception):
            server.stop()


@pytest.fixture
def tab():
    """``tab(server)`` -> a raw websocket tab on ``server`` (a :class:`ProtocolClient`), once viser knows it."""
    opened: list = []

    def open_(server):
        before = set(server.get_clients())
        client = ProtocolClient(server.get_port())
        wait_for(lambda: set(server.get_clients()) - before, what="the tab to be known to viser")
        opened.append(client)
        return client

    yield open_
    for client in opened:
        with contextlib.suppress(Exception):
            client.close()
