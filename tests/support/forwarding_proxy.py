"""A reverse proxy on loopback, as nginx or Caddy on the lecturer's laptop: it listens on ``127.0.0.1:<port>``,
connects to the app from 127.0.0.1, and adds ``X-Forwarded-For: <the client's address>`` (or ``Forwarded:
for=...``) to the head of each HTTP request (the websocket handshake included), then pipes bytes both ways.

Clients may bind another loopback address (127.0.0.2, ...) to be "another machine". Runs its own asyncio loop in a
daemon thread; :meth:`ForwardingProxy.close` stops it. Bounded: at most 200 connections, 64 KiB of request head.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading

__all__ = ["ForwardingProxy"]

MAX_CONNECTIONS = 200
MAX_HEAD = 65_536


class ForwardingProxy:
    """``127.0.0.1:<port>`` -> ``127.0.0.1:<target>``, adding ``header: <client address>`` to each request head
    (``style``: ``"xff"`` for X-Forwarded-For, ``"forwarded"`` for RFC 7239 Forwarded)."""

    def __init__(self, target: int, style: str = "xff") -> None:
        self.target = target
        self.style = style
        self.port = 0
        self._count = 0
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._server: asyncio.base_events.Server | None = None
        self._thread = threading.Thread(target=self._run, name="forwarding-proxy", daemon=True)
        self._thread.start()
        if not self._ready.wait(10.0):
            raise RuntimeError("the proxy did not start")

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        self._server = self._loop.run_until_complete(asyncio.start_server(self._handle, "127.0.0.1", 0))
        self.port = self._server.sockets[0].getsockname()[1]
        self._ready.set()
        self._loop.run_forever()

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

            async def pipe(src: asyncio.StreamReader, dst: asyncio.StreamWriter) -> None:
                try:
                    while data := await src.read(65536):
                        dst.write(data)
                        await dst.drain()
                except (ConnectionError, OSError):
                    pass
                finally:
                    dst.close()

            await asyncio.gather(pipe(reader, up_writer), pipe(up_reader, writer), return_exceptions=True)
        except (asyncio.IncompleteReadError, asyncio.LimitOverrunError, ConnectionError, OSError):
            pass
        finally:
            self._count -= 1
            writer.close()
            if up_writer is not None:
                up_writer.close()

    def close(self) -> None:
        """Stop the proxy and its thread."""

        async def stop() -> None:
            if self._server is not None:
                self._server.close()
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            self._loop.stop()

        with contextlib.suppress(RuntimeError):
            asyncio.run_coroutine_threadsafe(stop(), self._loop)
        self._thread.join(timeout=5.0)
