"""Lesson and preset files as TOML with line numbers: where a key is written (:func:`line_of`), typed access that
refuses a value at the line of its key (:class:`Reader`), and the file read and parsed (:func:`parse`). The words
of a refusal are a :class:`~tpm_viz.core.words.Phrase` (shown in a tab's language; ``str()``: English).
"""

from __future__ import annotations

import math
import pathlib
import re
import tomllib
from typing import NoReturn

from tpm_viz.core import files
from tpm_viz.core.errors import FileRefusedError, InputError
from tpm_viz.core.words import Phrase

__all__ = ["MAX_FILE_BYTES", "LessonError", "Problem", "Reader", "line_of", "parse"]

MAX_FILE_BYTES = 256 * 1024
"""Largest lesson, preset or lesson CSV file [bytes]."""
MAX_DEPTH = 8
"""Deepest nesting of tables and arrays in a lesson or preset file (the format needs 3)."""


class Problem(str):
    """One refused file as a line of English (``file:line: what is wrong``: the command line, the log) that keeps its
    words as a :class:`~tpm_viz.core.words.Phrase` in ``phrase`` (a tab shows them in its language)."""

    phrase: Phrase

    def __new__(cls, phrase: Phrase) -> Problem:
        line = super().__new__(cls, str(phrase))
        line.phrase = phrase
        return line


class LessonError(InputError):
    """A lesson or preset file is refused: ``line`` (1-based) and what is wrong."""

    def __init__(self, message: str | Phrase, line: int = 1) -> None:
        super().__init__(message)
        self.line = line


_HEADER = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]")
_KEY = re.compile(r'^\s*((?:"[^"]*"|[A-Za-z0-9_-]+)(?:\s*\.\s*(?:"[^"]*"|[A-Za-z0-9_-]+))*)\s*=')


def _dotted(name: str) -> list[str]:
    return [part.strip().strip('"') for part in name.split(".")] if name else []


def line_of(text: str, table: str, key: str = "") -> int:
    """1-based line where ``key`` is set in ``[table]`` (``table`` "" for the top level, ``key`` "" for the table
    itself: its header, or its first dotted key such as ``text.en = ...``); 1 if not found."""
    target = _dotted(table) + ([key] if key else [])
    current: list[str] = []
    in_string = False
    for number, line in enumerate(text.splitlines(), 1):
        was_in_string = in_string
        if line.count('"""') % 2 or line.count("'''") % 2:
            in_string = not in_string
        if was_in_string:
            continue
        header = _HEADER.match(line)
        if header:
            current = _dotted(header.group(1))
            if current == target:
                return number
            continue
        found = _KEY.match(line)
        if found and target and (current + _dotted(found.group(1)))[: len(target)] == target:
            return number
    return 1


class Reader:
    """Typed access to one parsed file, raising :class:`LessonError` at the line of the offending key."""

    def __init__(self, text: str, data: dict) -> None:
        self.text = text
        self.data = data

    def fail(self, table: str, key: str, message: str | Phrase) -> NoReturn:
        raise LessonError(message, line_of(self.text, table, key))

    def table(self, name: str, known: tuple[str, ...] | None, required: bool = False) -> dict:
        value = self.data.get(name)
        if value is None:
            if required:
                self.fail("", "", Phrase("missing [{name}]", name=name))
            return {}
        if not isinstance(value, dict):
            self.fail("", name, Phrase("{name} must be a table ([{name}])", name=name))
        if known is not None:
            for key in value:
                if key not in known:
                    self.fail(
                        name,
                        key,
                        Phrase("unknown key {name}.{key}; known: {known}", name=name, key=key, known=", ".join(known)),
                    )
        return value

    def number(self, table: str, values: dict, key: str, lo: float = -math.inf, hi: float = math.inf) -> float:
        value = values[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(
                table, key, Phrase("{name} must be a finite number, got {got}", name=_name(table, key), got=repr(value))
            )
        if not lo <= value <= hi:
            self.fail(
                table,
                key,
                Phrase(
                    "{name} must be from {lo:g} to {hi:g}, got {got}",
                    name=_name(table, key),
                    lo=lo,
                    hi=hi,
                    got=repr(value),
                ),
            )
        return float(value)

    def vector(self, table: str, values: dict, key: str, size: int) -> tuple[float, ...]:
        value = values[key]
        ok = isinstance(value, list) and len(value) == size
        if not ok or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value):
            self.fail(
                table,
                key,
                Phrase(
                    "{name} must be a list of {size} numbers [SI], got {got}",
                    name=_name(table, key),
                    size=size,
                    got=repr(value),
                ),
            )
        out = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in out):
            self.fail(table, key, Phrase("{name} must be finite, got {got}", name=_name(table, key), got=repr(value)))
        return out

    def string(self, table: str, values: dict, key: str, choices: tuple[str, ...] | None = None) -> str:
        value = values[key]
        if not isinstance(value, str) or not value.strip():
            self.fail(
                table,
                key,
                Phrase("{name} must be a non-empty string, got {got}", name=_name(table, key), got=repr(value)),
            )
        if choices is not None and value not in choices:
            self.fail(
                table,
                key,
                Phrase(
                    "{name} must be one of {choices}; got {got}",
                    name=_name(table, key),
                    choices=", ".join(choices),
                    got=repr(value),
                ),
            )
        return value


def _name(table: str, key: str) -> str:
    return f"{table}.{key}" if table else key


def parse(path: pathlib.Path, root: pathlib.Path | None = None) -> tuple[str, dict]:
    """The text and the TOML data of ``path`` (:class:`LessonError` with the line on any problem), read with
    :mod:`tpm_viz.core.files`' rules (a regular file inside ``root`` if given, at most :data:`MAX_FILE_BYTES`, nested
    at most :data:`MAX_DEPTH` levels); a refusal never quotes the file."""
    try:
        raw = files.read_bytes(path, MAX_FILE_BYTES, root)
    except FileRefusedError as exc:
        raise LessonError(exc.why) from None  # type: ignore[arg-type]
    try:
        text, data = _parse_text(raw)
    except RecursionError:
        raise LessonError(Phrase(files.TOO_DEEP.template, depth=MAX_DEPTH)) from None
    if files.depth_of(data) > MAX_DEPTH:
        raise LessonError(Phrase(files.TOO_DEEP.template, depth=MAX_DEPTH))
    return text, data


def _parse_text(raw: bytes) -> tuple[str, dict]:
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise LessonError(Phrase("not UTF-8 text"), raw[: exc.start].count(b"\n") + 1) from None
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        found = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        what = re.sub(r"\s*\(at line \d+, column \d+\)|\s*\(at end of document\)", "", str(exc))
        if found:
            raise LessonError(
                Phrase("TOML: {what} (column {column})", what=what, column=found.group(2)), int(found.group(1))
            ) from None
        raise LessonError(Phrase("TOML: {what}", what=what), text.count("\n") + 1) from None
