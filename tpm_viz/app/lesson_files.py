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
import os
import pathlib
import re

import numpy as np

from tpm_viz.app.demos import CHECK_NAMES, LANGUAGES, Camera, Check, Demo, Motion, demo_params, demo_pose, demo_source
from tpm_viz.app.exercises.reader import key_lines, read_exercises
from tpm_viz.app.lesson_toml import MAX_FILE_BYTES, LessonError, Problem, Reader, line_of, parse
from tpm_viz.app.moves import check, why_not
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.app.readouts import reason
from tpm_viz.app.runs import check_path
from tpm_viz.core import files
from tpm_viz.core.errors import FileRefusedError, InputError, TpmVizError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.trajectories import parse_trajectory_csv

__all__ = ["MAX_FILE_BYTES", "LessonError", "assets_dir", "load_lesson", "load_lessons", "load_preset"]

MOTION_KINDS = ("line", "circle", "segment", "csv")
TOP_KEYS = ("key", "title", "text", "params", "pose", "motion", "camera", "view", "checks", "exercise")
CHECK_SAMPLES = 101
"""Samples at which a lesson's motion is checked when it is loaded."""


def assets_dir() -> pathlib.Path:
    """The folder of packaged data: the installed ``tpm_viz.assets``, else ``assets/`` beside the package in a
    source checkout whose editable install predates it."""
    spec = importlib.util.find_spec("tpm_viz.assets")
    if spec is not None and spec.submodule_search_locations:
        return pathlib.Path(next(iter(spec.submodule_search_locations)))
    return pathlib.Path(__file__).resolve().parents[2] / "assets"


def _params(r: Reader) -> tuple[tuple[str, float], ...]:
    values = r.table("params", tuple(PARAM_INFO))
    overrides = tuple((key, r.number("params", values, key)) for key in values)
    try:
        Params.paper().replace(**dict(overrides))
    except TpmVizError as exc:
        named = [key for key, _ in overrides if re.search(rf"\b{re.escape(key)}\b", str(exc))]
        r.fail("params", named[0] if named else "", Phrase("parameters refused: {why}", why=reason(exc)))
    return overrides


def _motion(r: Reader, path: pathlib.Path, root: pathlib.Path) -> tuple[Motion | None, tuple[float, ...]]:
    t = "motion"
    values = r.table(t, ("kind", "duration", "start", "end", "file", "compare"))
    if not values:
        return None, ()
    if "kind" not in values:
        r.fail(t, "", Phrase("[motion] needs kind"))
    kind = r.string(t, values, "kind", MOTION_KINDS)
    if "duration" not in values and kind != "csv":
        r.fail(t, "", Phrase("a {kind} motion needs motion.duration [s]", kind=kind))
    duration = r.number(t, values, "duration", 0.01, 100.0) if "duration" in values else math.nan
    compare: tuple[float, ...] = ()
    if "compare" in values:
        raw = values["compare"]
        if not isinstance(raw, list) or len(raw) != 2:
            r.fail(t, "compare", Phrase("motion.compare must be a list of 2 durations [s], got {got}", got=repr(raw)))
        compare = r.vector(t, values, "compare", 2)
        if not all(0.01 <= v <= 100.0 for v in compare):
            r.fail(
                t, "compare", Phrase("motion.compare durations must be from 0.01 to 100 s, got {got}", got=repr(raw))
            )
    needs = {"segment": ("start", "end"), "csv": ("file",)}.get(kind, ())
    for key in ("start", "end", "file"):
        if key in needs and key not in values:
            r.fail(t, "kind", Phrase("a {kind} motion needs motion.{key}", kind=kind, key=key))
        if key not in needs and key in values:
            r.fail(t, key, Phrase("motion.{key} does not apply to a {kind} motion", key=key, kind=kind))
    if kind == "segment":
        start, end = r.vector(t, values, "start", 2), r.vector(t, values, "end", 2)
        return Motion(kind, duration, start, end), compare  # type: ignore[arg-type]
    if kind == "csv":
        name = r.string(t, values, "file")
        try:
            csv = _lesson_csv(path.parent / name, root)
        except FileRefusedError as exc:
            r.fail(t, "file", Phrase("motion.file {name}: {why}", name=repr(name), why=exc.why))
        try:
            traj = parse_trajectory_csv(csv, name=pathlib.Path(name).stem)
        except TpmVizError as exc:
            r.fail(t, "file", Phrase("motion.file {name}: {why}", name=repr(name), why=reason(exc)))
        if math.isnan(duration):
            duration = traj.duration  # the file's own timing
        return Motion(kind, duration, file=name, trajectory=traj), compare
    return Motion(kind, duration), compare


