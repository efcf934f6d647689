"""CSV as spreadsheets write it: the text encoding, the delimiter and the header (names and their units).

What the reader of :mod:`tpm_viz.core.csvio` forgives before it reads a single number (rules for users:
``docs/csv.md``):

- the **encoding** (:func:`binary_lines`, :func:`decode_text`): a UTF-8 or UTF-16 byte-order mark, UTF-16 without
  one, UTF-8, else Windows' cp1252 or Latin-1 line by line; CRLF, LF or CR line ends; no NUL byte, no line over
  :data:`MAX_LINE` characters, no more than the byte limit the caller gives;
- the **header** (:func:`find_header`): blank and ``#`` comment lines before it, Excel's ``sep=;`` first line;
- the **delimiter** (:func:`sniff`): comma, semicolon or tab, the most frequent in the header line;
- the **header cells** (:func:`split_header`): ``t [s]``, ``p1 (mm)``, ``p1/mm``, ``t_ms``; names in lower case,
  ``time`` read as ``t``; :func:`quantity` says what a known column measures, for its unit's conversion
  (:func:`tpm_viz.core.numbers.unit_factor`; decimal commas and the other number forms are
  :func:`tpm_viz.core.numbers.parse_number`'s).

Every refusal is one :class:`~tpm_viz.core.errors.InputError` line naming the source and the line.
"""

from __future__ import annotations

import io
from collections.abc import Iterable, Iterator

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import UNITS
from tpm_viz.core.words import Phrase, T

__all__ = ["DELIMITERS", "MAX_LINE", "binary_lines", "decode_text", "find_header", "quantity", "sniff"]
__all__ += ["split_header", "text_lines"]

MAX_LINE = 65_536
"""Longest line of an input [bytes or characters]."""
DELIMITERS = (";", "\t", ",")
"""Delimiters sniffed from the header line, in order of preference on a tie."""
_ALIASES = {"time": "t"}
_QUANTITIES = "ddp:acceleration ddd:acceleration dp:velocity dd:velocity tau:force theta:angle p:length d:length"

# Refusals too long for their raise, marked for the catalogue (gettext's N_ idiom); raised as Phrase(X.template, ...)
_NOT_TEXT = T("{source}: line {line} is not valid {code}; save the file as UTF-8")
_TOO_BIG = T("{source} is larger than {mib} MiB (the limit); split the file")
_BINARY = T("{source} is not a text CSV file (binary content on line {line})")
_LONG_LINE = T("{source}: line {line} is longer than {most} characters (the limit)")


def quantity(name: str) -> str | None:
    """The quantity of a known column name (``p1`` length, ``dp1`` velocity, ``t`` time, ...), None if unknown."""
    base = name.split("_", 1)[0]
    for prefix, kind in (pair.split(":") for pair in _QUANTITIES.split()):
        if base.startswith(prefix) and base[len(prefix) :].isdigit():
            return kind
    return "time" if base == "t" else None


def split_header(cell: str) -> tuple[str, str]:
    """``'t [s]'`` -> ``('t', 's')``; also ``p1 (mm)``, ``p1/mm``, ``t_ms``; the name in lower case."""
    s = cell.strip().lstrip("\ufeff").strip()
    name, unit = s, ""
    if s[-1:] in (")", "]"):
        i = s.rfind("(" if s[-1] == ")" else "[")
        if i > 0:
            name, unit = s[:i].rstrip().rstrip("/"), s[i + 1 : -1]
    elif "/" in s:
        name, unit = s.split("/", 1)
        unit = unit.strip().strip("()[]")
    elif "_" in s and s.rsplit("_", 1)[1].lower() in UNITS:
        name, unit = s.rsplit("_", 1)
    name = name.strip().lower()
    return _ALIASES.get(name, name), unit.strip()


