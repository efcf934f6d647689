"""Lessons and parameter presets written as TOML files, and where the packaged ones are.

The packaged data live in ``assets/`` at the repository root, installed as the package ``tpm_viz.assets``
(``lessons/*.toml``, ``trajectories/*.csv``, ``presets/*.toml``; each folder has a README). A lecturer's own
lessons are a folder of the same files (``tpm-viz serve --lessons DIR``); the format is
``assets/lessons/README.md``.

:func:`load_lessons` never raises for a bad file: it returns the lessons that are right and one line per file that
is not, ``file:line: what is wrong`` (TOML syntax, an unknown or missing key, a wrong type, a parameter that
:class:`~tpm_viz.Params` refuses, a pose or a motion that leaves the valid set).
"""

from __future__ import annotations

import importlib.util
import math
import pathlib
import re
import tomllib
from typing import NoReturn

import numpy as np

from tpm_viz.app.demos import CHECK_NAMES, LANGUAGES, Camera, Check, Demo, Motion, demo_params, demo_pose, demo_source
from tpm_viz.app.moves import check, why_not
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.app.runs import check_path
from tpm_viz.errors import InputError, TpmVizError
from tpm_viz.paper.trajectories import parse_trajectory_csv
from tpm_viz.params import PARAM_INFO, Params

__all__ = ["MAX_FILE_BYTES", "LessonError", "assets_dir", "load_lesson", "load_lessons", "load_preset"]

MAX_FILE_BYTES = 256 * 1024
"""Largest lesson, preset or lesson CSV file [bytes]."""
MOTION_KINDS = ("line", "circle", "segment", "csv")
TOP_KEYS = ("key", "title", "text", "params", "pose", "motion", "camera", "view", "checks")
CHECK_SAMPLES = 101
"""Samples at which a lesson's motion is checked when it is loaded."""


class LessonError(InputError):
    """A lesson or preset file is refused: ``line`` (1-based) and what is wrong."""

    def __init__(self, message: str, line: int = 1) -> None:
        super().__init__(message)
        self.line = line


def assets_dir() -> pathlib.Path:
    """The folder of packaged data: the installed ``tpm_viz.assets``, else ``assets/`` beside the package in a
    source checkout whose editable install predates it."""
    spec = importlib.util.find_spec("tpm_viz.assets")
    if spec is not None and spec.submodule_search_locations:
        return pathlib.Path(next(iter(spec.submodule_search_locations)))
    return pathlib.Path(__file__).resolve().parents[2] / "assets"


# --- where a key is written -------------------------------------------------------------------------------------

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


class _Reader:
    """Typed access to one parsed file, raising :class:`LessonError` at the line of the offending key."""

    def __init__(self, text: str, data: dict) -> None:
        self.text = text
        self.data = data

    def fail(self, table: str, key: str, message: str) -> NoReturn:
        raise LessonError(message, line_of(self.text, table, key))

    def table(self, name: str, known: tuple[str, ...] | None, required: bool = False) -> dict:
        value = self.data.get(name)
        if value is None:
            if required:
                self.fail("", "", f"missing [{name}]")
            return {}
        if not isinstance(value, dict):
            self.fail("", name, f"{name} must be a table ([{name}])")
        if known is not None:
            for key in value:
                if key not in known:
                    self.fail(name, key, f"unknown key {name}.{key}; known: {', '.join(known)}")
        return value

    def number(self, table: str, values: dict, key: str, lo: float = -math.inf, hi: float = math.inf) -> float:
        value = values[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(table, key, f"{_name(table, key)} must be a finite number, got {value!r}")
        if not lo <= value <= hi:
            self.fail(table, key, f"{_name(table, key)} must be from {lo:g} to {hi:g}, got {value!r}")
        return float(value)

    def vector(self, table: str, values: dict, key: str, size: int) -> tuple[float, ...]:
        value = values[key]
        ok = isinstance(value, list) and len(value) == size
        if not ok or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value):
            self.fail(table, key, f"{_name(table, key)} must be a list of {size} numbers [SI], got {value!r}")
        out = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in out):
            self.fail(table, key, f"{_name(table, key)} must be finite, got {value!r}")
        return out

    def string(self, table: str, values: dict, key: str, choices: tuple[str, ...] | None = None) -> str:
        value = values[key]
        if not isinstance(value, str) or not value.strip():
            self.fail(table, key, f"{_name(table, key)} must be a non-empty string, got {value!r}")
        if choices is not None and value not in choices:
            self.fail(table, key, f"{_name(table, key)} must be one of {', '.join(choices)}; got {value!r}")
        return value


def _name(table: str, key: str) -> str:
    return f"{table}.{key}" if table else key


