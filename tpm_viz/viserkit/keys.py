"""The wire format of a key the page script (:mod:`.page`) sends: its path, the keys it sends, and the parser of a
request (:func:`key_request`)."""

from __future__ import annotations

from dataclasses import dataclass
from urllib.parse import parse_qs, urlsplit

__all__ = ["KEYS", "KEY_PATH", "NONCE_CHARS", "QUEUED", "KeyRequest", "key_request", "page_query"]

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


def page_query(path: str, route: str, names: tuple[str, str, str], kind: str) -> tuple[str, str, str] | None:
    """The three fields ``names`` of a page-script request for ``path`` (the first is the tab's nonce, checked), or
    None when the path is not ``route``. Raises ``ValueError`` (one line, ``malformed <kind>: ...``)."""
    try:
        parts = urlsplit(path)
    except ValueError as exc:
        raise ValueError(f"malformed {kind}") from exc
    if parts.path != route:
        return None
    query = parse_qs(parts.query, max_num_fields=4)
    nonce, second, third = (query.get(name, [""])[0] for name in names)
    if not 16 <= len(nonce) <= 64 or not set(nonce) <= NONCE_CHARS:
        raise ValueError(f"malformed {kind}: nonce")
    return nonce, second, third


def key_request(path: str) -> KeyRequest | None:
    """The key of a request for ``path`` (its query ``n``, ``k``, ``s``), or None when the path is not
    :data:`KEY_PATH`. Raises ``ValueError`` (one line) for a malformed one."""
    fields = page_query(path, KEY_PATH, ("n", "k", "s"), "key request")
    if fields is None:
        return None
    nonce, code, shift = fields
    if code not in KEYS:
        raise ValueError("malformed key request: key")
    return KeyRequest(nonce, code, shift == "1")