def decode_text(data: bytes, source: str = "input") -> str:
    """Bytes to text with the reader's rules: BOM (UTF-8/UTF-16), UTF-16 without BOM, UTF-8, else cp1252/Latin-1."""
    return "".join(binary_lines(io.BufferedReader(io.BytesIO(data)), source, len(data) + 1))


def binary_lines(raw: io.BufferedReader, source: str, max_bytes: int) -> Iterator[str]:
    """Decoded lines of a binary stream ``raw`` (see :func:`decode_text`; each keeps its line end), refused past
    ``max_bytes`` characters in all, at a NUL byte or at a line over :data:`MAX_LINE`."""
    head = raw.peek(4)[:4]
    bom = head[:2] in (b"\xff\xfe", b"\xfe\xff")
    le = len(head) == 4 and 0 not in (head[0], head[2]) and head[1] == head[3] == 0  # UTF-16-LE without BOM
    enc = "utf-16" if bom else "utf-16-le" if le else "utf-8"
    utf16 = enc != "utf-8"
    errors = "strict" if utf16 else "surrogateescape"  # bytes that are not UTF-8: see _decode_line
    readline = io.TextIOWrapper(raw, encoding=enc, errors=errors, newline="").readline  # \n, \r\n or \r
    total, n = 0, 0
    while True:
        try:
            line = readline(MAX_LINE + 1)
        except UnicodeDecodeError:
            raise InputError(Phrase(_NOT_TEXT.template, source=source, line=n + 1, code=enc.upper())) from None
        if not line:
            return
        n += 1
        if not line.isascii() and not utf16:
            try:
                line.encode("utf-8")
            except UnicodeEncodeError:
                line = _decode_line(line.encode("utf-8", "surrogateescape"))
        total += len(line)
        if total > max_bytes:
            raise InputError(Phrase(_TOO_BIG.template, source=source, mib=max_bytes // 1048576))
        if "\x00" in line:
            raise InputError(Phrase(_BINARY.template, source=source, line=n))
        if len(line) > MAX_LINE:
            raise InputError(Phrase(_LONG_LINE.template, source=source, line=n, most=MAX_LINE))
        yield line.lstrip("\ufeff") if n == 1 else line


def _decode_line(b: bytes) -> str:
    """A line that is not UTF-8: Windows' cp1252, else Latin-1 (only headers hold letters; numbers are ASCII)."""
    try:
        return b.decode("cp1252")
    except UnicodeDecodeError:
        return b.decode("latin-1")


def text_lines(text: str, source: str | Phrase) -> Iterator[str]:
    """The lines of ``text`` (each keeps its line end; a leading BOM dropped), refused at a line over
    :data:`MAX_LINE` characters."""
    for n, line in enumerate(io.StringIO(text, newline=""), start=1):
        if len(line) > MAX_LINE:
            raise InputError(Phrase(_LONG_LINE.template, source=source, line=n, most=MAX_LINE))
        yield line.lstrip("\ufeff") if n == 1 else line


def sniff(line: str) -> str:
    """The delimiter of a header ``line``: the most frequent of :data:`DELIMITERS` (``,`` when it has none)."""
    counts = [line.count(d) for d in DELIMITERS]
    best = max(counts)
    return DELIMITERS[counts.index(best)] if best else ","


def find_header(lines: Iterable[str]) -> tuple[str, str | None, int]:
    """Read ``lines`` up to the header: ``(delimiter, header line, lines read)``, skipping blank and ``#`` comment
    lines and taking the delimiter from Excel's ``sep=`` line (else sniffed from the header, :func:`sniff`). The
    header is None when ``lines`` hold none (the delimiter is then ``,``)."""
    delimiter, read = None, 0
    for line in lines:
        read += 1
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        if s.lower().startswith("sep=") and delimiter is None and len(s) == 5:
            delimiter = s[4]
            continue
        header = line.lstrip("\ufeff")
        return delimiter or sniff(header), header, read
    return delimiter or ",", None, read
