"""CSV as spreadsheets write it, read into SI columns; CSV written back losslessly. Rules for users: ``docs/csv.md``.

Reading (the command line and the browser upload share it) is streaming, with stated limits
(:data:`MAX_ROWS`, :data:`MAX_BYTES`, :data:`MAX_LINE`), and forgives what real files contain: the spreadsheet
dialects of :mod:`tpm_viz.core.csvdialect` (byte-order marks, Windows text, CRLF, ``sep=;``, comma, semicolon or tab
delimiters, blank and ``#`` comment lines before the header, units in the header: ``t [s]``, ``p1 (mm)``,
``t_ms``, ``dp1 [mm/s]``, converted to SI), quoted cells, trailing empty columns, blank and comment lines among
the rows, decimal commas and the other number forms of :func:`tpm_viz.core.numbers.parse_number`, and columns it does
not need (ignored, whatever they hold). Every refusal is one :class:`~tpm_viz.core.errors.InputError` line naming the
row and column, or quoting the header it found.

Writing uses 17 significant digits (lossless for float64) and leaves a cell empty where a value does not exist
(an unreachable pose). :func:`write_columns` replaces a file atomically (temporary file, then rename).
"""

from __future__ import annotations

import csv
import io
import math
import sys
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import IO, Protocol, cast

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.csvdialect import (
    DELIMITERS,
    MAX_LINE,
    binary_lines,
    decode_text,
    find_header,
    quantity,
    split_header,
    text_lines,
)
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import atomic_writer, open_regular
from tpm_viz.core.numbers import parse_number, shorten, unit_factor
from tpm_viz.core.words import Phrase, T

__all__ = ["DELIMITERS", "MAX_BYTES", "MAX_LINE", "MAX_ROWS", "OPTIONAL_COLUMNS", "Table", "decode_text"]
__all__ += ["format_columns", "parse_columns", "read_columns", "read_text", "time_unit_note", "write_columns"]

OPTIONAL_COLUMNS = ("t",)
"""Columns read when present and passed through to the output (time [s])."""
MAX_ROWS = 1_000_000
"""Most data rows in one input (the command line; the upload has its own, smaller limit)."""
MAX_BYTES = 256 * 1024 * 1024
"""Largest input [bytes] (256 MiB)."""
CHUNK = 65_536
"""Rows converted to numbers at a time while reading."""
# Refusals too long for their raise, marked for the catalogue (gettext's N_ idiom); raised as Phrase(X.template, ...)
_FILE_TOO_BIG = T("{source} is {size} MiB; inputs are limited to {mib} MiB")
_NOT_CSV = T("{source}: line {line}: not valid CSV ({why})")
_TWICE = T("{source}: column {name} appears twice in the header {header}")
_MISSING = T("{source}: missing column {name} (need {need}); found header {header}")
_CELLS = T("{source}: row {row} has {cells} cells, the header has {width}")
_TOO_MANY = T("{source} has more than {limit} data rows (the limit); split the file")


class Rows(Protocol):
    """A :func:`csv.reader`: rows of cells, and the number of the line it has read up to."""

    @property
    def line_num(self) -> int: ...

    def __iter__(self) -> Iterator[list[str]]: ...

    def __next__(self) -> list[str]: ...


class Table(dict):
    """``{column: float array}`` in SI units, plus ``units``: the unit each column had in the file (``""``: none)."""

    units: dict[str, str]


def _open_lines(path: str, max_bytes: int) -> tuple[Iterator[str], IO[bytes] | None]:
    """Lines of the file at ``path`` (``-``: stdin), refused at once if a regular file is over ``max_bytes``."""
    if path == "-":
        raw = cast(io.BufferedReader, sys.stdin.buffer)  # typed BinaryIO; binary_lines needs its peek
        fh = None
    else:
        raw = fh = open_regular(path)  # a device, a FIFO or a folder is refused (one line), nothing hangs
        try:
            if raw.seekable() and raw.seek(0, 2) > max_bytes:
                size, mib = raw.tell() // 1048576, max_bytes // 1048576
                raise InputError(Phrase(_FILE_TOO_BIG.template, source=path, size=size, mib=mib))
            raw.seek(0)
        except BaseException:
            fh.close()
            raise
    return binary_lines(raw, "stdin" if path == "-" else path, max_bytes), fh