def _parse(path: pathlib.Path) -> tuple[str, dict]:
    """The text and the TOML data of ``path`` (:class:`LessonError` with the line on any problem)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise LessonError(f"cannot read: {exc.strerror or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise LessonError(f"larger than {MAX_FILE_BYTES // 1024} KiB")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise LessonError("not UTF-8 text", raw[: exc.start].count(b"\n") + 1) from None
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        found = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        what = re.sub(r"\s*\(at line \d+, column \d+\)|\s*\(at end of document\)", "", str(exc))
        if found:
            raise LessonError(f"TOML: {what} (column {found.group(2)})", int(found.group(1))) from None
        raise LessonError(f"TOML: {what}", text.count("\n") + 1) from None


def _params(r: _Reader) -> tuple[tuple[str, float], ...]:
    values = r.table("params", tuple(PARAM_INFO))
    overrides = tuple((key, r.number("params", values, key)) for key in values)
    try:
        Params.paper().replace(**dict(overrides))
    except TpmVizError as exc:
        named = [key for key, _ in overrides if re.search(rf"\b{re.escape(key)}\b", str(exc))]
        r.fail("params", named[0] if named else "", f"parameters refused: {exc}")
    return overrides


def _motion(r: _Reader, path: pathlib.Path) -> tuple[Motion | None, tuple[float, ...]]:
    t = "motion"
    values = r.table(t, ("kind", "duration", "start", "end", "file", "compare"))
    if not values:
        return None, ()
    if "kind" not in values:
        r.fail(t, "", "[motion] needs kind")
    kind = r.string(t, values, "kind", MOTION_KINDS)
    if "duration" not in values and kind != "csv":
        r.fail(t, "", f"a {kind} motion needs motion.duration [s]")
    duration = r.number(t, values, "duration", 0.01, 100.0) if "duration" in values else math.nan
    compare: tuple[float, ...] = ()
    if "compare" in values:
        raw = values["compare"]
        if not isinstance(raw, list) or len(raw) != 2:
            r.fail(t, "compare", f"motion.compare must be a list of 2 durations [s], got {raw!r}")
        compare = r.vector(t, values, "compare", 2)
        if not all(0.01 <= v <= 100.0 for v in compare):
            r.fail(t, "compare", f"motion.compare durations must be from 0.01 to 100 s, got {raw!r}")
    needs = {"segment": ("start", "end"), "csv": ("file",)}.get(kind, ())
    for key in ("start", "end", "file"):
        if key in needs and key not in values:
            r.fail(t, "kind", f"a {kind} motion needs motion.{key}")
        if key not in needs and key in values:
            r.fail(t, key, f"motion.{key} does not apply to a {kind} motion")
    if kind == "segment":
        start, end = r.vector(t, values, "start", 2), r.vector(t, values, "end", 2)
        return Motion(kind, duration, start, end), compare  # type: ignore[arg-type]
    if kind == "csv":
        name = r.string(t, values, "file")
        try:
            csv = (path.parent / name).read_bytes()
            if len(csv) > MAX_FILE_BYTES:
                raise InputError(f"larger than {MAX_FILE_BYTES // 1024} KiB")
            traj = parse_trajectory_csv(csv.decode("utf-8-sig"), name=pathlib.Path(name).stem)
        except OSError as exc:
            r.fail(t, "file", f"motion.file {name!r}: {exc.strerror or exc}")
        except (TpmVizError, UnicodeDecodeError) as exc:
            r.fail(t, "file", f"motion.file {name!r}: {exc}")
        if math.isnan(duration):
            duration = traj.duration  # the file's own timing
        return Motion(kind, duration, file=name, trajectory=traj), compare
    return Motion(kind, duration), compare


def _pose(r: _Reader) -> dict:
    values = r.table("pose", ("p", "d", "mode"))
    out: dict = {}
    if "p" in values and "d" in values:
        r.fail("pose", "d", "give pose.p (platform) or pose.d (actuators), not both")
    if "p" in values:
        out["p"] = r.vector("pose", values, "p", 2)
    if "d" in values:
        out["d"] = r.vector("pose", values, "d", 2)
    if "mode" in values:
        if values["mode"] not in (1, -1) or isinstance(values["mode"], bool):
            r.fail("pose", "mode", f"pose.mode must be 1 (working) or -1, got {values['mode']!r}")
        if "d" not in values:
            r.fail("pose", "mode", "pose.mode applies to pose.d only (pose.p is in the working mode)")
        out["mode"] = values["mode"]
    return out


def _checks(r: _Reader) -> tuple[Check, ...]:
    values = r.table("checks", tuple(CHECK_NAMES))
    out = []
    for name, value in values.items():
        if isinstance(value, dict):
            for key in value:
                if key not in ("value", "tol"):
                    r.fail("checks", name, f"checks.{name}: unknown key {key!r}; known: value, tol")
            if "value" not in value:
                r.fail("checks", name, f"checks.{name} needs a value")
            stated = r.number("checks", value, "value")
            tol = r.number("checks", value, "tol", 0.0) if "tol" in value else None
            out.append(Check(name, stated, tol))
        else:
            out.append(Check(name, r.number("checks", values, name)))
    return tuple(out)


def _key_of(path: pathlib.Path) -> str:
    """``01-direct.toml`` -> ``direct``."""
    return re.sub(r"^[0-9]+[-_ .]*", "", path.stem) or path.stem


def load_lesson(path) -> Demo:
    """One lesson file (raises :class:`LessonError`; its ``line`` says where)."""
    path = pathlib.Path(path)
    text, data = _parse(path)
    r = _Reader(text, data)
    for key in data:
        if key not in TOP_KEYS:
            r.fail("", key, f"unknown key {key!r}; known: {', '.join(TOP_KEYS)}")
    if "title" not in data:
        r.fail("", "", "missing title")
    title = r.string("", data, "title")
    key = r.string("", data, "key") if "key" in data else _key_of(path)
    if isinstance(data.get("text"), str):
        r.fail("", "text", 'text must be a table of languages: [text] en = "..."')
    texts = r.table("text", LANGUAGES, required=True)
    if "en" not in texts:
        r.fail("text", "", "missing text.en (the English paragraph)")
    paragraphs = {lang: " ".join(r.string("text", texts, lang).split()) for lang in texts}
    camera_values = r.table("camera", ("position", "look_at"))
    camera = None
    if camera_values:
        for name in ("position", "look_at"):
            if name not in camera_values:
                r.fail("camera", "", f"[camera] needs {name}")
        position, look_at = (r.vector("camera", camera_values, k, 3) for k in ("position", "look_at"))
        camera = Camera(position, look_at)  # type: ignore[arg-type]
    view = r.table("view", ("map", "ellipses"))
    map_kind = r.string("view", view, "map", tuple(MAP_KINDS)) if "map" in view else "off"
    ellipses = view.get("ellipses", False)
    if not isinstance(ellipses, bool):
        r.fail("view", "ellipses", f"view.ellipses must be true or false, got {ellipses!r}")
    params = _params(r)
    motion, compare = _motion(r, path)
    pose = _pose(r)
    if motion is not None and pose:
        r.fail("pose", "", "give [pose] or [motion], not both (a motion starts at its first point)")
    if motion is None and not pose:
        r.fail("", "", "a lesson needs [pose] (p or d) or [motion]")
    demo = Demo(
        key=key,
        title=title,
        text=paragraphs["en"],
        camera=camera,
        params=params,
        motion=motion,
        map_kind=map_kind,
        ellipses=ellipses,
        compare=compare,
        texts=tuple((lang, t) for lang, t in paragraphs.items() if lang != "en"),
        checks=_checks(r),
        source=str(path),
        **pose,
    )
    _check_scene(r, demo)
    return demo


def _check_scene(r: _Reader, demo: Demo) -> None:
    """Refuse a pose or a motion that leaves the valid set (the same rules as a drag or an upload)."""
    params = demo_params(demo)
    where = ("motion", "") if demo.motion is not None else ("pose", "")
    try:
        pose = demo_pose(demo, params)
        source = demo_source(demo)
        if source is not None:
            t = np.linspace(0.0, source.duration, CHECK_SAMPLES)
            check_path(params, t, source.motion(t)[0], what="the motion")
        else:
            status = check(params, pose)
            if status:
                raise InputError(f"the pose: {why_not(params, status, pose.p, pose.d)}")
    except TpmVizError as exc:
        what = str(exc)
        r.fail(*where, what if what.startswith(("the pose", "the motion")) else f"the {where[0]}: {what}")


def load_lessons(directory) -> tuple[tuple[Demo, ...], tuple[str, ...]]:
    """Every ``*.toml`` lesson of ``directory`` (or the one lesson file it names) in file-name order, and one line
    ``file:line: what is wrong`` per file refused (the others still load). A key or a title used by an earlier file
    is refused too."""
    directory = pathlib.Path(directory)
    if directory.is_file() and directory.suffix == ".toml":
        files = [directory]  # one lesson file
    elif not directory.is_dir():
        return (), (f"{directory}: not a folder of lessons",)
    else:
        files = sorted(p for p in directory.glob("*.toml") if not p.name.startswith("."))  # no editor backups
    if not files:
        return (), (f"{directory}: no lesson files (*.toml)",)
    lessons: list[Demo] = []
    problems: list[str] = []
    for path in files:
        try:
            demo = load_lesson(path)
            for other in lessons:
                for what in ("key", "title"):
                    if getattr(other, what) == getattr(demo, what):
                        line = line_of(path.read_text(encoding="utf-8-sig"), "", what)
                        raise LessonError(f"{what} {getattr(demo, what)!r} is already used by {other.source}", line)
        except LessonError as exc:
            problems.append(f"{path}:{exc.line}: {exc}")
            continue
        lessons.append(demo)
    return tuple(lessons), tuple(problems)


def load_preset(path) -> Params:
    """A parameter preset (``assets/presets/*.toml``): ``name``, ``description`` and a ``[params]`` table of
    overrides of the paper's prototype in SI units; raises :class:`LessonError` (with the line) if refused."""
    path = pathlib.Path(path)
    text, data = _parse(path)
    r = _Reader(text, data)
    for key in data:
        if key not in ("name", "description", "params"):
            r.fail("", key, f"unknown key {key!r}; known: name, description, params")
    for key in ("name", "description"):
        if key in data:
            r.string("", data, key)
    return Params.paper().replace(**dict(_params(r)))
