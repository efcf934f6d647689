"""A reverse proxy on loopback, as nginx or Caddy on the lecturer's laptop: it listens on ``127.0.0.1:<port>``,
connects to the app from 127.0.0.1, and adds ``X-Forwarded-For: <the client's address>`` (or ``Forwarded:
for=...``) to the head of each HTTP request (the websocket handshake included), then pipes bytes both ways.

Clients may bind another loopback address (127.0.0.2, ...) to be "another machine". Runs its own asyncio loop in a
daemon thread; :meth:`ForwardingProxy.close` stops it. Bounded: at most 200 connections, 64 KiB of request head.
"""

from __future__ import annotations

import asyncio

from tests.support.proxy import MAX_CONNECTIONS, LoopbackProxy, splice

__all__ = ["ForwardingProxy"]

MAX_HEAD = 65_536


class ForwardingProxy(LoopbackProxy):
    """``127.0.0.1:<port>`` -> ``127.0.0.1:<target>``, adding ``header: <client address>`` to each request head
    (``style``: ``"xff"`` for X-Forwarded-For, ``"forwarded"`` for RFC 7239 Forwarded)."""

    def __init__(self, target: int, style: str = "xff") -> None:
        self.style = style
        self._count = 0
        super().__init__(target, "forwarding-proxy")

    def _header(self, client: str) -> bytes:
        if self.style == "forwarded":
            node = f'"[{client}]"' if ":" in client else client
            return f"Forwarded: for={node};proto=http\r\n".encode()
        return f"X-Forwarded-For: {client}\r\n".encode()

    async def _handle(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        if self._count >= MAX_CONNECTIONS:
            writer.close()
            return
        self._count += 1
        client = writer.get_extra_info("peername")[0]
        up_writer = None
        try:
            head = await reader.readuntil(b"\r\n\r\n")
            if len(head) > MAX_HEAD:
                return
            up_reader, up_writer = await asyncio.open_connection("127.0.0.1", self.target, local_addr=("127.0.0.1", 0))
            up_writer.write(head[:-2] + self._header(client) + b"\r\n")
            await splice(reader, writer, up_reader, up_writer)
        except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, ConnectionError, OSError):
            pass
        finally:
            self._count -= 1
            writer.close()
            if up_writer is not None:
                up_writer.close()
