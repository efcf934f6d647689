"""Share links: one mechanism's state (parameters, pose, load, trajectory, player time, view options, language) as
a short, versioned, checksummed token for a URL, written and read without viser.

A token is ``<version>.<payload>.<checksum>``: the payload is the state in the session file's form
(:func:`tpm_viz.classroom.sessionfile.encode_saved`), as compact JSON, deflated and base64url-encoded; the checksum is
the first 16 hex digits of its SHA-256. Reading (:func:`decode_link`) refuses in one line a token of another version, a
damaged one (bad characters, a checksum that does not match, a payload that does not inflate within
:data:`MAX_STATE_BYTES`) and a forged one (every field goes through the session file's checks:
:func:`~tpm_viz.classroom.sessionfile.decode_saved` builds ``Params``, the pose, the load and the trajectory with the
library's own validation). No secret is involved: any tpm-viz server reads any link.

An uploaded trajectory is kept by content hash whenever there is a store (``put_blob``: the classroom store's
``put_blob(data) -> sha256 hex``, when the class is served): the token names only the digest, so that the link stays
short enough for a QR code (a 400-row CSV made a 2,690-character link, too long for one). Without a store the upload
goes in the token, up to :data:`MAX_TOKEN_CHARS`. A server that does not hold the digest (``get_blob(digest) -> bytes |
None``) refuses the link with one line that says to open it on the server that made it or to upload the CSV there,
quoting nothing the link carries.

A link is ``http://HOST:PORT/?share=TOKEN`` (:func:`share_url`). The page request is the only request that sees the
query (viser's websocket URL has none): :class:`PendingLinks` keeps its token under a random nonce for
:data:`PENDING_SECONDS`, the page's response puts the nonce in a cookie, and the tab's websocket handshake brings it
back (:mod:`tpm_viz.ui.classroom`, :mod:`tpm_viz.ui.share`). Bounded: :data:`MAX_PENDING` tokens in all,
:data:`MAX_PENDING_PER_ADDRESS` per client address, each read once.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import re
import secrets
import threading
import time
import zlib
from collections import OrderedDict
from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qs

import numpy as np

from tpm_viz.app.readouts import reason
from tpm_viz.classroom.sessionfile import Saved, decode_saved, encode_saved
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase, T

__all__ = [
    "LINK_VERSION",
    "MAX_PENDING",
    "MAX_PENDING_PER_ADDRESS",
    "MAX_STATE_BYTES",
    "MAX_TOKEN_CHARS",
    "PENDING_SECONDS",
    "SHARE_PARAMETER",
    "PendingLinks",
    "decode_link",
    "encode_link",
    "share_url",
    "token_of_query",
]

LINK_VERSION = 1
"""Version of the token's layout and of its state's schema."""
MAX_TOKEN_CHARS = 4000
"""Longest token put in a link [characters] (browsers and proxies cut long URLs); a larger upload is stored."""
MAX_STATE_BYTES = 8 * 2**20
"""Most bytes a token's (or a stored upload's) JSON may inflate to."""
_TOKEN = re.compile(r"^(\d{1,3})\.([A-Za-z0-9_-]{1,200000})\.([0-9a-f]{16})$")
_DIGEST = re.compile(r"^[0-9a-f]{64}$")

PutBlob = Callable[[bytes], str]
GetBlob = Callable[[str], "bytes | None"]


def _checksum(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


def _pack(raw: dict[str, Any]) -> str:
    payload = zlib.compress(json.dumps(raw, sort_keys=True, separators=(",", ":"), allow_nan=False).encode(), 9)
    body = base64.urlsafe_b64encode(payload).decode("ascii").rstrip("=")
    return f"{LINK_VERSION}.{body}.{_checksum(payload)}"


def encode_link(saved: Saved, put_blob: PutBlob | None = None) -> str:
    """The token of ``saved``; an uploaded trajectory goes to ``put_blob`` when there is one (the token names its
    digest), else in the token (refused in one line when that makes it longer than :data:`MAX_TOKEN_CHARS`)."""
    raw = encode_saved(saved)
    trajectory = raw.get("trajectory")
    if not isinstance(trajectory, dict) or trajectory.get("kind") != "csv":
        return _pack(raw)
    if put_blob is None:
        token = _pack(raw)
        if len(token) > MAX_TOKEN_CHARS:
            raise InputError(T("the uploaded trajectory is too large for a link and this server cannot store it"))
        return token
    data = json.dumps(trajectory, sort_keys=True, separators=(",", ":"), allow_nan=False).encode()
    raw["trajectory"] = {"stored": put_blob(data)}
    return _pack(raw)


def _inflate(payload: bytes) -> bytes:
    inflater = zlib.decompressobj()
    try:
        data = inflater.decompress(payload, MAX_STATE_BYTES + 1)
    except zlib.error:
        raise InputError(T("the share link is damaged: copy it again in full")) from None
    if len(data) > MAX_STATE_BYTES or inflater.unconsumed_tail:
        raise InputError(T("the share link is damaged: copy it again in full"))
    return data


def _json(data: bytes) -> Any:
    try:
        return json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise InputError(T("the share link is damaged: copy it again in full")) from None


def decode_link(token: str, get_blob: GetBlob | None = None) -> Saved:
    """The state a token carries, every field checked; one-line :class:`~tpm_viz.core.errors.InputError` otherwise."""
    match = _TOKEN.match(str(token).strip())
    if match is None:
        raise InputError(T("the share link is damaged: copy it again in full"))
    version, body, checksum = match.groups()
    if int(version) != LINK_VERSION:
        raise InputError(
            Phrase(
                "this share link is of version {got}; this tpm-viz reads version {version}: ask for a new link",
                got=int(version),
                version=LINK_VERSION,
            )
        )
    try:
        payload = base64.urlsafe_b64decode(body + "=" * (-len(body) % 4))
    except (binascii.Error, ValueError):
        raise InputError(T("the share link is damaged: copy it again in full")) from None
    if _checksum(payload) != checksum:
        raise InputError(T("the share link is damaged: copy it again in full"))
    raw = _json(_inflate(payload))
    if not isinstance(raw, dict):
        raise InputError(T("the share link is damaged: copy it again in full"))
    trajectory = raw.get("trajectory")
    if isinstance(trajectory, dict) and "stored" in trajectory:
        raw["trajectory"] = _stored(trajectory, get_blob)
    try:
        saved = decode_saved(raw)
    except InputError as exc:
        raise InputError(
            Phrase("the share link's state is refused ({why}): ask for a new link", why=reason(exc))
        ) from None
    state = saved.state
    p, d = np.asarray(state.pose.p, dtype=float), np.asarray(state.pose.d, dtype=float)
    c = p - d + state.params.offset  # leg closure, eq. (27): c_i² + p_j² = l_a²
    gap = np.abs(c**2 + p[::-1] ** 2 - state.params.l_a**2)
    if not np.all(gap <= 1e-9 * state.params.l_a**2):
        raise InputError(T("the share link's state is refused (its pose does not close the legs): ask for a new link"))
    return saved


def _stored(ref: dict[str, Any], get_blob: GetBlob | None) -> Any:
    """The uploaded trajectory a link names by its digest, from this server's store."""
    digest = ref.get("stored")
    if not isinstance(digest, str) or not _DIGEST.match(digest):
        raise InputError(T("the share link is damaged: copy it again in full"))
    data = None if get_blob is None else get_blob(digest)
    if data is None:  # nothing of the link is quoted: its text is anyone's
        raise InputError(
            T(
                "this link's uploaded trajectory is kept on the server that made the link: open the link there, or "
                "upload the CSV here"
            )
        )
    if hashlib.sha256(data).hexdigest() != digest or len(data) > MAX_STATE_BYTES:
        raise InputError(T("the share link's stored trajectory is damaged on this server: upload the CSV again"))
    return _json(data)


