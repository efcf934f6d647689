"""Writing the generated C into a folder (``tpm-viz export --format c --output DIR``) without harming what is there.

The rules, checked for both files before either is written (a refusal writes nothing):

- the folder: created if missing (its parents as well); ``DIR`` itself must not be a symbolic link (the export
  does not write through a link: give the folder it points to), nor anything but a folder. It is opened once with
  ``O_NOFOLLOW | O_DIRECTORY`` and every later step goes through that descriptor (``dir_fd``), so a folder swapped
  for a link after the check is not followed either;
- each file name in it: absent, or a regular file (a symbolic link, a folder, a FIFO or a device of that name is
  refused, even with ``force``); a regular file must be *untouched* since its export (its last line is the content
  hash of :mod:`.stamp`, and matches), or ``force`` must be given: an edited file is never replaced silently;
- each file is written atomically: a temporary file in the folder, ``fsync``, then ``os.replace`` (a replaced file
  keeps its permission bits; a new one gets those of a plain ``open()``).
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Mapping

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase, T
from tpm_viz.exchange.c.stamp import untouched

__all__ = ["write_c_folder"]

_READ_LIMIT = 4 << 20
"""Bytes read of an existing file to check its hash [bytes]; a larger file cannot be an export (~40 kB): edited."""
_KINDS = (
    (stat.S_ISLNK, T("symbolic link")),
    (stat.S_ISDIR, T("folder")),
    (stat.S_ISFIFO, T("pipe (FIFO)")),
    (stat.S_ISCHR, T("device")),
    (stat.S_ISBLK, T("device")),
    (stat.S_ISSOCK, T("socket")),
)


def _kind(mode: int) -> Phrase:
    return next((kind for test, kind in _KINDS if test(mode)), T("special file"))


def _open_folder(directory: str) -> int:
    """A descriptor of the folder ``directory`` (created if missing), never through a symbolic link."""
    if directory == "-":
        raise InputError(T("--format c writes two files: give a directory as --output, not '-'"))
    directory = directory.rstrip(os.sep) or os.sep  # "link/" would resolve the link even under O_NOFOLLOW
    if os.path.islink(directory):
        raise InputError(
            Phrase(
                "--output {path} is a symbolic link: --format c does not write through a link; give the directory it "
                "points to, or another one",
                path=repr(directory),
            )
        )
    if os.path.lexists(directory) and not os.path.isdir(directory):
        raise InputError(
            Phrase(
                "--output {path} is not a directory: --format c needs a directory (created if missing)",
                path=repr(directory),
            )
        )
    try:
        os.makedirs(directory, exist_ok=True)
        return os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise InputError(
            Phrase(
                "cannot use the directory --output {path}: {why}", path=repr(directory), why=exc.strerror or str(exc)
            )
        ) from None


def _is_untouched(folder: int, name: str) -> bool:
    """Whether the regular file ``name`` in ``folder`` is an export as written (read at most :data:`_READ_LIMIT`)."""
    fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0), dir_fd=folder)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return False
        chunks, got = [], 0
        while got <= _READ_LIMIT:
            chunk = os.read(fd, _READ_LIMIT + 1 - got)
            if not chunk:
                break
            chunks.append(chunk)
            got += len(chunk)
        return got <= _READ_LIMIT and untouched(b"".join(chunks))
    finally:
        os.close(fd)


def _check(folder: int, directory: str, name: str, force: bool) -> int | None:
    """The permission bits of the existing file ``name`` (None if absent); refuses what must not be replaced."""
    path = os.path.join(directory, name)
    try:
        info = os.stat(name, dir_fd=folder, follow_symlinks=False)
    except FileNotFoundError:
        return None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(
            Phrase(
                "{path} is a {kind}, not a regular file: not replaced; remove it or choose another --output directory",
                path=repr(path),
                kind=_kind(info.st_mode),
            )
        )
    try:
        edited = not force and not _is_untouched(folder, name)
    except OSError as exc:
        raise InputError(Phrase("cannot read {path}: {why}", path=repr(path), why=exc.strerror or str(exc))) from None
    if edited:
        raise InputError(
            Phrase(
                "{path} was changed after it was exported (it no longer matches the hash in its last line): not "
                "replaced; move it away, or give --force to replace it",
                path=repr(path),
            )
        )
    return stat.S_IMODE(info.st_mode)


def _write(folder: int, name: str, text: str, mode: int | None) -> None:
    """``text`` into ``name`` through a temporary file in ``folder``, ``fsync``, ``os.replace``."""
    tmp = f".{name}.tpm-viz-{os.getpid()}.tmp"
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(tmp, flags, 0o666, dir_fd=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            if mode is not None:
                os.fchmod(fh.fileno(), mode)
            fh.write(text.encode("utf-8"))
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, name, src_dir_fd=folder, dst_dir_fd=folder)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp, dir_fd=folder)
        raise


def write_c_folder(directory: str, files: Mapping[str, str], force: bool = False) -> None:
    """Write ``files`` (``{name: text}``, :func:`tpm_viz.exchange.c.code.c_files`) into the folder ``directory`` by
    the rules of the module docstring; :class:`~tpm_viz.core.errors.InputError` (one line) for what it refuses."""
    folder = _open_folder(directory)
    try:
        modes = {name: _check(folder, directory, name, force) for name in files}
        for name, text in files.items():
            try:
                _write(folder, name, text, modes[name])
            except OSError as exc:
                path = repr(os.path.join(directory, name))
                raise InputError(
                    Phrase("cannot write {path}: {why}", path=path, why=exc.strerror or str(exc))
                ) from None
    finally:
        os.close(folder)