def _lesson_csv(target: pathlib.Path, root: pathlib.Path) -> str:
    """The text of a lesson's CSV: a regular file inside the lessons folder ``root`` or the packaged
    ``trajectories/`` (never /dev/zero, a FIFO, /proc or /etc/passwd; a refusal quotes nothing of the file)."""
    try:
        return files.read_text(target, MAX_FILE_BYTES, root)
    except FileRefusedError:
        packaged = assets_dir() / "trajectories"
        try:
            return files.read_text(target, MAX_FILE_BYTES, packaged)
        except FileRefusedError:
            pass
        raise


def _pose(r: Reader) -> dict:
    values = r.table("pose", ("p", "d", "mode"))
    out: dict = {}
    if "p" in values and "d" in values:
        r.fail("pose", "d", Phrase("give pose.p (platform) or pose.d (actuators), not both"))
    if "p" in values:
        out["p"] = r.vector("pose", values, "p", 2)
    if "d" in values:
        out["d"] = r.vector("pose", values, "d", 2)
    if "mode" in values:
        if values["mode"] not in (1, -1) or isinstance(values["mode"], bool):
            r.fail("pose", "mode", Phrase("pose.mode must be 1 (working) or -1, got {got}", got=repr(values["mode"])))
        if "d" not in values:
            r.fail("pose", "mode", Phrase("pose.mode applies to pose.d only (pose.p is in the working mode)"))
        out["mode"] = values["mode"]
    return out


def _checks(r: Reader) -> tuple[Check, ...]:
    values = r.table("checks", tuple(CHECK_NAMES))
    out = []
    for name, value in values.items():
        if isinstance(value, dict):
            for key in value:
                if key not in ("value", "tol"):
                    r.fail(
                        "checks",
                        name,
                        Phrase("checks.{name}: unknown key {key}; known: value, tol", name=name, key=repr(key)),
                    )
            if "value" not in value:
                r.fail("checks", name, Phrase("checks.{name} needs a value", name=name))
            stated = r.number("checks", value, "value")
            tol = r.number("checks", value, "tol", 0.0) if "tol" in value else None
            out.append(Check(name, stated, tol))
        else:
            out.append(Check(name, r.number("checks", values, name)))
    return tuple(out)


def _key_of(path: pathlib.Path) -> str:
    """``01-direct.toml`` -> ``direct``."""
    return re.sub(r"^[0-9]+[-_ .]*", "", path.stem) or path.stem


def load_lesson(path: str | os.PathLike[str], root: str | os.PathLike[str] | None = None) -> Demo:
    """One lesson file (raises :class:`LessonError`; its ``line`` says where). It and the CSV file it names must be
    regular files inside ``root`` (default: the lesson's own folder), read by :mod:`tpm_viz.core.files`."""
    path = pathlib.Path(path)
    root = path.parent if root is None else pathlib.Path(root)
    text, data = parse(path, root)
    r = Reader(text, data)
    for key in data:
        if key not in TOP_KEYS:
            r.fail("", key, Phrase("unknown key {key}; known: {known}", key=repr(key), known=", ".join(TOP_KEYS)))
    if "title" not in data:
        r.fail("", "", Phrase("missing title"))
    title = r.string("", data, "title")
    key = r.string("", data, "key") if "key" in data else _key_of(path)
    if isinstance(data.get("text"), str):
        r.fail("", "text", Phrase('text must be a table of languages: [text] en = "..."'))
    texts = r.table("text", LANGUAGES, required=True)
    if "en" not in texts:
        r.fail("text", "", Phrase("missing text.en (the English paragraph)"))
    paragraphs = {lang: " ".join(r.string("text", texts, lang).split()) for lang in texts}
    camera_values = r.table("camera", ("position", "look_at"))
    camera = None
    if camera_values:
        for name in ("position", "look_at"):
            if name not in camera_values:
                r.fail("camera", "", Phrase("[camera] needs {name}", name=name))
        position, look_at = (r.vector("camera", camera_values, k, 3) for k in ("position", "look_at"))
        camera = Camera(position, look_at)  # type: ignore[arg-type]
    view = r.table("view", ("map", "ellipses"))
    map_kind = r.string("view", view, "map", tuple(MAP_KINDS)) if "map" in view else "off"
    ellipses = view.get("ellipses", False)
    if not isinstance(ellipses, bool):
        r.fail("view", "ellipses", Phrase("view.ellipses must be true or false, got {got}", got=repr(ellipses)))
    params = _params(r)
    motion, compare = _motion(r, path, root)
    pose = _pose(r)
    if motion is not None and pose:
        r.fail("pose", "", Phrase("give [pose] or [motion], not both (a motion starts at its first point)"))
    if motion is None and not pose:
        r.fail("", "", Phrase("a lesson needs [pose] (p or d) or [motion]"))
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
        exercises=read_exercises(text, data, key, params, str(path)),
        **pose,
    )
    _check_scene(r, demo)
    return demo


