"""Saved classroom sessions: a versioned JSON document, written and read without viser (pure serialisation).

A document holds the shared mechanism (parameters, pose, load, trajectory sample, loaded trajectory including an
uploaded one, player time, lesson step) and, optionally, the tabs that were away when it was saved (their own copies
and view options, for :data:`KEEP_SECONDS` after they left), keyed by the browser's identity. :func:`dumps` writes
it, :func:`loads` reads it back through the library's own checks (``Params``, ``Pose.working``, ``Load``,
``Source.paper`` / ``Source.from_trajectory``, the upload limits of :mod:`tpm_viz.app.inputs`); anything wrong is
one :class:`~tpm_viz.InputError`. :func:`write_atomic` replaces a file in one step (temporary file + ``os.replace``).

Every number read must be finite and physically meaningful, as a browser could have typed it (a share link is read
here too, and anyone can mint one): positions within :data:`~tpm_viz.app.transitions.MAX_POSITION`, the load within
the panel's bounds (:data:`~tpm_viz.app.transitions.MAX_FORCE`, ``MAX_SPEED``, ``MAX_ACCEL``), times within
:data:`~tpm_viz.app.inputs.MAX_UPLOAD_SECONDS`, an uploaded trajectory within the upload's own limits (positions,
duration, finite velocities and accelerations): :mod:`.ranges`. ``1e308`` is refused like NaN, in one line naming the
field.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.app.inputs import MAX_UPLOAD_BYTES, MAX_UPLOAD_ROWS, MAX_UPLOAD_SECONDS
from tpm_viz.app.moves import Pose, check
from tpm_viz.app.readouts import Load, reason
from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState, TrajectorySample
from tpm_viz.app.transitions import MAX_ACCEL, MAX_FORCE, MAX_POSITION, MAX_SPEED
from tpm_viz.classroom.ranges import check_samples, within
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.files import loads_json, read_bytes, write_atomically
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Lang, Phrase
from tpm_viz.paper.trajectories import Trajectory

__all__ = [
    "FORMAT",
    "KEEP_SECONDS",
    "VERSION",
    "Document",
    "Saved",
    "decode_saved",
    "dumps",
    "encode_saved",
    "loads",
    "read_file",
    "write_atomic",
]

FORMAT = "tpm-viz-session"
VERSION = 1
"""Schema version; a document of another version is refused (one line), never half-read."""
KEEP_SECONDS = 30 * 60.0
"""How long a tab that left keeps its own copy and view options (wifi blip, laptop lid, restart)."""
MAX_DOCUMENT_BYTES = 4 * MAX_UPLOAD_BYTES + (1 << 20)
MAX_TABS = 2000
_SOURCE_KINDS = ("line", "circle", "segment", "csv")
_TIMES = (0.0, MAX_UPLOAD_SECONDS)
"""Range of every duration and time read [s] (the longest trajectory anything plays)."""


@dataclass
class Saved:
    """One mechanism as saved: its state, loaded trajectory (or None) and view options of the tab (if any), with
    the tab's language (``lang``: a :class:`tpm_viz.core.words.Lang` tag)."""

    state: AppState
    source: Source | None = None
    playing_t: float = 0.0
    show: dict[str, bool] = field(default_factory=dict)
    lang: str = "en"


@dataclass
class Document:
    """A whole session: the shared mechanism, the lesson step and the tabs that were away (identity -> records).

    A record is ``{"private": bool, "presenter": bool, "saved": Saved | None, "left_at": wall-clock seconds}``
    (``presenter``: the tab had logged in as the presenter; it is again when it comes back)."""

    shared: Saved
    lesson_step: int = 0
    tabs: dict[str, list[dict[str, Any]]] = field(default_factory=dict)


# -- writing ----------------------------------------------------------------------------------------------------------
def _vec(v: ArrayLike) -> list[float]:
    return [float(x) for x in np.asarray(v, dtype=float).reshape(-1)]


