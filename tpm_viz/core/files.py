"""One reader for every file the app reads (session store imports, lessons, uploads, *Open session*, the command
line's inputs) and one writer for every file the command line writes (:func:`atomic_writer`).

The reader's rules, in the order they are checked:

- an optional ``root`` folder: the path, with every symlink resolved, must lie inside the resolved root (no
  symlink or ``..`` out of a lessons folder);
- no kernel pseudo-files: nothing under ``/proc``, ``/sys`` or ``/dev`` (``/proc/self/environ`` is a "regular"
  file of size 0 whose contents are secrets);
- regular files only: the file is opened with ``O_NONBLOCK`` (so a FIFO without a writer cannot hang the open)
  and ``fstat`` must say ``S_ISREG`` (no device such as ``/dev/zero``, no FIFO, no socket, no folder);
- a size ``limit`` [bytes]: ``fstat``'s size is checked before reading, and at most ``limit + 1`` bytes are ever
  read (a file that grows while being read is refused too);
- JSON and TOML are parsed with a nesting ``depth`` limit (levels of arrays and tables/objects); the parsers'
  ``RecursionError`` is turned into the same refusal, never raised.

Streaming readers (the command line's CSV) open the file with :func:`open_regular`: the same rules but the size.

The writer (:func:`atomic_writer`, :func:`write_atomically`) writes a temporary file in the target's folder, then
``os.replace`` it over the target, so that a failure leaves any previous file as it was. The target is the path with
every symlink resolved (:func:`output_target`), and it is refused, before anything is written and again just before
the replace, when it exists and is not a regular file (a device such as ``/dev/full``, a FIFO, a socket, a folder:
never opened, never replaced) or lies under ``/proc``, ``/sys`` or ``/dev``; a missing folder is refused too.

Every failure is one :class:`~tpm_viz.core.errors.FileRefusedError` whose one-line message names the path and what to
change, and never quotes the file's contents (no first line, no offending byte, no parser excerpt); an ``OSError``
while writing names the given path, never the temporary file.

Base layer: standard library only.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import stat
import tempfile
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from tpm_viz.core.errors import FileRefusedError
from tpm_viz.core.words import Phrase, T

__all__ = [
    "DEFAULT_DEPTH",
    "TOO_DEEP",
    "FileRefusedError",
    "atomic_writer",
    "depth_of",
    "loads_json",
    "loads_toml",
    "open_regular",
    "output_target",
    "read_bytes",
    "read_json",
    "read_text",
    "read_toml",
    "resolve_inside",
    "write_atomically",
]

DEFAULT_DEPTH = 32
"""Deepest nesting of arrays and tables/objects a JSON or TOML file may have (the app's own files need < 10)."""
_PSEUDO = (Path("/proc"), Path("/sys"), Path("/dev"))
_CHUNK = 1 << 20
# Refusals, marked for the catalogue (gettext's N_ idiom) and raised as Phrase(X.template, ...) after "path: "
_OUTSIDE = T("outside the folder {root}; put the file inside that folder")
_SYSTEM = T("a system file, not a data file; give a regular file")
_NO_OPEN = T("cannot open ({why}); check the name and its permissions")
_NOT_REGULAR = T("a {kind}, not a regular file; give a regular file")
_TOO_BIG = T("larger than {limit}; use a smaller file")
_NO_READ = T("cannot read ({why}); check the file")
_NOT_JSON = T("not valid JSON (line {line}); fix or replace the file")
_NOT_TOML = T("not valid TOML ({why}); fix the file")
TOO_DEEP = T("nested deeper than {depth} levels; flatten the file")
_NOT_UTF8 = T("not UTF-8 text (line {line}); save it as UTF-8")
_NOT_REGULAR_OUT = T("a {kind}, not a regular file: it is not replaced; write to a regular file or a new name")
_NO_FOLDER = T("the folder {folder} does not exist; create it or write elsewhere")
_FLAGS = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)


def _size(limit: int) -> str:
    """``limit`` [bytes] as people read it (``256 KiB``, ``5 MiB``)."""
    if limit >= 1 << 20 and limit % (1 << 20) == 0:
        return f"{limit >> 20} MiB"
    if limit >= 1 << 10:
        return f"{limit // 1024} KiB"
    return f"{limit} bytes"


def _refuse(template: Phrase, path: object, **values: object) -> FileRefusedError:
    """``path: what is wrong; what to change`` (``why``: the words without the path, to quote elsewhere)."""
    why = Phrase(template.template, **values)
    return FileRefusedError(Phrase("{path}: {why}", path=str(path), why=why), why)


