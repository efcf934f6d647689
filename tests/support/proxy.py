"""A small TCP proxy on 127.0.0.1 for network-drop tests: a browser talks to the app through it, and
:meth:`TcpProxy.drop` cuts every connection and, for a while, refuses new ones (a wifi blip, a closed laptop lid: the
other end answers "no") or black-holes them (a wifi that lost its way out: accepted, never answered).
:attr:`TcpProxy.arrivals` times every connection attempt (``time.monotonic()``), drops included.

The proxy runs its own asyncio loop in a daemon thread; :meth:`TcpProxy.close` stops it. Bounded: at most
:data:`MAX_CONNECTIONS` at once. :class:`LoopbackProxy` and :func:`splice` are that skeleton, shared with
:mod:`tests.support.forwarding_proxy`.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
import time

__all__ = ["LoopbackProxy", "TcpProxy", "splice"]

MAX_CONNECTIONS = 200


async def _pipe(src: asyncio.StreamReader, dst: asyncio.StreamWriter) -> None:
    try:
        while data := await src.read(65536):
            dst.write(data)
            await dst.drain()
    except (ConnectionError, OSError):
        pass
    finally:
        dst.close()


async def splice(
    reader: asyncio.StreamReader,
    writer: asyncio.StreamWriter,
    up_reader: asyncio.StreamReader,
    up_writer: asyncio.StreamWriter,
) -> None:
    """Pipe bytes both ways until either side ends; each direction closes its destination when it stops."""
    await asyncio.gather(_pipe(reader, up_writer), _pipe(up_reader, writer), return_exceptions=True)


class LoopbackProxy:
    """A server on ``127.0.0.1:<port>`` (for ``127.0.0.1:<target>``) in its own asyncio loop and daemon thread.

    Subclasses implement :meth:`_handle` (one client connection) and set their own state before calling this
    ``__init__`` (it starts serving). :meth:`close` cuts the connections in ``_writers`` and stops the thread."""

    def __init__(self, target: int, name: str) -> None:
        self.target = target
        self.port = 0
        self._writers: set[asyncio.StreamWriter] = set()
        self._loop = asyncio.new_event_loop()
        self._ready = threading.Event()
        self._server: asyncio.base_events.Server | None = None
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()
        if not self._ready.wait(10.0):
            raise RuntimeError("the proxy did not start")

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        self._server = self._loop.run_until_complete(asyncio.start_server(self._handle, "127.0.0.1", 0))
        self.port = self._server.sockets[0].getsockname()[1]
        self._ready.set()
        self._loop.run_forever()

    async def _handle(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        raise NotImplementedError

    def close(self) -> None:
        """Stop the proxy and its thread."""

        async def stop() -> None:
            if self._server is not None:
                self._server.close()
            for w in list(self._writers):
                with contextlib.suppress(Exception):
                    w.transport.abort()
            tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
            for task in tasks:  # no connection handler is left pending (it would be reported when collected)
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            self._loop.stop()

        with contextlib.suppress(RuntimeError):  # the loop has already stopped
            asyncio.run_coroutine_threadsafe(stop(), self._loop)
        self._thread.join(timeout=5.0)


class TcpProxy(LoopbackProxy):
    """``127.0.0.1:<port>`` -> ``127.0.0.1:<target>``; :meth:`drop` is the network going down."""

    def __init__(self, target: int) -> None:
        self.accepted = 0
        self.arrivals: list[float] = []
        """When each connection attempt arrived (``time.monotonic()``), refused and black-holed ones included."""
        self._down_until = 0.0
        self._black_hole = False
        self._held: set[asyncio.StreamWriter] = set()
        super().__init__(target, "tcp-proxy")

    async def _handle(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        now = time.monotonic()
        if len(self.arrivals) < 100_000:
            self.arrivals.append(now)
        if now < self._down_until and self._black_hole and len(self._held) < MAX_CONNECTIONS:
            await self._hold(reader, writer)
            return
        if now < self._down_until or len(self._writers) >= MAX_CONNECTIONS:
            writer.close()  # the network is down
            return
        self.accepted += 1
        try:
            up_reader, up_writer = await asyncio.open_connection("127.0.0.1", self.target)
        except OSError:
            writer.close()
            return
        self._writers |= {writer, up_writer}
        await splice(reader, writer, up_reader, up_writer)
        self._writers -= {writer, up_writer}

    async def _hold(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        """A black-holed connection: whatever the client sends is swallowed, nothing ever comes back, until the
        client gives up (or the proxy closes)."""
        self._held.add(writer)
        self._writers.add(writer)
        try:
            while await reader.read(65536):
                pass
        except (ConnectionError, OSError):
            pass
        finally:
            self._held.discard(writer)
            self._writers.discard(writer)
            writer.close()

    def drop(self, seconds: float, black_hole: bool = False) -> None:
        """Cut every connection now (reset, no closing handshake) and, for ``seconds``, refuse new ones (closed at
        once) or, with ``black_hole``, accept and never answer them (they hang until the client gives up)."""

        def cut() -> None:
            self._down_until = time.monotonic() + seconds
            self._black_hole = black_hole
            for w in list(self._writers):
                transport = w.transport
                with contextlib.suppress(Exception):
                    transport.abort()
            self._writers.clear()

        self._loop.call_soon_threadsafe(cut)

    def restore(self) -> None:
        """The network is back now (a drop ends early); black-holed connections stay silent until their client
        gives up."""

        def up() -> None:
            self._down_until = 0.0

        self._loop.call_soon_threadsafe(up)
