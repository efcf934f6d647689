"""Identities the server issues: a browser's cookie is minted and signed here, and only its hash is ever stored.

A cookie value is ``<32 hex: a random id>.<32 hex: HMAC-SHA256(secret, id), first 128 bits>``. :meth:`Keys.verify`
gives the id back only for a cookie this server signed (compared in constant time); anything else (a self-made
32-hex value, another server's cookie, garbage) is no identity, and the page answers it with a new cookie. The key
a browser's records are stored under is :func:`hashed` (SHA-256 of the id): a copy of the store gives no cookie.

The secret (32 random bytes) is kept in a file beside the store, created with mode 0600
(:meth:`Keys.in_folder`); a secret that cannot be kept is held in memory only (cookies then last until the server
stops), with a one-line notice.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import re
import secrets
from pathlib import Path

from tpm_viz.core.errors import InputError
from tpm_viz.core.files import read_bytes

__all__ = ["SECRET_FILE", "Keys", "hashed"]

SECRET_FILE = "tpm-viz-cookie-secret"
_SECRET_BYTES = 32
_VALUE = re.compile(r"^([0-9a-f]{32})\.([0-9a-f]{32})$")


def hashed(kind: str, raw: str) -> str:
    """The stored form of an identity: ``<kind>:<SHA-256 of raw, hex>`` (``kind``: ``c`` cookie, ``a`` address)."""
    return f"{kind}:{hashlib.sha256(raw.encode('utf-8', 'replace')).hexdigest()}"


class Keys:
    """Mints and verifies the ``tpmviz_id`` cookie with one secret."""

    def __init__(self, secret: bytes | None = None) -> None:
        self._secret = secret if secret is not None else secrets.token_bytes(_SECRET_BYTES)
        if len(self._secret) < 16:
            raise ValueError("the cookie secret must be at least 16 bytes")

    @classmethod
    def in_folder(cls, folder: Path) -> tuple[Keys, str | None]:
        """The keys of the secret in ``folder`` (made, mode 0600, if there is none), and a notice if it could not be
        read or kept (then an in-memory secret)."""
        path = Path(folder) / SECRET_FILE
        try:
            folder.mkdir(parents=True, exist_ok=True)
            try:
                fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
            except FileExistsError:
                secret = read_bytes(path, 4096)
                if len(secret) < _SECRET_BYTES:
                    raise InputError(f"{path}: too short to be a secret") from None
                if os.stat(path).st_mode & 0o077:
                    os.chmod(path, 0o600)  # nobody else reads it
                return cls(secret), None
            secret = secrets.token_bytes(_SECRET_BYTES)
            with os.fdopen(fd, "wb") as handle:
                handle.write(secret)
                handle.flush()
                os.fsync(handle.fileno())
            return cls(secret), None
        except (OSError, InputError) as exc:
            why = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
            return cls(), f"cannot keep the cookie secret in {path} ({why}); browsers are known until the server stops"

    def derive(self, purpose: str) -> bytes:
        """A 32-byte key for ``purpose`` derived from the secret (HMAC-SHA256 of the purpose): the same for as long as
        the secret is kept (the exercise seeds' key, :mod:`tpm_viz.classroom.results`); it gives no cookie back."""
        return hmac.new(self._secret, f"tpm-viz derive: {purpose}".encode(), hashlib.sha256).digest()

    def _mac(self, ident: str) -> str:
        return hmac.new(self._secret, ident.encode(), hashlib.sha256).hexdigest()[:32]

    def mint(self) -> str:
        """A new cookie value (a new, empty identity)."""
        ident = secrets.token_hex(16)
        return f"{ident}.{self._mac(ident)}"

    def verify(self, value: object) -> str | None:
        """The id of a cookie value this server signed, else None."""
        found = _VALUE.match(value) if isinstance(value, str) else None
        if found is None or not hmac.compare_digest(found.group(2), self._mac(found.group(1))):
            return None
        return found.group(1)
