"""The tool's RSA key: read (:meth:`ToolKey.read`), made (:func:`keygen`), named and published.

The key signs the deep-linking responses and the AGS client assertions (RS256). Its ``kid`` is the RFC 7638
thumbprint of the public key (base64url of the SHA-256 of ``{"e","kty","n"}`` in canonical JSON), so the same key
always has the same ``kid`` and ``/lti/jwks`` serves exactly what ``tpm-viz lti keygen`` printed.

``keygen(folder)`` writes ``folder/tool-key.pem`` (PKCS #8, unencrypted) created with mode 0600 and ``O_EXCL``: an
existing file is never overwritten.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import jwt
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric import rsa

from tpm_viz.core.errors import InputError
from tpm_viz.core.files import read_bytes

__all__ = ["KEY_BITS", "KEY_FILE", "MIN_BITS", "ToolKey", "keygen", "thumbprint"]

KEY_FILE = "tool-key.pem"
KEY_BITS = 2048
"""Size of a new key [bits] (what Moodle, Canvas and the IMS certification suite accept)."""
MIN_BITS = 2048
_MAX_PEM_BYTES = 64 << 10


def _b64(n: int) -> str:
    raw = n.to_bytes((n.bit_length() + 7) // 8, "big")
    return base64.urlsafe_b64encode(raw).decode("ascii").rstrip("=")


def thumbprint(jwk: dict[str, Any]) -> str:
    """The RFC 7638 thumbprint of an RSA public JWK (its ``e``, ``kty``, ``n``)."""
    canonical = json.dumps({k: jwk[k] for k in ("e", "kty", "n")}, separators=(",", ":"), sort_keys=True)
    return base64.urlsafe_b64encode(hashlib.sha256(canonical.encode()).digest()).decode("ascii").rstrip("=")


@dataclass(frozen=True)
class ToolKey:
    """The tool's private key, its ``kid`` and its public JWK."""

    private: rsa.RSAPrivateKey
    kid: str
    public_jwk: dict[str, Any]

    @classmethod
    def of(cls, private: rsa.RSAPrivateKey) -> ToolKey:
        numbers = private.public_key().public_numbers()
        jwk = {"kty": "RSA", "e": _b64(numbers.e), "n": _b64(numbers.n)}
        kid = thumbprint(jwk)
        return cls(private, kid, {**jwk, "kid": kid, "alg": "RS256", "use": "sig"})

    @classmethod
    def read(cls, path: Path) -> ToolKey:
        """The key in the PEM file ``path`` (one-line :class:`InputError` when it is not an RSA key of at least
        :data:`MIN_BITS` bits without a passphrase)."""
        data = read_bytes(path, _MAX_PEM_BYTES)
        try:
            key = serialization.load_pem_private_key(data, password=None)
        except (ValueError, TypeError):
            raise InputError(
                f"{path}: not an unencrypted PEM private key; make one with tpm-viz lti keygen --output DIR"
            ) from None
        if not isinstance(key, rsa.RSAPrivateKey) or key.key_size < MIN_BITS:
            raise InputError(f"{path}: not an RSA key of at least {MIN_BITS} bits; make one with tpm-viz lti keygen")
        return cls.of(key)

    def jwks(self) -> dict[str, Any]:
        """The public key set ``/lti/jwks`` serves."""
        return {"keys": [dict(self.public_jwk)]}

    def sign(self, claims: dict[str, Any]) -> str:
        """``claims`` as a JWT signed RS256 with this key, ``kid`` in its header."""
        return jwt.encode(claims, self.private, algorithm="RS256", headers={"kid": self.kid, "typ": "JWT"})

    def pem(self) -> bytes:
        return self.private.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        )


def keygen(folder: Path, bits: int = KEY_BITS) -> ToolKey:
    """A new key written to ``folder/tool-key.pem`` (mode 0600, never over an existing file)."""
    folder = Path(folder)
    path = folder / KEY_FILE
    if path.exists() or path.is_symlink():
        raise InputError(f"{path} exists and is not overwritten; choose another --output folder or move it away")
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
    except OSError as exc:
        raise InputError(f"cannot make the folder {folder} ({exc.strerror or exc}); choose another --output") from None
    key = ToolKey.of(rsa.generate_private_key(public_exponent=65537, key_size=bits))
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags, 0o600)
    except FileExistsError:
        raise InputError(f"{path} exists and is not overwritten; choose another --output folder") from None
    except OSError as exc:
        raise InputError(f"cannot write {path} ({exc.strerror or exc}); choose another --output") from None
    with os.fdopen(fd, "wb") as handle:
        handle.write(key.pem())
        handle.flush()
        os.fsync(handle.fileno())
    return key