def _source(source: Source | None) -> dict[str, Any] | None:
    if source is None:
        return None
    out: dict[str, Any] = {"kind": source.kind, "duration": float(source.duration), "label": source.label}
    if source.kind == "segment" and source.start is not None and source.end is not None:
        out["start"], out["end"] = _vec(source.start), _vec(source.end)
    if source.kind == "csv" and source.knots is not None:
        t, p = source.knots
        out["t"], out["p"] = _vec(t), [_vec(row) for row in np.asarray(p)]
    return out


def _honest(state: AppState, source: Source | None) -> AppState:
    """``state`` as saved: never a run's stale dynamic load. The platform is at rest (static load, keeping ``f_ext``);
    the sample stays only if it is one of the saved trajectory (reopening seeks there again and recomputes ``ṗ, p̈``),
    a control run's or a plan's sample (a tab's own, not saved) becomes ``"none"``."""
    if not state.run_load:
        return state
    ours = (
        source is not None
        and state.trajectory.kind == source.kind
        and abs(state.trajectory.duration - source.duration) < 1e-12
    )
    rest = state.at_rest()
    return dataclasses.replace(rest, trajectory=state.trajectory) if ours else rest


def _saved(saved: Saved) -> dict[str, Any]:
    s = _honest(saved.state, saved.source)
    return {
        "params": {name: float(getattr(s.params, name)) for name in PARAM_INFO},
        "p": _vec(s.pose.p),
        "d": _vec(s.pose.d),
        "load": {"mode": s.load.mode, "f_ext": _vec(s.load.f_ext), "dp": _vec(s.load.dp), "ddp": _vec(s.load.ddp)},
        "sample": {"kind": s.trajectory.kind, "duration": s.trajectory.duration, "t": s.trajectory.t},
        "trajectory": _source(saved.source),
        "player_t": float(saved.playing_t),
        "show": {k: bool(v) for k, v in saved.show.items()},
        "lang": Lang.parse(saved.lang).value,
    }


def dumps(doc: Document, saved_at: float | None = None) -> str:
    """The JSON text of ``doc`` (UTF-8, stable key order); ``saved_at`` defaults to now (wall clock)."""
    tabs = {
        key: [
            {
                "private": bool(r["private"]),
                "presenter": bool(r.get("presenter", False)),
                "left_at": float(r["left_at"]),
                "saved": None if r.get("saved") is None else _saved(r["saved"]),
            }
            for r in records
        ]
        for key, records in doc.tabs.items()
    }
    body = {
        "format": FORMAT,
        "version": VERSION,
        "saved_at": time.time() if saved_at is None else float(saved_at),
        "shared": _saved(doc.shared),
        "lesson_step": int(doc.lesson_step),
        "tabs": tabs,
    }
    return json.dumps(body, sort_keys=True, allow_nan=False)


# -- reading ----------------------------------------------------------------------------------------------------------
def _get(obj: Any, name: str, kind: type | tuple[type, ...], where: str) -> Any:
    if not isinstance(obj, dict) or name not in obj or not isinstance(obj[name], kind) or isinstance(obj[name], bool):
        raise InputError(Phrase("session file: {where}{name} is missing or not the right type", where=where, name=name))
    return obj[name]


def _float(value: float, name: str, where: str) -> float:
    """``float(value)``; a JSON integer beyond float's range (``1e400`` written out) is not finite either."""
    try:
        return float(value)
    except OverflowError:
        raise InputError(Phrase("session file: {where}{name} is not finite", where=where, name=name)) from None


def _number(obj: Any, name: str, where: str) -> float:
    value = _float(_get(obj, name, (int, float), where), name, where)
    if not math.isfinite(value):
        raise InputError(Phrase("session file: {where}{name} is not finite", where=where, name=name))
    return value


def _pair(obj: Any, name: str, where: str) -> tuple[float, float]:
    value = _get(obj, name, list, where)
    if len(value) != 2 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise InputError(Phrase("session file: {where}{name} must be two numbers", where=where, name=name))
    out = (_float(value[0], name, where), _float(value[1], name, where))
    if not all(math.isfinite(v) for v in out):
        raise InputError(Phrase("session file: {where}{name} is not finite", where=where, name=name))
    return out


