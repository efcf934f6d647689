"""One reader for every file the app reads (session store imports, lessons, uploads, *Open session*).

The rules, in the order they are checked:

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

Every failure is one :class:`~tpm_viz.core.errors.FileRefusedError` whose one-line message names the path and what to
change, and never quotes the file's contents (no first line, no offending byte, no parser excerpt).

Base layer: standard library only.
"""

from __future__ import annotations

import json
import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any

from tpm_viz.core.errors import FileRefusedError
from tpm_viz.core.words import Phrase, T

__all__ = [
    "DEFAULT_DEPTH",
    "TOO_DEEP",
    "FileRefusedError",
    "depth_of",
    "loads_json",
    "loads_toml",
    "read_bytes",
    "read_json",
    "read_text",
    "read_toml",
    "resolve_inside",
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


def read_bytes(path: str | os.PathLike[str], limit: int, root: str | os.PathLike[str] | None = None) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit`` bytes, inside ``root`` if given); any problem is
    one :class:`FileRefusedError`."""
    real = resolve_inside(path, root)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(real, flags)
    except OSError as exc:
        raise _refuse(_NO_OPEN, path, why=_why(exc)) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = _kind(info.st_mode)
            raise _refuse(_NOT_REGULAR, path, kind=kind)
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
