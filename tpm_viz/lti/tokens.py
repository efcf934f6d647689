"""AGS access tokens (IMS Security Framework §4.1): client credentials with a JWT client assertion (RFC 7523).

:meth:`Tokens.get` posts to the platform's ``auth_token_url`` ``grant_type=client_credentials``,
``client_assertion_type=urn:ietf:params:oauth:client-assertion-type:jwt-bearer``, the ``scope`` asked and a
``client_assertion`` signed RS256 with the tool's key: ``iss`` = ``sub`` = the client_id, ``aud`` = the token
URL, ``iat``, ``exp`` (:data:`ASSERTION_SECONDS` later) and a fresh ``jti``. The token is kept until
:data:`MARGIN_SECONDS` before it expires (:meth:`Tokens.forget` drops it when the platform answers 401). A platform
that cannot be reached, is slow or answers 5xx is a transient :class:`TokenError` (the score is retried); any other
answer is a permanent one.
"""

from __future__ import annotations

import json
import secrets
import threading
import time
from collections.abc import Callable, Sequence

import httpx

from tpm_viz.lti.config import Platform
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.platform_keys import read_limited

__all__ = ["ASSERTION_SECONDS", "MARGIN_SECONDS", "SCORE_SCOPE", "TokenError", "Tokens", "transient"]

SCORE_SCOPE = "https://purl.imsglobal.org/spec/lti-ags/scope/score"
ASSERTION_SECONDS = 300
MARGIN_SECONDS = 30.0
MAX_ANSWER_BYTES = 64 << 10
ASSERTION_TYPE = "urn:ietf:params:oauth:client-assertion-type:jwt-bearer"


def transient(status: int) -> bool:
    """Whether an HTTP status is worth trying again later (timeout, too many requests, the server's fault)."""
    return status in (408, 425, 429) or status >= 500


class TokenError(Exception):
    """No token: ``transient`` (try again later) or not, with a one-line ``why``."""

    def __init__(self, why: str, transient: bool) -> None:
        super().__init__(why)
        self.why, self.transient = why, transient


class Tokens:
    """Access tokens per platform and scope set (thread-safe; ``clock``: seconds of the wall clock)."""

    def __init__(
        self, key: ToolKey, client: httpx.Client, clock: Callable[[], float] = time.time, timeout: float = 10.0
    ) -> None:
        self.key, self.client, self.clock, self.timeout = key, client, clock, timeout
        self._lock = threading.Lock()
        self._tokens: dict[tuple[str, str, str], tuple[str, float]] = {}
        self.requests = 0
        """Tokens asked for so far (tests check the cache)."""

    def assertion(self, platform: Platform) -> str:
        """A fresh client assertion for ``platform``'s token URL."""
        now = int(self.clock())
        claims = {
            "iss": platform.client_id,
            "sub": platform.client_id,
            "aud": platform.auth_token_url,
            "iat": now,
            "exp": now + ASSERTION_SECONDS,
            "jti": secrets.token_hex(16),
        }
        return self.key.sign(claims)

    def get(self, platform: Platform, scopes: Sequence[str]) -> str:
        """A token of ``scopes`` for ``platform`` (the cached one while it is good)."""
        scope = " ".join(sorted(set(scopes)))
        slot = (platform.issuer, platform.client_id, scope)
        with self._lock:
            found = self._tokens.get(slot)
        if found is not None and self.clock() < found[1]:
            return found[0]
        token, seconds = self._ask(platform, scope)
        with self._lock:
            self._tokens[slot] = (token, self.clock() + max(0.0, seconds - MARGIN_SECONDS))
        return token

    def forget(self, platform: Platform) -> None:
        """Drop ``platform``'s tokens (it answered 401: expired or revoked)."""
        with self._lock:
            for slot in [s for s in self._tokens if s[:2] == (platform.issuer, platform.client_id)]:
                del self._tokens[slot]

    def _ask(self, platform: Platform, scope: str) -> tuple[str, float]:
        self.requests += 1
        form = {
            "grant_type": "client_credentials",
            "client_assertion_type": ASSERTION_TYPE,
            "client_assertion": self.assertion(platform),
            "scope": scope,
        }
        try:
            with self.client.stream(
                "POST",
                platform.auth_token_url,
                data=form,
                timeout=self.timeout,
                headers={"Accept": "application/json"},
            ) as response:
                status = response.status_code
                body = read_limited(response, MAX_ANSWER_BYTES)
        except httpx.HTTPError as exc:
            raise TokenError(f"token endpoint unreachable ({type(exc).__name__})", True) from None
        if status != 200:
            raise TokenError(f"token endpoint answered HTTP {status}", transient(status))
        try:
            data = json.loads(body or b"")
            token, seconds = data["access_token"], float(data.get("expires_in", 3600))
        except (ValueError, KeyError, TypeError, RecursionError):
            raise TokenError("token endpoint answered no access_token", False) from None
        if not isinstance(token, str) or not token or not 0 < seconds < 1e7:
            raise TokenError("token endpoint answered no usable access_token", False)
        return token, seconds
