"""Where things are written in a lesson file: the line of each ``[[exercise]]`` entry, its tables and its keys.

The standard library's TOML parser gives no line numbers; :func:`tpm_viz.app.lesson_toml.line_of` finds a key of a
plain table. Arrays of tables (``[[exercise]]``, ``[[exercise.mistake]]``) need their entries counted:
:func:`key_lines` scans the text once and records the first line of every table, entry and key by its path, with the
entry's index in place of an array's name (``("exercise", 0, "draw", "l_a")``). Multi-line strings are skipped.
"""

from __future__ import annotations

import re

__all__ = ["key_lines"]

_ARRAY = re.compile(r"^\s*\[\[\s*([^\[\]]+?)\s*\]\]")
_TABLE = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]")
_KEY = re.compile(r'^\s*((?:"[^"]*"|[A-Za-z0-9_-]+)(?:\s*\.\s*(?:"[^"]*"|[A-Za-z0-9_-]+))*)\s*=')


def _dotted(name: str) -> tuple[str, ...]:
    return tuple(part.strip().strip('"') for part in name.split("."))


def key_lines(text: str) -> dict[tuple[object, ...], int]:
    """Where each table, array entry and key is first written: ``("exercise", 0, "draw", "l_a") -> line``."""
    found: dict[tuple[object, ...], int] = {}
    counts: dict[tuple[object, ...], int] = {}
    current: tuple[object, ...] = ()
    in_string = False

    def resolve(names: tuple[str, ...], new_entry: bool) -> tuple[object, ...]:
        path: tuple[object, ...] = ()
        for k, name in enumerate(names):
            path += (name,)
            last = k == len(names) - 1
            if last and new_entry:
                counts[path] = counts.get(path, 0) + 1
                path += (counts[path] - 1,)
            elif path in counts:
                path += (counts[path] - 1,)
        return path

    for number, line in enumerate(text.splitlines(), 1):
        was = in_string
        if line.count('"""') % 2 or line.count("'''") % 2:
            in_string = not in_string
        if was:
            continue
        array, table = _ARRAY.match(line), _TABLE.match(line)
        if array or table:
            current = resolve(_dotted((array or table).group(1)), bool(array))  # type: ignore[union-attr]
            found.setdefault(current, number)
            continue
        key = _KEY.match(line)
        if key:
            found.setdefault(current + _dotted(key.group(1)), number)
    return found