def resolve_inside(path: str | os.PathLike[str], root: str | os.PathLike[str] | None = None) -> Path:
    """``path`` with every symlink resolved (relative to ``root`` when given), refused if it leaves ``root`` or is
    a kernel pseudo-file (``/proc``, ``/sys``, ``/dev``)."""
    given = Path(path)
    base = None if root is None else Path(os.path.realpath(root))
    real = Path(os.path.realpath(given if base is None or given.is_absolute() else base / given))
    if base is not None and not real.is_relative_to(base):
        raise _refuse(_OUTSIDE, given, root=str(base))
    if any(real.is_relative_to(p) for p in _PSEUDO):
        raise _refuse(_SYSTEM, given)
    return real


def _open(path: str | os.PathLike[str], root: str | os.PathLike[str] | None) -> tuple[int, os.stat_result]:
    """A descriptor of the regular file ``path`` and its ``fstat``; refused as the module docstring says."""
    real = resolve_inside(path, root)
    try:
        fd = os.open(real, _FLAGS)  # O_NONBLOCK: a FIFO without a writer cannot hang the open
    except OSError as exc:
        raise _refuse(_NO_OPEN, path, why=_why(exc)) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise _refuse(_NOT_REGULAR, path, kind=_kind(info.st_mode))
    except BaseException as exc:
        os.close(fd)
        if isinstance(exc, OSError):
            raise _refuse(_NO_READ, path, why=_why(exc)) from None
        raise
    return fd, info


def open_regular(path: str | os.PathLike[str], root: str | os.PathLike[str] | None = None) -> io.BufferedReader:
    """The regular file ``path`` opened for reading in binary (for a streaming reader, which keeps its own size
    limit); anything else (a device, a FIFO, a folder, a kernel pseudo-file, a path outside ``root``) is one
    :class:`FileRefusedError`, and nothing hangs."""
    fd, _info = _open(path, root)
    return open(fd, "rb")  # the caller closes it


def read_bytes(path: str | os.PathLike[str], limit: int, root: str | os.PathLike[str] | None = None) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit`` bytes, inside ``root`` if given); any problem is
    one :class:`FileRefusedError`."""
    fd, info = _open(path, root)
    try:
        if info.st_size > limit:
            raise _refuse(_TOO_BIG, path, limit=_size(limit))
        chunks: list[bytes] = []
        got = 0
        while got <= limit:
            chunk = os.read(fd, min(_CHUNK, limit + 1 - got))
            if not chunk:
                break
            chunks.append(chunk)
            got += len(chunk)
        if got > limit:
            raise _refuse(_TOO_BIG, path, limit=_size(limit))
        return b"".join(chunks)
    except OSError as exc:
        raise _refuse(_NO_READ, path, why=_why(exc)) from None
    finally:
        os.close(fd)


def read_text(path: str | os.PathLike[str], limit: int, root: str | os.PathLike[str] | None = None) -> str:
    """:func:`read_bytes` decoded as UTF-8 (a byte-order mark is dropped)."""
    return _decode(read_bytes(path, limit, root), path)


def read_json(
    path: str | os.PathLike[str], limit: int, root: str | os.PathLike[str] | None = None, depth: int = DEFAULT_DEPTH
) -> Any:
    """The JSON value of the file ``path`` (rules of :func:`read_bytes`, nesting at most ``depth`` levels)."""
    return loads_json(read_bytes(path, limit, root), path, depth)


def read_toml(
    path: str | os.PathLike[str], limit: int, root: str | os.PathLike[str] | None = None, depth: int = DEFAULT_DEPTH
) -> dict[str, Any]:
    """The TOML table of the file ``path`` (rules of :func:`read_bytes`, nesting at most ``depth`` levels)."""
    return loads_toml(read_text(path, limit, root), path, depth)


def loads_json(data: str | bytes, source: object = "input", depth: int = DEFAULT_DEPTH) -> Any:
    """``json.loads`` that refuses (one :class:`FileRefusedError` naming ``source``) invalid JSON, non-UTF-8 bytes
    and nesting deeper than ``depth``; never a ``RecursionError``. The message quotes nothing of ``data``."""
    text = _decode(data, source) if isinstance(data, bytes) else data
    try:
        value = json.loads(text)
    except RecursionError:
        raise _too_deep(source, depth) from None
    except ValueError as exc:
        where = getattr(exc, "lineno", None)
        raise _refuse(_NOT_JSON, source, line=where or "?") from None
    if depth_of(value) > depth:
        raise _too_deep(source, depth)
    return value


def loads_toml(text: str, source: object = "input", depth: int = DEFAULT_DEPTH) -> dict[str, Any]:
    """``tomllib.loads`` with the same guarantees as :func:`loads_json`; a syntax error keeps the parser's words
    and position, which never contain the file's text."""
    try:
        value = tomllib.loads(text)
    except RecursionError:
        raise _too_deep(source, depth) from None
    except tomllib.TOMLDecodeError as exc:
        raise _refuse(_NOT_TOML, source, why=_toml_why(exc)) from None
    if depth_of(value) > depth:
        raise _too_deep(source, depth)
    return value