def read_text(path: str, max_bytes: int = MAX_BYTES) -> str:
    """The text of a file (``-`` for stdin) with the reader's decoding rules and size limit."""
    lines, fh = _open_lines(path, max_bytes)
    try:
        return "".join(lines)
    finally:
        if fh is not None:
            fh.close()


def read_columns(path: str, required: Sequence[str], max_rows: int = MAX_ROWS, max_bytes: int = MAX_BYTES) -> Table:
    """Read a CSV file (``-`` for stdin), streaming, into SI columns ``required`` (+ ``t`` if present)."""
    lines, fh = _open_lines(path, max_bytes)
    try:
        return parse_lines(lines, required, source="stdin" if path == "-" else path, max_rows=max_rows)
    finally:
        if fh is not None:
            fh.close()


def parse_columns(
    text: str, required: Sequence[str], source: str | Phrase = "input", max_rows: int = MAX_ROWS
) -> Table:
    """Parse CSV text into SI columns ``required`` (+ ``t`` if present); rules in the module docstring."""
    return parse_lines(text_lines(text, source), required, source, max_rows)


def parse_lines(
    lines: Iterable[str], required: Sequence[str], source: str | Phrase = "input", max_rows: int = MAX_ROWS
) -> Table:
    """The streaming core of :func:`parse_columns` and :func:`read_columns` (``lines`` keep their line ends)."""
    lines = iter(lines)
    delimiter, header_line, skipped = find_header(lines)
    need = ",".join(required)
    if header_line is None:
        raise InputError(Phrase("{source} is empty: expected a header with columns {need}", source=source, need=need))
    header: str = header_line

    def chained() -> Iterator[str]:
        yield header
        yield from lines

    reader = csv.reader(chained(), delimiter=delimiter)
    try:
        return _read_records(reader, required, source, max_rows, skipped - 1, header)
    except csv.Error as exc:
        at = skipped - 1 + reader.line_num
        raise InputError(Phrase(_NOT_CSV.template, source=source, line=at, why=str(exc))) from None


def _read_records(
    reader: Rows, required: Sequence[str], source: str | Phrase, max_rows: int, offset: int, header_line: str
) -> Table:
    raw_header = next(reader)
    while raw_header and not raw_header[-1].strip():
        raw_header.pop()  # trailing empty columns (spreadsheets)
    shown = shorten(header_line.strip(), 80)
    names: dict[str, int] = {}
    units: dict[str, str] = {}
    for j, cell in enumerate(raw_header):
        if not cell.strip():
            continue
        name, unit = split_header(cell)
        if name in names and name in (*required, *OPTIONAL_COLUMNS):
            raise InputError(Phrase(_TWICE.template, source=source, name=repr(name), header=shown))
        names.setdefault(name, j)
        units.setdefault(name, unit)
    missing = [c for c in required if c not in names]
    if missing:
        need = ",".join(required)
        raise InputError(Phrase(_MISSING.template, source=source, name=repr(missing[0]), need=need, header=shown))
    used = [c for c in OPTIONAL_COLUMNS if c in names and c not in required] + list(required)
    idx = [names[c] for c in used]
    factors = [
        unit_factor(
            units[c],
            quantity(c),
            Phrase("{source}: column {name}", source=source, name=shorten(raw_header[names[c]])),
            c,
        )
        for c in used
    ]
    width = len(raw_header)
    chunks: list[np.ndarray] = []
    buf: list[list[str]] = []
    where: list[int] = []
    for row in reader:
        line = offset + reader.line_num
        if len(row) != width or not row[0] or row[0][0] in "# \t":  # else: the common case, fast
            if not row or row[0].lstrip().startswith("#") or not any(c.strip() for c in row):
                continue  # blank and comment lines
            if len(row) < width or any(c.strip() for c in row[width:]):
                raise InputError(Phrase(_CELLS.template, source=source, row=line, cells=len(row), width=width))
        buf.append(row)
        where.append(line)
        if len(where) + CHUNK * len(chunks) > max_rows:
            raise InputError(Phrase(_TOO_MANY.template, source=source, limit=max_rows))
        if len(buf) == CHUNK:
            chunks.append(_numbers(buf, where, used, idx, source))
            buf, where = [], []
    if buf or not chunks:
        chunks.append(_numbers(buf, where, used, idx, source))
    data = np.concatenate(chunks)
    if len(data) == 0:
        raise InputError(Phrase("{source} has a header but no data rows", source=source))
    table = Table()
    for k, (c, (mul, div)) in enumerate(zip(used, factors, strict=True)):
        col = data[:, k]
        if div != 1.0:
            col = col / div
        table[c] = col * mul if mul != 1.0 else col.copy()
    table.units = {c: units[c] for c in used}
    return table


