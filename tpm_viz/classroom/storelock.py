"""One server per store: an operating-system lock on a file beside the store, held while the server runs.

Two ``tpm-viz serve`` on one store (the second finds port 8080 busy, takes 8081 and opens the same default store)
would both save, and the lecture would be whichever saved last. So the first server takes an exclusive ``flock`` on
``<store>.lock`` (made beside the store, mode 0600) before it reads or moves anything, and writes its process id and,
once it listens, its port into that file; a second server finds the lock taken and refuses to start with one line
naming the first one's port and the ``--session`` option (:class:`StoreBusyError`).

The kernel releases the lock when the holder's process ends, however it ends (``kill -9`` and a power cut included),
so it never goes stale: the next server starts at once. The file itself stays (removing it would let two servers lock
two different files of one name); its contents only serve the refusal's message.

A lock file that cannot be made or locked (a read-only folder, a full disk, a system without ``flock``) is not a
reason not to start: :meth:`StoreLock.take` returns a notice instead, and the store then says itself whether it can
save (a read-only folder saves nothing, so nothing is overwritten).
"""

from __future__ import annotations

import importlib
import json
import os
import stat
from pathlib import Path
from typing import Any

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

try:
    fcntl: Any = importlib.import_module("fcntl")  # POSIX only
except ImportError:  # pragma: no cover - Windows: no flock; the notice of StoreLock.take says so
    fcntl = None

__all__ = ["LOCK_SUFFIX", "StoreBusyError", "StoreLock", "lock_path"]

LOCK_SUFFIX = ".lock"
"""The lock file is the store's name plus this (``classroom.sqlite3.lock``)."""
_MAX_LOCK_BYTES = 4096
_FLAGS = os.O_RDWR | os.O_CREAT | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


class StoreBusyError(InputError):
    """Another live server holds the store (its port, when it wrote one, is in the message)."""


def lock_path(store: Path) -> Path:
    """The lock file of the store at ``store``."""
    return store.with_name(store.name + LOCK_SUFFIX)


def _holder(fd: int) -> Phrase:
    """Who holds the lock, from what the holder wrote (its port, else its process id, else nothing)."""
    try:
        raw = json.loads(os.pread(fd, _MAX_LOCK_BYTES, 0).decode("utf-8"))
    except (OSError, ValueError):
        raw = None
    port = raw.get("port") if isinstance(raw, dict) else None
    pid = raw.get("pid") if isinstance(raw, dict) else None
    if isinstance(port, int) and not isinstance(port, bool) and 0 < port < 65536:
        return Phrase("the tpm-viz server on port {port}", port=port)
    if isinstance(pid, int) and not isinstance(pid, bool) and pid > 0:
        return Phrase("another tpm-viz server (process {pid}, still starting)", pid=pid)
    return Phrase("another tpm-viz server")


class StoreLock:
    """The lock of one store, held by this process from :meth:`take` until :meth:`release` (or its end)."""

    def __init__(self, path: Path, fd: int) -> None:
        self.path = path
        self._fd: int | None = fd
        self._write(None)

    @classmethod
    def take(cls, store: Path) -> tuple[StoreLock | None, str | None]:
        """Lock ``store`` for this server: ``(the lock, None)``, or ``(None, a notice)`` when no lock can be made
        here (the server starts anyway). Raises :class:`StoreBusyError` (one line) when another live server holds
        it."""
        path = lock_path(Path(store))
        if fcntl is None:  # pragma: no cover - Windows
            return None, f"cannot lock {path} (no flock here): start one server per session store"
        try:
            path.parent.mkdir(parents=True, exist_ok=True)  # the store's folder (a first start), as the store does
            fd = os.open(path, _FLAGS, 0o600)
        except OSError as exc:
            return None, f"cannot make the lock file {path} ({exc.strerror or type(exc).__name__})"
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                os.close(fd)
                return None, f"cannot lock {path}: it is not a regular file"
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            who = _holder(fd)
            os.close(fd)
            raise StoreBusyError(
                Phrase(
                    "the session store {store} is in use by {who}; stop that server first, or start this one on "
                    "another store with --session FILE",
                    store=str(store),
                    who=who,
                )
            ) from None
        except OSError as exc:
            os.close(fd)
            return None, f"cannot lock {path} ({exc.strerror or type(exc).__name__})"
        return cls(path, fd), None

    def _write(self, port: int | None) -> None:
        """Who holds the lock, for the refusal of the next server (a failure to write, e.g. a full disk, only
        makes that message shorter)."""
        if self._fd is None:
            return
        data = json.dumps({"pid": os.getpid(), "port": port}).encode()
        try:
            os.ftruncate(self._fd, 0)
            os.pwrite(self._fd, data, 0)
        except OSError:
            pass

    def serving(self, port: int) -> None:
        """This server listens on ``port`` now: the next one's refusal names it."""
        self._write(int(port))

    def release(self) -> None:
        """Let the next server take the store (idempotent)."""
        fd, self._fd = self._fd, None
        if fd is not None:
            os.close(fd)  # closing the only descriptor releases the flock

    def __del__(self) -> None:
        self.release()