# -- links in URLs ----------------------------------------------------------------------------------------------------
SHARE_PARAMETER = "share"
"""The query parameter of a share link (``/?share=TOKEN``)."""
PENDING_SECONDS = 120.0
"""How long a page's share token waits for that page's websocket [s]."""
MAX_PENDING = 512
"""Most share tokens waiting at once (the oldest goes first)."""
MAX_PENDING_PER_ADDRESS = 8
"""Most share tokens waiting for one client address (its oldest goes first: one student cannot evict the class's)."""
_MAX_QUERY_CHARS = MAX_TOKEN_CHARS + 64  # a longer value is kept cut: it then reads as damaged, never as another link


def share_url(origin: str, token: str) -> str:
    """The link of ``token`` on the server whose pages are at ``origin`` (``http://host:port``)."""
    return f"{origin.rstrip('/')}/?{SHARE_PARAMETER}={token}"


def token_of_query(query: str) -> str | None:
    """The share token a page request's query carries (None: no ``share`` parameter; the value as given, cut to a
    bounded length, even when damaged: the tab then says the link was refused)."""
    try:
        values = parse_qs(str(query)[: 2 * _MAX_QUERY_CHARS], keep_blank_values=True, max_num_fields=32)
    except ValueError:  # too many fields: not a link this app made
        return ""
    found = values.get(SHARE_PARAMETER)
    return None if not found else found[0][:_MAX_QUERY_CHARS]


class PendingLinks:
    """Share tokens of page requests, each waiting under a random nonce for its tab's websocket (:meth:`put`,
    :meth:`take`); thread-safe, bounded in number, per client address and in time (``clock``: seconds)."""

    def __init__(
        self,
        seconds: float = PENDING_SECONDS,
        most: int = MAX_PENDING,
        per_address: int = MAX_PENDING_PER_ADDRESS,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.seconds, self.most, self.per_address, self.clock = seconds, most, per_address, clock
        self._lock = threading.Lock()
        self._items: OrderedDict[str, tuple[float, str, str]] = OrderedDict()  # nonce -> (expiry, address, token)

    def __len__(self) -> int:
        with self._lock:
            self._expire(self.clock())
            return len(self._items)

    def _expire(self, now: float) -> None:
        while self._items and next(iter(self._items.values()))[0] <= now:
            self._items.popitem(last=False)

    def put(self, token: str, address: str) -> str:
        """Keep ``token`` (cut to a bounded length) for a page served to ``address``; its nonce (for the cookie)."""
        nonce = secrets.token_urlsafe(16)
        with self._lock:
            now = self.clock()
            self._expire(now)
            mine = [k for k, (_, a, _) in self._items.items() if a == address]
            for old in mine[: max(0, len(mine) - self.per_address + 1)]:
                del self._items[old]
            while len(self._items) >= self.most:
                self._items.popitem(last=False)
            self._items[nonce] = (now + self.seconds, str(address), str(token)[:_MAX_QUERY_CHARS])
        return nonce

    def take(self, nonce: str | None) -> str | None:
        """The token kept under ``nonce``, once (None: unknown, already taken or expired)."""
        if not nonce:
            return None
        with self._lock:
            self._expire(self.clock())
            item = self._items.pop(str(nonce), None)
        return None if item is None else item[2]