def depth_of(value: object) -> int:
    """Levels of nested lists and dicts in ``value`` (a scalar: 0, ``[]``: 1, ``[[1]]``: 2), computed without
    recursion."""
    deepest = 0
    stack: list[tuple[object, int]] = [(value, 0)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, dict):
            children: Any = item.values()
        elif isinstance(item, list | tuple):
            children = item
        else:
            continue
        deepest = max(deepest, level + 1)
        stack.extend((child, level + 1) for child in children if isinstance(child, dict | list | tuple))
    return deepest


def _too_deep(source: object, depth: int) -> FileRefusedError:
    return _refuse(TOO_DEEP, source, depth=depth)


def _decode(data: bytes, source: object) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise _refuse(_NOT_UTF8, source, line=line) from None


def _toml_why(exc: tomllib.TOMLDecodeError) -> str:
    """tomllib's message: fixed words plus ``(at line L, column C)``; anything else is dropped (never quoted)."""
    text = str(exc).splitlines()[0] if str(exc) else "syntax error"
    found = re.match(r"([A-Za-z ,'=/.\[\]{}-]{1,80}?)\s*\((at line \d+, column \d+|at end of document)\)$", text)
    return f"{found.group(1)}, {found.group(2)}" if found else "syntax error"


def _kind(mode: int) -> Phrase:
    if stat.S_ISDIR(mode):
        return T("folder")
    if stat.S_ISFIFO(mode):
        return T("pipe (FIFO)")
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return T("device")
    if stat.S_ISSOCK(mode):
        return T("socket")
    return T("special file")


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


# -- writing ---------------------------------------------------------------------------------------------------------
def output_target(path: str | os.PathLike[str], folder: bool = True) -> Path:
    """The file that writing ``path`` makes or replaces: ``path`` with every symlink resolved. Refused (one
    :class:`FileRefusedError` naming ``path``) when it exists and is not a regular file, is a kernel pseudo-file
    (``/proc``, ``/sys``, ``/dev``) or (``folder``) its folder does not exist. Nothing is opened: a FIFO cannot hang
    it."""
    real = Path(os.path.realpath(path))
    try:
        info: os.stat_result | None = os.stat(real)
    except (FileNotFoundError, NotADirectoryError):  # not there (a file where a folder should be: not there either)
        info = None
    except OSError as exc:  # a symlink loop, a folder that cannot be searched
        raise _refuse(_NO_OPEN, path, why=_why(exc)) from None
    if info is not None and not stat.S_ISREG(info.st_mode):
        raise _refuse(_NOT_REGULAR_OUT, path, kind=_kind(info.st_mode))
    if any(real.is_relative_to(p) for p in _PSEUDO):
        raise _refuse(_SYSTEM, path)
    if folder and not real.parent.is_dir():
        raise _refuse(_NO_FOLDER, path, folder=str(real.parent))
    return real


def _new_file_mode(target: Path) -> int:
    """The existing file's permission bits, or ``0o666`` less the process umask for a new file."""
    try:
        return os.stat(target).st_mode & 0o777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextlib.contextmanager
def atomic_writer(path: str | os.PathLike[str], text: bool = False) -> Iterator[IO[Any]]:
    """A file object whose contents replace ``path`` in one step when the ``with`` block ends without an error
    (``text``: UTF-8 text with ``\n`` kept as written; else bytes). The target is checked by :func:`output_target`
    before anything is written and again just before the replace; it keeps its permissions (a new file gets those a
    plain ``open()`` would give it). On any failure the temporary file is removed and a previous file is kept; an
    ``OSError`` names ``path``."""
    target = output_target(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=".tpm-viz-", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(path)) from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") if text else os.fdopen(fd, "wb") as handle:
            os.fchmod(handle.fileno(), _new_file_mode(target))  # mkstemp makes 0600
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        output_target(path)  # a device or FIFO put there meanwhile is not replaced either
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise


def write_atomically(path: str | os.PathLike[str], data: str | bytes) -> None:
    """Write ``data`` (text as UTF-8) to ``path`` with :func:`atomic_writer`."""
    with atomic_writer(path) as handle:
        handle.write(data.encode("utf-8") if isinstance(data, str) else data)