def _bounded(obj: Any, name: str, where: str, span: tuple[float, float], unit: str) -> float:
    """:func:`_number` within ``span``."""
    value = _number(obj, name, where)
    within(value, name, where, span, unit)
    return value


def _bounded_pair(obj: Any, name: str, where: str, most: float, unit: str) -> tuple[float, float]:
    """:func:`_pair` within ``±most`` each."""
    value = _pair(obj, name, where)
    within(value, name, where, (-most, most), unit)
    return value


def _read_source(raw: Any) -> Source | None:
    if raw is None:
        return None
    kind = _get(raw, "kind", str, "trajectory.")
    duration = _bounded(raw, "duration", "trajectory.", _TIMES, "s")
    if kind in ("line", "circle"):
        return Source.paper(kind, duration)
    if kind == "segment":
        start = _bounded_pair(raw, "start", "trajectory.", MAX_POSITION, "m")
        return Source.segment(start, _bounded_pair(raw, "end", "trajectory.", MAX_POSITION, "m"), duration)
    if kind != "csv":
        raise InputError(Phrase("session file: trajectory kind must be one of {kinds}", kinds=", ".join(_SOURCE_KINDS)))
    t = np.asarray(_get(raw, "t", list, "trajectory."), dtype=float)
    p = np.asarray(_get(raw, "p", list, "trajectory."), dtype=float)
    if t.ndim != 1 or not 4 <= t.size <= MAX_UPLOAD_ROWS or p.shape != (t.size, 2):
        raise InputError(
            Phrase(
                "session file: an uploaded trajectory needs 4 to {most} samples of (t, p1, p2)", most=MAX_UPLOAD_ROWS
            )
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p)) and np.all(np.diff(t) > 0)):
        raise InputError(
            Phrase("session file: the uploaded trajectory's times must increase and every value be finite")
        )
    check_samples(t, p)
    label = _get(raw, "label", str, "trajectory.")[:200]
    name = label.rsplit(", T =", 1)[0]
    zeros = np.zeros_like(p)
    return Source.from_trajectory(Trajectory(name, t, p, zeros, zeros))


def _read_saved(raw: Any, where: str) -> Saved:
    params_raw = _get(raw, "params", dict, where)
    unknown = set(params_raw) - set(PARAM_INFO)
    if unknown:
        raise InputError(Phrase("session file: unknown parameter {name}", name=repr(sorted(unknown)[0])))
    params = Params(**{k: v for k, v in params_raw.items()})  # validated: one-line InvalidParametersError
    p, d = _bounded_pair(raw, "p", where, MAX_POSITION, "m"), _bounded_pair(raw, "d", where, MAX_POSITION, "m")
    pose = Pose(np.array(p), np.array(d))
    if check(params, pose) != 0:
        pose = Pose.working(params, pose.p)  # not valid as saved: the working-mode pose at the same p
        if check(params, pose) != 0:
            raise InputError(Phrase("session file: the saved pose is not a valid pose of the saved parameters"))
    load_raw = _get(raw, "load", dict, where)
    load = Load(
        _get(load_raw, "mode", str, where + "load."),
        _bounded_pair(load_raw, "f_ext", where + "load.", MAX_FORCE, "N"),
        _bounded_pair(load_raw, "dp", where + "load.", MAX_SPEED, "m/s"),
        _bounded_pair(load_raw, "ddp", where + "load.", MAX_ACCEL, "m/s²"),
    )
    sample_raw = _get(raw, "sample", dict, where)
    sample = TrajectorySample(
        _get(sample_raw, "kind", str, where + "sample."),
        _bounded(sample_raw, "duration", where + "sample.", _TIMES, "s"),
        _bounded(sample_raw, "t", where + "sample.", _TIMES, "s"),
    )
    source = _read_source(raw.get("trajectory"))
    state = _honest(AppState(params=params, pose=pose, load=load, trajectory=sample), source)
    show_raw = raw.get("show", {}) if isinstance(raw, dict) else {}
    show = {str(k): v for k, v in show_raw.items() if isinstance(v, bool)} if isinstance(show_raw, dict) else {}
    player_t = _bounded(raw, "player_t", where, _TIMES, "s") if "player_t" in raw else 0.0
    lang = Lang.parse(raw.get("lang")).value  # absent (older files) or unknown: English
    return Saved(state, source, max(0.0, player_t), show, lang)


