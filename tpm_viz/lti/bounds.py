"""The LTI service's bounds: request bodies (:class:`BoundedBodies`, an ASGI middleware) and requests per client
address (:class:`Rate`), with the client's address read through a trusted reverse proxy as the app reads it
(:func:`tpm_viz.classroom.network.client_address`)."""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Awaitable, Callable, MutableMapping
from typing import Any

from starlette.requests import Request

from tpm_viz.classroom.network import Network, client_address

__all__ = ["MAX_BODY_BYTES", "BoundedBodies", "Rate", "address_of"]

MAX_BODY_BYTES = 64 << 10
"""Largest request body [bytes]: a launch's id_token is a few kB (a large Canvas one ~20 kB)."""
Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]


def address_of(request: Request, network: Network) -> str:
    """The client's address of ``request`` (through a trusted proxy's ``X-Forwarded-For`` / ``Forwarded``)."""
    peer = request.client.host if request.client is not None else "?"
    return client_address(
        peer, request.headers.getlist("x-forwarded-for"), request.headers.getlist("forwarded"), network
    )


class BoundedBodies:
    """Reads a request's body (at most ``limit`` bytes, else a 413 answer from ``too_large``) before the app."""

    def __init__(self, app: Any, too_large: Callable[[Scope], Any], limit: int = MAX_BODY_BYTES) -> None:
        self.app, self.too_large, self.limit = app, too_large, limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope.get("headers") or []).get(b"content-length", b"0")
        if not declared.isdigit() or int(declared) > self.limit:
            await self.too_large(scope)(scope, receive, send)
            return
        chunks, got, more = [], 0, True
        while more:
            message = await receive()
            if message["type"] != "http.request":
                return  # the client went away
            chunks.append(message.get("body", b""))
            got += len(chunks[-1])
            more = bool(message.get("more_body"))
            if got > self.limit:
                await self.too_large(scope)(scope, receive, send)
                return
        body, sent = b"".join(chunks), False

        async def replay() -> Message:
            nonlocal sent
            if not sent:
                sent = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        await self.app(scope, replay, send)


class Rate:
    """At most ``burst`` requests per address, refilled at ``per_minute`` (a token bucket; thread-safe; bounded
    to ``addresses`` addresses, the least recently seen forgotten first)."""

    def __init__(
        self,
        per_minute: float = 60.0,
        burst: float = 30.0,
        addresses: int = 10_000,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.per_minute, self.burst, self.addresses, self.clock = per_minute, burst, addresses, clock
        self._lock = threading.Lock()
        self._buckets: OrderedDict[str, tuple[float, float]] = OrderedDict()  # address -> (tokens, at)

    def allow(self, address: str) -> bool:
        """Whether one more request from ``address`` may go now."""
        with self._lock:
            now = self.clock()
            tokens, at = self._buckets.pop(address, (self.burst, now))
            tokens = min(self.burst, tokens + (now - at) * self.per_minute / 60.0)
            ok = tokens >= 1.0
            self._buckets[address] = (tokens - 1.0 if ok else tokens, now)
            while len(self._buckets) > self.addresses:
                self._buckets.popitem(last=False)
            return ok
