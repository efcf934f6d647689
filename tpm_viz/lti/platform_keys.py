"""The platforms' public keys (their JWKS at ``key_set_url``): fetched bounded, cached, refetched for a new ``kid``.

A fetch reads at most :data:`MAX_JWKS_BYTES` within :data:`FETCH_SECONDS` and follows no redirect. A key set is kept
for :data:`CACHE_SECONDS`; a ``kid`` it does not list makes one refetch, at most once per
:data:`REFETCH_SECONDS` per key set (a platform that rolled its key over is seen at once; a flood of made-up
``kid`` s costs the platform one request per interval). A key set that cannot be fetched or read is a refusal
with the word *key* (:class:`~tpm_viz.lti.refusals.Refused`), never a traceback.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from typing import Any

import httpx
import jwt

from tpm_viz.core.words import Phrase
from tpm_viz.lti.refusals import Refused, Why

__all__ = ["CACHE_SECONDS", "FETCH_SECONDS", "MAX_JWKS_BYTES", "REFETCH_SECONDS", "KeySets", "read_limited"]

MAX_JWKS_BYTES = 256 << 10
FETCH_SECONDS = 5.0
CACHE_SECONDS = 3600.0
REFETCH_SECONDS = 10.0
MAX_KEYS = 50


def read_limited(response: httpx.Response, limit: int) -> bytes | None:
    """The body of a streamed response, or None if it is longer than ``limit`` bytes."""
    chunks, got = [], 0
    for chunk in response.iter_bytes():
        got += len(chunk)
        if got > limit:
            return None
        chunks.append(chunk)
    return b"".join(chunks)


def _unreadable(url: str, why: str) -> Refused:
    return Refused(
        Why.KEY,
        Phrase("cannot read the platform's key set at {url} ({why}): check key_set_url", url=url[:120], why=why),
    )


class KeySets:
    """The key sets of every platform, by URL (thread-safe; ``client``: an httpx client, ``clock``: seconds)."""

    def __init__(self, client: httpx.Client | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        self.client = client if client is not None else httpx.Client(timeout=FETCH_SECONDS, follow_redirects=False)
        self.clock = clock
        self.refetch_seconds = REFETCH_SECONDS
        """Shortest time between two fetches of one key set for an unknown ``kid`` [s]."""
        self._lock = threading.Lock()
        self._sets: dict[str, tuple[float, dict[str, Any]]] = {}  # url -> (fetched at, kid -> public key)
        self.fetches = 0
        """Key sets fetched so far (tests count refetches)."""

    def key(self, url: str, kid: str) -> Any:
        """The public key ``kid`` of the key set at ``url`` (refused with *key* if it is not there)."""
        now = self.clock()
        with self._lock:
            cached = self._sets.get(url)
        fresh = cached is not None and now - cached[0] < CACHE_SECONDS
        if fresh and cached is not None and kid in cached[1]:
            return cached[1][kid]
        if cached is None or not fresh or now - cached[0] >= self.refetch_seconds:
            keys = self._fetch(url)
            with self._lock:
                self._sets[url] = (self.clock(), keys)
            if kid in keys:
                return keys[kid]
        raise Refused(
            Why.KEY,
            Phrase(
                "the launch is signed with a key the platform's key set does not list (key {kid}): check key_set_url",
                kid=kid[:80],
            ),
        )

    def _fetch(self, url: str) -> dict[str, Any]:
        self.fetches += 1
        try:
            with self.client.stream("GET", url, timeout=FETCH_SECONDS, headers={"Accept": "application/json"}) as r:
                if r.status_code != 200:
                    raise _unreadable(url, f"HTTP {r.status_code}")
                body = read_limited(r, MAX_JWKS_BYTES)
        except httpx.HTTPError as exc:
            raise _unreadable(url, type(exc).__name__) from None
        if body is None:
            raise _unreadable(url, f"larger than {MAX_JWKS_BYTES >> 10} KiB")
        try:
            data = json.loads(body)
        except (ValueError, RecursionError):
            raise _unreadable(url, "not JSON") from None
        found = data.get("keys") if isinstance(data, dict) else None
        if not isinstance(found, list):
            raise _unreadable(url, "no keys list")
        keys: dict[str, Any] = {}
        for jwk in found[:MAX_KEYS]:
            if not isinstance(jwk, dict) or jwk.get("kty") != "RSA" or not isinstance(jwk.get("kid"), str):
                continue
            if jwk.get("use", "sig") != "sig" or jwk.get("alg", "RS256") != "RS256":
                continue
            try:
                keys[jwk["kid"]] = jwt.PyJWK(jwk, algorithm="RS256").key
            except (jwt.PyJWKError, ValueError, TypeError):
                continue
        return keys