def _check_scene(r: Reader, demo: Demo) -> None:
    """Refuse a pose or a motion that leaves the valid set (the same rules as a drag or an upload)."""
    params = demo_params(demo)
    where = ("motion", "") if demo.motion is not None else ("pose", "")
    try:
        pose = demo_pose(demo, params)
        source = demo_source(demo)
        if source is not None:
            t = np.linspace(0.0, source.duration, CHECK_SAMPLES)
            check_path(params, t, source.motion(t)[0], what=T("the motion"))
        else:
            status = check(params, pose)
            if status:
                raise InputError(Phrase("the pose: {why}", why=why_not(params, status, pose.p, pose.d)))
    except TpmVizError as exc:
        why = reason(exc)
        if str(why).startswith(("the pose", "the motion")):
            r.fail(*where, why)
        r.fail(
            *where,
            Phrase("the motion: {why}", why=why) if demo.motion is not None else Phrase("the pose: {why}", why=why),
        )


def load_lessons(directory: str | os.PathLike[str]) -> tuple[tuple[Demo, ...], tuple[Problem, ...]]:
    """Every ``*.toml`` lesson of ``directory`` (or the one lesson file it names) in file-name order, and one line
    ``file:line: what is wrong`` per file refused (the others still load). A key or a title used by an earlier file
    is refused too."""
    directory = pathlib.Path(directory)
    if directory.is_file() and directory.suffix == ".toml":
        paths, root = [directory], directory.parent  # one lesson file
    elif not directory.is_dir():
        return (), (Problem(Phrase("{path}: not a folder of lessons", path=str(directory))),)
    else:
        paths, root = sorted(p for p in directory.glob("*.toml") if not p.name.startswith(".")), directory  # no backups
    if not paths:
        return (), (Problem(Phrase("{path}: no lesson files (*.toml)", path=str(directory))),)
    lessons: list[Demo] = []
    problems: list[Problem] = []
    for path in paths:
        try:
            demo = load_lesson(path, root)
            for other in lessons:
                _same_exercise(path, root, other, demo)
                for what in ("key", "title"):
                    if getattr(other, what) == getattr(demo, what):
                        line = line_of(parse(path, root)[0], "", what)
                        raise LessonError(
                            Phrase(
                                "{what} {value} is already used by {other}",
                                what=what,
                                value=repr(getattr(demo, what)),
                                other=other.source,
                            ),
                            line,
                        )
        except LessonError as exc:
            problems.append(Problem(Phrase("{path}:{line}: {why}", path=str(path), line=exc.line, why=reason(exc))))
            continue
        lessons.append(demo)
    return tuple(lessons), tuple(problems)


def _same_exercise(path: pathlib.Path, root: pathlib.Path, other: Demo, demo: Demo) -> None:
    """Refuse an exercise id that an earlier lesson file already uses (ids are unique in a folder)."""
    used = {e.id for e in other.exercises}
    for index, exercise in enumerate(demo.exercises):
        if exercise.id in used:
            line = key_lines(parse(path, root)[0]).get(("exercise", index, "id"), 1)
            raise LessonError(
                Phrase("exercise id {id} is already used by {other}", id=repr(exercise.id), other=other.source), line
            )


def load_preset(path: str | os.PathLike[str]) -> Params:
    """A parameter preset (``assets/presets/*.toml``): ``name``, ``description`` and a ``[params]`` table of
    overrides of the paper's prototype in SI units; raises :class:`LessonError` (with the line) if refused."""
    path = pathlib.Path(path)
    text, data = parse(path)
    r = Reader(text, data)
    for key in data:
        if key not in ("name", "description", "params"):
            r.fail("", key, Phrase("unknown key {key}; known: name, description, params", key=repr(key)))
    for key in ("name", "description"):
        if key in data:
            r.string("", data, key)
    return Params.paper().replace(**dict(_params(r)))
