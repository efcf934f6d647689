"""A content hash in each generated C file: how ``tpm-viz export --format c`` tells its own output from an edit.

The last line of ``tpm_2ppa.h`` and of ``tpm_2ppa.c`` is a comment with the SHA-256 of every byte above it (UTF-8),
e.g. ``/* tpm-viz-sha256 3f5a...: the hash of the lines above ... */``. A file is *untouched* when its last line is
such a stamp and the bytes above it hash to it; anything else counts as *edited*: a changed byte, a lost or altered
stamp, other line endings (a checkout with ``autocrlf``), a file of that name that tpm-viz never wrote. The export
replaces an untouched file and refuses an edited one unless told to (:mod:`.folder`, ``--force``).
"""

from __future__ import annotations

import hashlib

__all__ = ["stamped", "untouched"]


def _stamp(body: bytes) -> bytes:
    """The last line (without its newline) that marks ``body`` as written by the export."""
    digest = hashlib.sha256(body).hexdigest()
    return (
        f"/* tpm-viz-sha256 {digest}: the hash of the lines above; `tpm-viz export --format c` replaces this file "
        "only while they match */"
    ).encode("ascii")


def stamped(text: str) -> str:
    """``text`` (a newline added if it lacks one) and its stamp as a last line."""
    body = text if text.endswith("\n") else text + "\n"
    return body + _stamp(body.encode("utf-8")).decode("ascii") + "\n"


def untouched(data: bytes) -> bool:
    """Whether ``data`` (a file's bytes) is a stamped file exactly as :func:`stamped` wrote it, byte for byte."""
    if not data.endswith(b"\n"):
        return False
    body, newline, last = data[:-1].rpartition(b"\n")
    return last == _stamp(body + newline)
