"""Validation of everything a browser sends: widget values and uploaded files. Pure Python + numpy, no viser.

The browser is not trusted: viser does not range-check GUI values, casts strings such as ``"nan"`` or ``"1e999"``
to floats on the server, and a hand-written client can send anything the protocol allows. Every reader here
either returns a clean value in SI units or raises :class:`~tpm_viz.InputError` with a one-line message meant
for the user who sent it. Out-of-range numbers that are merely *too large* are clipped (a slider dragged past its
end); values that are not numbers at all (NaN, inf, text, wrong length) are refused.

The CSV trajectory upload goes through :func:`read_upload` only (size, encoding, row count, finiteness, timing),
whichever widget receives it. :func:`value_problem` is the first, kind-level check of any widget value, applied to
every GUI message before a callback runs (``viserkit/transport.py``): a number for a number, a boolean for a checkbox,
text of at most :data:`MAX_TEXT` characters, a tuple of the widget's length (its answer is a log line, in English:
a browser never sends such a value, so no user reads it).

Every refusal carries a :class:`~tpm_viz.core.words.Phrase` (``str(exc)``: the English line; ``say(lang, exc)``: the
line in a tab's language). A widget's ``name`` in a message may be a phrase (``T("time t")``), shown in the tab's
language, or a plain name (``"d1"``, ``"f_ext"``), shown as it is.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np

from tpm_viz.app.readouts import reason
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.trajectories import Trajectory, parse_trajectory_csv

__all__ = [
    "MAX_TEXT",
    "MAX_UPLOAD_BYTES",
    "MAX_UPLOAD_ROWS",
    "TOO_LARGE",
    "read_choice",
    "read_flag",
    "read_number",
    "read_params",
    "read_upload",
    "read_vec2",
    "value_problem",
]

MAX_UPLOAD_BYTES = 1 << 20
"""Largest accepted upload [bytes] (1 MiB, ~20 000 rows of ``t,p1,p2``); larger transfers are dropped."""
MAX_UPLOAD_ROWS = 20_000
"""Most data rows in an uploaded trajectory."""
MAX_UPLOAD_SECONDS = 3600.0
"""Longest accepted trajectory duration [s]."""
MAX_UPLOAD_POSITION = 10.0
"""Largest accepted ``|p_i|`` in an upload [m] (reachability is checked by whoever plays it)."""
_MAX_NAME = 80
MAX_TEXT = 1000
"""Longest text a text input accepts [characters] (the presenter token is far shorter)."""
TOO_LARGE = T("the file is too large ({size} bytes; at most {most} bytes)")
"""The refusal of an upload beyond the size limit (raise ``Phrase(TOO_LARGE.template, size=..., most=...)``; also
the transport's, ``tpm_viz.viserkit.transport``, which refuses it before any byte is buffered)."""


def value_problem(current: object, value: object, max_text: int = MAX_TEXT) -> str | None:
    """Why ``value`` is not a value of the same kind as a widget's ``current`` value (None if it is): a finite
    number (not a boolean, not text) for a number, a boolean for a boolean, text of at most ``max_text`` characters
    for text, a sequence of the same length, item by item, for a tuple."""
    if current is None:
        return "this widget takes no value"
    if isinstance(current, bool):
        return None if isinstance(value, bool) else f"on or off is due, got {type(value).__name__}"
    if isinstance(current, (int, float)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f"a number is due, got {type(value).__name__}"
        try:
            ok = math.isfinite(value)
        except OverflowError:  # an int beyond float range
            ok = False
        return None if ok else "not a finite number"
    if isinstance(current, str):
        if not isinstance(value, str):
            return f"text is due, got {type(value).__name__}"
        return None if len(value) <= max_text else f"text longer than {max_text} characters"
    if isinstance(current, tuple):
        if not isinstance(value, (list, tuple)) or len(value) != len(current):
            return f"{len(current)} values are due"
        problems = (value_problem(c, v, max_text) for c, v in zip(current, value, strict=True))
        return next((p for p in problems if p is not None), None)
    return f"a value of the wrong type for this widget ({type(value).__name__})"


def read_number(
    value: object, name: str | Phrase, scale: float = 1.0, lo: float = -math.inf, hi: float = math.inf
) -> float:
    """A finite number from a widget, times ``scale`` (UI unit -> SI), clipped to ``[lo, hi]`` (SI)."""
    if isinstance(value, bool):
        raise InputError(Phrase("{name} must be a number, got {got}", name=name, got=_show(value)))
    try:
        x = float(value)  # type: ignore[arg-type]  # anything a browser sent: TypeError is caught
    except (TypeError, ValueError, OverflowError):
        raise InputError(Phrase("{name} must be a number, got {got}", name=name, got=_show(value))) from None
    if not math.isfinite(x):
        raise InputError(Phrase("{name} must be finite, got {got}", name=name, got=_show(value)))
    scaled = x * scale
    if not math.isfinite(scaled):  # e.g. 1e308 mm -> m is fine, but 1e308 * 1e3 is not
        raise InputError(Phrase("{name} is too large, got {got}", name=name, got=_show(value)))
    return float(np.clip(scaled, lo, hi))


def read_vec2(value: object, name: str | Phrase, scale: float = 1.0, bound: float = math.inf) -> np.ndarray:
    """Two finite numbers from a widget, times ``scale`` (UI unit -> SI), each clipped to ``[-bound, bound]``."""
    two = Phrase("{name} must be two numbers, got {got}", name=name, got=_show(value))
    if isinstance(value, (str, bytes, Mapping)):
        raise InputError(two)
    try:
        items = list(value)  # type: ignore[call-overload]  # anything a browser sent: TypeError is caught
    except TypeError:
        raise InputError(two) from None
    if len(items) != 2:
        raise InputError(two)
    return np.array([read_number(v, name, scale, -bound, bound) for v in items])


def read_choice(value: object, name: str | Phrase, choices: Iterable[str]) -> str:
    """One of ``choices`` (a dropdown value), else :class:`~tpm_viz.InputError`."""
    choices = tuple(choices)
    if not isinstance(value, str) or value not in choices:
        raise InputError(
            Phrase(
                "{name} must be one of {choices}, got {got}", name=name, choices=", ".join(choices), got=_show(value)
            )
        )
    return value


def read_flag(value: object, name: str | Phrase) -> bool:
    """A checkbox value: a real boolean (``0``/``1`` accepted), else :class:`~tpm_viz.InputError`."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)) and value in (0, 1):
        return bool(value)
    raise InputError(Phrase("{name} must be on or off, got {got}", name=name, got=_show(value)))


def read_params(params: Params, raw: Mapping[str, object]) -> Params:
    """A new parameter set from the panel's inputs (UI units: mm, kg); ``Params`` checks the geometry."""
    changes = {}
    for name, value in raw.items():
        if name not in PARAM_INFO:
            raise InputError(Phrase("unknown parameter {name}", name=_show(name)))
        changes[name] = read_number(value, name, scale=1.0 / PARAM_INFO[name]["ui_scale"])
    return params.replace(**changes)


def read_upload(content: object, filename: str = "upload.csv", max_bytes: int = MAX_UPLOAD_BYTES) -> Trajectory:
    """A trajectory from an uploaded CSV file (columns ``t,p1,p2`` in s, m, m), checked from the bytes up.

    Refused with a one-line :class:`~tpm_viz.InputError`: not bytes, larger than ``max_bytes``, not UTF-8,
    binary (NUL bytes), more than :data:`MAX_UPLOAD_ROWS` rows, anything :func:`~tpm_viz.parse_trajectory_csv`
    refuses (missing columns, text or NaN cells, fewer than 4 rows, times not increasing), positions beyond
    :data:`MAX_UPLOAD_POSITION`, a duration beyond :data:`MAX_UPLOAD_SECONDS`, or non-finite derivatives
    (samples too close in time). Reachability for the current parameters is the player's check.
    """
    if not isinstance(content, (bytes, bytearray, memoryview)):
        raise InputError(T("the upload is not a file"))
    content = bytes(content)
    if len(content) > max_bytes:
        raise InputError(Phrase(TOO_LARGE.template, size=len(content), most=max_bytes))
    if b"\x00" in content:
        raise InputError(T("the file is not a text CSV file (binary content)"))
    try:
        text = content.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(T("the file is not UTF-8 text")) from None
    name = _clean_name(filename)
    try:
        with np.errstate(all="ignore"):
            traj = parse_trajectory_csv(text, name=name, max_rows=MAX_UPLOAD_ROWS)
    except TpmVizError:
        raise
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:  # defensive: a parser gap
        raise InputError(Phrase("the trajectory CSV could not be read: {why}", why=reason(exc))) from None
    if np.max(np.abs(traj.p)) > MAX_UPLOAD_POSITION:
        raise InputError(
            Phrase("a position in the file is beyond {most:g} m (the file is in metres)", most=MAX_UPLOAD_POSITION)
        )
    if not float(traj.t[-1]) <= MAX_UPLOAD_SECONDS:
        raise InputError(
            Phrase(
                "the trajectory lasts {duration:g} s (at most {most:g} s)",
                duration=float(traj.t[-1]),
                most=MAX_UPLOAD_SECONDS,
            )
        )
    if not (np.all(np.isfinite(traj.dp)) and np.all(np.isfinite(traj.ddp))):
        raise InputError(T("samples too close in time: the velocities or accelerations are not finite"))
    return traj


def _clean_name(filename: object) -> str:
    """A short printable trajectory name from an uploaded file name (never a path)."""
    text = filename if isinstance(filename, str) else "upload.csv"
    text = text.replace("\\", "/").rsplit("/", 1)[-1]
    text = "".join(ch for ch in text if ch.isprintable())[:_MAX_NAME]
    return text or "upload.csv"


def _show(value: object) -> str:
    """A short, printable rendering of an untrusted value for a message (never the whole of a huge string)."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