def _numbers(
    rows: list[list[str]], where: list[int], used: Sequence[str], idx: Sequence[int], source: str | Phrase
) -> np.ndarray:
    """The used cells of ``rows`` as floats ``(len(rows), len(used))``; one-line errors name row and column."""
    data = np.empty((len(rows), len(used)))
    for k, (c, j) in enumerate(zip(used, idx, strict=True)):
        cells = [r[j] for r in rows]
        try:
            data[:, k] = list(map(float, cells))
        except ValueError:
            data[:, k] = [
                parse_number(x, f"{source}: row {n}, column {c!r}") for x, n in zip(cells, where, strict=True)
            ]
        bad = ~np.isfinite(data[:, k])
        if np.any(bad):
            r = int(np.argmax(bad))
            cell = {"source": source, "row": where[r], "column": repr(c), "text": shorten(cells[r].strip())}
            if any(w in cells[r].lower() for w in ("nan", "inf")):
                raise InputError(Phrase("{source}: row {row}, column {column}: {text} is not finite", **cell))
            raise InputError(Phrase("{source}: row {row}, column {column}: {text} is too large", **cell))
    return data


def time_unit_note(table: Mapping[str, np.ndarray]) -> str | None:
    """A one-line hint when a ``t`` column without unit looks like milliseconds (spans 100 s in steps of >= 1 s)."""
    t = table.get("t")
    if t is None or getattr(table, "units", {}).get("t") or len(t) < 2:
        return None
    span, step = float(t[-1] - t[0]), float(np.median(np.diff(t)))
    if span >= 100.0 and step >= 1.0:
        return (
            f"note: t spans {span:g} s in steps of {step:g} s; if the times are in milliseconds, "
            "name the column t_ms or 't [ms]'"
        )
    return None


def format_columns(columns: Mapping[str, np.ndarray]) -> str:
    """Equal-length columns as CSV text (header line, then one line per row), as :func:`write_columns` writes."""
    out = io.StringIO()
    write_csv(out, columns)
    return out.getvalue()


def _strings(col: ArrayLike) -> list[str]:
    arr = np.asarray(col)
    if arr.dtype.kind in "biu":
        return list(map(str, arr.astype(np.int64).tolist()))
    if arr.dtype.kind == "f":
        values = arr.tolist()
        text = list(map("{:.17g}".format, values))
        if not np.all(np.isfinite(arr)):
            text = [t if math.isfinite(v) else "" for t, v in zip(text, values, strict=True)]
        return text
    return [str(x) for x in arr.tolist()]


def write_csv(fh: IO[str], columns: Mapping[str, np.ndarray]) -> None:
    """Write equal-length columns as CSV to the text file object ``fh`` (in chunks of rows)."""
    names = list(columns)
    n = len(next(iter(columns.values())))
    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow(names)
    cols = [columns[c] for c in names]
    for start in range(0, n, CHUNK):
        writer.writerows(zip(*(_strings(col[start : start + CHUNK]) for col in cols), strict=True))


def write_columns(path: str | None, columns: Mapping[str, np.ndarray]) -> None:
    """Write columns as CSV to ``path`` (stdout when None or ``-``), atomically
    (:func:`tpm_viz.core.files.atomic_writer`: a temporary file in the same folder, renamed over ``path`` once
    complete, so that a failure leaves any previous file as it was).

    The permissions of an existing file are kept and a symbolic link is followed; a path that exists and is not a
    regular file (``/dev/full``, a FIFO, a folder) is refused in one line and left as it is. An ``OSError`` names
    ``path``, not the temporary file.
    """
    if path in (None, "-"):
        write_csv(sys.stdout, columns)
        return
    with atomic_writer(path, text=True) as fh:
        write_csv(fh, columns)
