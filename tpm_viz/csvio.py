"""Strict CSV reading and writing for the command line (numeric columns, SI units).

Reading checks, in this order, and raises :class:`~tpm_viz.errors.InputError` with one line
naming the problem: empty file, missing column, unknown column, ragged row, non-numeric
cell, non-finite cell (NaN or inf). Writing uses 17 significant digits (lossless for
float64) and leaves a cell empty where a value does not exist (e.g. an unreachable pose).
"""

from __future__ import annotations

import csv
import io
import math
import sys
from collections.abc import Mapping, Sequence

import numpy as np

from tpm_viz.errors import InputError

__all__ = ["OPTIONAL_COLUMNS", "parse_columns", "read_columns", "read_text", "write_columns"]

OPTIONAL_COLUMNS = ("t",)
"""Columns accepted in any input and passed through to the output (time [s])."""


def read_columns(path: str, required: Sequence[str]) -> dict[str, np.ndarray]:
    """Read a CSV file (``-`` for stdin) whose header holds exactly ``required`` (+ optional ``t``)."""
    return parse_columns(read_text(path), required, source=path)


def read_text(path: str) -> str:
    """The text of a file (``-`` for stdin), BOM-tolerant."""
    if path == "-":
        return sys.stdin.read()
    with open(path, encoding="utf-8-sig") as fh:
        return fh.read()


def parse_columns(text: str, required: Sequence[str], source: str = "input") -> dict[str, np.ndarray]:
    """Parse CSV text into ``{column: float array}``; see the module docstring for the checks."""
    rows = [r for r in csv.reader(io.StringIO(text)) if any(cell.strip() for cell in r)]
    if not rows:
        raise InputError(f"{source} is empty: expected a header with columns {','.join(required)}")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in required if c not in header]
    if missing:
        raise InputError(f"{source}: missing column {missing[0]!r} (need {','.join(required)})")
    unknown = [c for c in header if c not in required and c not in OPTIONAL_COLUMNS]
    if unknown:
        raise InputError(f"{source}: unknown column {unknown[0]!r} (expected {','.join(required)})")
    if len(set(header)) != len(header):
        raise InputError(f"{source}: a column name appears twice in the header")
    if len(rows) < 2:
        raise InputError(f"{source} has a header but no data rows")
    data = np.empty((len(rows) - 1, len(header)))
    for r, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise InputError(f"{source}: row {r} has {len(row)} cells, the header has {len(header)}")
        for k, cell in enumerate(row):
            try:
                value = float(cell)
            except ValueError:
                raise InputError(f"{source}: row {r}, column {header[k]!r}: {cell.strip()!r} is not a number") from None
            if not math.isfinite(value):
                raise InputError(f"{source}: row {r}, column {header[k]!r}: {cell.strip()!r} is not finite")
            data[r - 2, k] = value
    ordered = [c for c in OPTIONAL_COLUMNS if c in header and c not in required] + list(required)
    return {c: data[:, header.index(c)] for c in ordered}


def _cell(x) -> str:
    if isinstance(x, (str, np.str_)):
        return str(x)
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    x = float(x)
    return format(x, ".17g") if math.isfinite(x) else ""


def format_columns(columns: Mapping[str, np.ndarray]) -> str:
    """Equal-length columns as CSV text (header line, then one line per row), as :func:`write_columns` writes."""
    names = list(columns)
    n = len(next(iter(columns.values())))
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(names)
    cols = [columns[c] for c in names]
    for r in range(n):
        writer.writerow([_cell(col[r]) for col in cols])
    return out.getvalue()


def write_columns(path: str | None, columns: Mapping[str, np.ndarray]) -> None:
    """Write equal-length columns as CSV to ``path`` (stdout when ``None`` or ``-``)."""
    text = format_columns(columns)
    if path in (None, "-"):
        sys.stdout.write(text)
    else:
        with open(path, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
