"""The wire format of a key the page script (:mod:`.page`) sends: its path, the keys it sends, and the parser of a
request (:func:`key_request`)."""

from __future__ import annotations

from dataclasses import dataclass
from urllib.parse import parse_qs, urlsplit

__all__ = ["KEYS", "KEY_PATH", "NONCE_CHARS", "QUEUED", "KeyRequest", "key_request"]

KEY_PATH = "/tpm-viz/key"
"""The path the page script sends a key to (``GET``: websockets' HTTP server reads nothing else)."""

KEYS = (
    "ArrowLeft",
    "ArrowRight",
    "ArrowUp",
    "ArrowDown",
    "KeyQ",
    "KeyA",
    "KeyW",
    "KeyS",
)
"""The physical keys (``KeyboardEvent.code``: the same on every layout, Korean included) the script sends."""

QUEUED = 8
"""Keys the script keeps while one is on its way; more are dropped (a held key repeats ~30 times a second)."""

NONCE_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")
"""The characters of a tab's nonce (URL-safe base64)."""


@dataclass(frozen=True)
class KeyRequest:
    """One key the page sent: the tab's ``nonce``, the key's ``code`` (one of :data:`KEYS`), Shift held."""

    nonce: str
    code: str
    shift: bool


def key_request(path: str) -> KeyRequest | None:
    """The key of a request for ``path`` (its query ``n``, ``k``, ``s``), or None when the path is not
    :data:`KEY_PATH`. Raises ``ValueError`` (one line) for a malformed one."""
    try:
        parts = urlsplit(path)
    except ValueError as exc:
        raise ValueError("malformed key request") from exc
    if parts.path != KEY_PATH:
        return None
    query = parse_qs(parts.query, max_num_fields=4)
    nonce, code, shift = (query.get(name, [""])[0] for name in ("n", "k", "s"))
    if not 16 <= len(nonce) <= 64 or not set(nonce) <= NONCE_CHARS:
        raise ValueError("malformed key request: nonce")
    if code not in KEYS:
        raise ValueError("malformed key request: key")
    return KeyRequest(nonce, code, shift == "1")
