"""Share links: one mechanism's state (parameters, pose, load, trajectory, player time, view options, language) as
a short, versioned, checksummed token for a URL, written and read without viser.

A token is ``<version>.<payload>.<checksum>``: the payload is the state in the session file's form
(:func:`tpm_viz.app.sessions.encode_saved`), as compact JSON, deflated and base64url-encoded; the checksum is the
first 16 hex digits of its SHA-256. Reading (:func:`decode_link`) refuses in one line a token of another version,
a damaged one (bad characters, a checksum that does not match, a payload that does not inflate within
:data:`MAX_STATE_BYTES`) and a forged one (every field goes through the session file's checks:
:func:`~tpm_viz.app.sessions.decode_saved` builds ``Params``, the pose, the load and the trajectory with the
library's own validation). No secret is involved: any tpm-viz server reads any link.

An uploaded trajectory that would make the token longer than :data:`MAX_TOKEN_CHARS` is kept by content hash
through ``put_blob`` (the classroom store's ``put_blob(data) -> sha256 hex``); the token then names the digest,
and a server that does not hold it (``get_blob(digest) -> bytes | None``) refuses the link with one line that says
to open it on the server that made it or to upload the CSV there.

Status: the codec only; the *Copy share link* button and opening a link on page load are not wired yet.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import re
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

from tpm_viz.app.readouts import reason
from tpm_viz.app.sessions import Saved, decode_saved, encode_saved
from tpm_viz.errors import InputError
from tpm_viz.words import Phrase, T

__all__ = ["LINK_VERSION", "MAX_STATE_BYTES", "MAX_TOKEN_CHARS", "decode_link", "encode_link"]

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
    """The token of ``saved``; an uploaded trajectory that makes it too long goes to ``put_blob`` (refused in one
    line when there is no store)."""
    raw = encode_saved(saved)
    token = _pack(raw)
    trajectory = raw.get("trajectory")
    if len(token) <= MAX_TOKEN_CHARS or not isinstance(trajectory, dict) or trajectory.get("kind") != "csv":
        return token
    if put_blob is None:
        raise InputError(T("the uploaded trajectory is too large for a link and this server cannot store it"))
    data = json.dumps(trajectory, sort_keys=True, separators=(",", ":"), allow_nan=False).encode()
    raw["trajectory"] = {"stored": put_blob(data), "label": str(trajectory.get("label", ""))[:200]}
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
    """The state a token carries, every field checked; one-line :class:`~tpm_viz.errors.InputError` otherwise."""
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
    if data is None:
        raise InputError(
            Phrase(
                "this link's uploaded trajectory {name} is kept on the server that made the link: open the link "
                "there, or upload the CSV here",
                name=repr(str(ref.get("label", ""))[:80]),
            )
        )
    if hashlib.sha256(data).hexdigest() != digest or len(data) > MAX_STATE_BYTES:
        raise InputError(T("the share link's stored trajectory is damaged on this server: upload the CSV again"))
    return _json(data)