def encode_saved(saved: Saved) -> dict[str, Any]:
    """The JSON-ready form of one mechanism, as in a document (a record of the classroom store)."""
    return _saved(saved)


def decode_saved(raw: Any) -> Saved:
    """:func:`encode_saved`'s form read back through the library's checks; one-line :class:`~tpm_viz.InputError`."""
    return _checked(lambda: _read_saved(raw, ""))


def _checked(read: Any) -> Any:
    """``read()``, any problem turned into one ``session file: ...`` :class:`~tpm_viz.InputError`."""
    try:
        return read()
    except TpmVizError as exc:
        why = reason(exc)
        raise InputError(
            why if str(why).startswith("session file") else Phrase("session file: {why}", why=why)
        ) from None
    except (TypeError, ValueError, AttributeError, RecursionError, OverflowError) as exc:
        raise InputError(Phrase("session file: malformed ({kind})", kind=type(exc).__name__)) from None


def loads(text: str | bytes, now: float | None = None, steps: int | None = None) -> Document:
    """Read a session document; raises one-line :class:`~tpm_viz.InputError` if it is not a valid one of this
    version (not UTF-8, not JSON, nested too deep: :func:`tpm_viz.core.files.loads_json`). Away tabs older than
    :data:`KEEP_SECONDS` (at ``now``, wall clock) are dropped. ``steps``: the number of lesson steps; a lesson step
    out of range is refused (None: one out of range reads as 0)."""
    if len(text) > MAX_DOCUMENT_BYTES:
        raise InputError(Phrase("session file: larger than {limit} MiB", limit=MAX_DOCUMENT_BYTES >> 20))
    raw = loads_json(text, "session file")
    if not isinstance(raw, dict) or raw.get("format") != FORMAT:
        raise InputError(Phrase("session file: not a tpm-viz session"))
    if raw.get("version") != VERSION:
        raise InputError(
            Phrase(
                "session file: version {version}, this tpm-viz reads version {ours}",
                version=repr(raw.get("version")),
                ours=VERSION,
            )
        )
    step = raw.get("lesson_step", 0)
    valid = isinstance(step, int) and not isinstance(step, bool) and 0 <= step < (1000 if steps is None else steps)
    if steps is not None and not valid:
        raise InputError(
            Phrase("session file: lesson step {step} is not one of the {n} steps", step=repr(step)[:20], n=steps)
        )
    return _checked(lambda: _document(raw, step if valid else 0, time.time() if now is None else now))


def _document(raw: dict[str, Any], step: int, now: float) -> Document:
    """The document of a checked header (may raise anything: see :func:`_checked`)."""
    shared = _read_saved(raw.get("shared"), "shared.")
    tabs: dict[str, list[dict[str, Any]]] = {}
    tabs_raw = raw.get("tabs", {})
    for key, records in list(tabs_raw.items() if isinstance(tabs_raw, dict) else [])[:MAX_TABS]:
        kept = []
        for r in records if isinstance(records, list) else []:
            left_at = _number(r, "left_at", "tabs.")
            if now - left_at > KEEP_SECONDS:
                continue
            saved = None if r.get("saved") is None else _read_saved(r["saved"], "tabs.")
            record = {"private": bool(r.get("private")), "saved": saved, "left_at": left_at}
            kept.append(dict(record, presenter=r.get("presenter") is True))
        if kept:
            tabs[str(key)[:200]] = kept
    return Document(shared, step, tabs)


def read_file(path: Path) -> Document:
    """:func:`loads` of a file; a missing, unreadable or invalid file is one :class:`~tpm_viz.InputError`."""
    try:
        data = read_bytes(path, MAX_DOCUMENT_BYTES)
    except InputError as exc:
        raise InputError(Phrase("session file {why}", why=reason(exc))) from None
    return loads(data)


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` in one step (:func:`tpm_viz.core.files.write_atomically`: a temporary file in the
    same folder, then ``os.replace``; a device, FIFO or folder at ``path`` is refused, never replaced)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(path, text)
