"""``tpm-viz page``: a lesson to take home, as one offline HTML page and/or a SCORM 1.2 package (``docs/takehome.md``).

``tpm-viz page --lesson N --output FILE.html [--lang en|ko] [--seed S] [--set NAME=VALUE ...] [--scorm FILE.zip]
[--lessons DIR]`` writes the page of lesson ``N`` (the number that prefixes its file name: ``03-speed.toml`` is 3):
the lesson's motion in 3D (viser's client with a recording, :mod:`tpm_viz.ui.takehome`), its text, the calculator
(the closed form as WebAssembly, :mod:`tpm_viz.exchange.c.calculator`) and its exercises graded in the page for the
variant ``S`` (default 0), assembled by :mod:`tpm_viz.media.page_html`. ``--scorm`` writes the same page in a SCORM 1.2
package (:mod:`tpm_viz.media.scorm`); give ``--output``, ``--scorm`` or both. ``--set`` changes the lesson's
mechanism (SI units, over the lesson's own parameters; the exercises keep their variants). Each file is replaced
atomically; one line per file on stdout: its path and size in bytes. A bad lesson number or option: exit 2 with one
line. viser, the recording and the compiler-free calculator are imported by the handler.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from tpm_viz.cli.common import one_line
from tpm_viz.core.errors import InputError

__all__ = ["register"]


def _lessons(args: argparse.Namespace):  # -> tuple[Demo, ...]
    from tpm_viz.app.lessons import DEMOS, load_lessons

    if args.lessons is None:
        return DEMOS
    lessons, problems = load_lessons(args.lessons)
    if not lessons:
        raise InputError(problems[0] if problems else f"--lessons {args.lessons}: no lesson files in that folder")
    for problem in problems:
        print(f"tpm-viz: warning: {one_line(str(problem))}", file=sys.stderr)
    return lessons


def _number(source: str, place: int) -> int:
    """A lesson's number: the digits that start its file name, else its place in the tour."""
    found = re.match(r"\d+", Path(source).name) if source else None
    return int(found.group()) if found else place


def _lesson(lessons, wanted: int):  # -> tuple[int, Demo]
    numbered = [(_number(demo.source, place), demo) for place, demo in enumerate(lessons, 1)]
    for number, demo in numbered:
        if number == wanted:
            return number, demo
    known = ", ".join(str(number) for number, _ in numbered) or "none"
    raise InputError(f"--lesson {wanted}: no lesson has that number; lessons: {known}")


def _params(demo, args: argparse.Namespace):  # -> Params
    """The lesson's mechanism with ``--set NAME=VALUE`` over it (numbers as typed, SI units)."""
    from tpm_viz.app.demos import demo_params
    from tpm_viz.core.numbers import parse_number
    from tpm_viz.core.params import PARAM_INFO

    overrides: dict[str, str] = {}
    for item in args.set or []:
        name, sep, value = item.partition("=")
        if not sep:
            raise InputError(f"--set expects NAME=VALUE, got {item!r}")
        name = name.strip()
        info = PARAM_INFO.get(name)
        overrides[name] = str(parse_number(value, name, info.get("unit", ""))) if info else value.strip()
    return demo_params(demo).with_overrides(overrides)


def _cmd_page(args: argparse.Namespace) -> int:
    from tpm_viz.app.exercises.variants import parse_seed
    from tpm_viz.cli.outputs import write_bytes
    from tpm_viz.core.params import PARAM_INFO
    from tpm_viz.core.words import Lang
    from tpm_viz.exchange.c.calculator import calculator_assets
    from tpm_viz.media.page_exercises import lesson_exercises
    from tpm_viz.media.page_html import PageContent, lesson_page, version
    from tpm_viz.media.scorm import scorm_package
    from tpm_viz.ui.takehome import record_lesson

    if args.output is None and args.scorm is None:
        raise InputError("give --output FILE.html, --scorm FILE.zip or both")
    if args.lesson is None or not 0 <= args.lesson <= 10**6:
        raise InputError(f"--lesson must be a lesson number, got {args.lesson}")
    lang, seed = Lang.parse(args.lang), parse_seed(args.seed)
    number, demo = _lesson(_lessons(args), args.lesson)
    params = _params(demo, args)
    exercises = lesson_exercises(demo.exercises, seed, lang)  # before the recording: a seed without variant fails fast
    recording = record_lesson(demo, params)
    content = PageContent(
        lang=lang,
        seed=seed,
        number=number,
        key=demo.key,
        title=demo.title,
        text=demo.text_in(lang.value),
        viser_html=recording.html,
        calculator=calculator_assets().html(),
        params={name: float(getattr(params, name)) for name in PARAM_INFO},
        frames={
            "t": recording.t.tolist(),
            "p": recording.p.tolist(),
            "dp": recording.dp.tolist(),
            "ddp": recording.ddp.tolist(),
        },
        exercises=exercises,
        version=version(),
    )
    page = lesson_page(content).encode("utf-8")
    outputs = []
    if args.output is not None:
        outputs.append((args.output, page))
    if args.scorm is not None:
        outputs.append((args.scorm, scorm_package(page.decode("utf-8"), demo.title, f"{number:02d}-{demo.key}-{seed}")))
    for path, data in outputs:
        write_bytes(path, data)
        print(f"{path}: {len(data)} bytes")
    return 0


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``page`` to the ``tpm-viz`` subparsers (``common_parent`` provides ``--set``)."""
    p = subparsers.add_parser(
        "page",
        parents=[common_parent],
        help="a lesson to take home: one offline HTML page (3D motion, text, calculator, exercises) or SCORM 1.2",
        description="One self-contained HTML page per lesson that opens from disk with no server and no network: "
        "the lesson's motion in 3D (viser's player), its text, a calculator of the closed form (WebAssembly) and "
        "its exercises graded in the page for the variant --seed. --scorm packages the same page for an LMS.",
    )
    p.add_argument("--lesson", type=int, required=True, metavar="N", help="the lesson: its file's number (03-... is 3)")
    p.add_argument("--output", metavar="FILE.html", help="the page (replaced atomically)")
    p.add_argument("--scorm", metavar="FILE.zip", help="the page as a SCORM 1.2 package (replaced atomically)")
    p.add_argument("--lang", choices=["en", "ko"], default="en", help="language of the page (en)")
    p.add_argument("--seed", default="0", metavar="S", help="the exercises' variant, 0 to 2^53 - 1 (0)")
    p.add_argument("--lessons", metavar="DIR", help="a folder of lesson files (default: the packaged tour)")
    p.set_defaults(func=_cmd_page)
