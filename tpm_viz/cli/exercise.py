"""``tpm-viz exercise``: the exercises of the lessons and their grader on the command line (``docs/exercises.md``).

- ``exercise list [--lesson N]``: CSV ``id,lesson,kind,unit,title`` on stdout;
- ``exercise show ID --seed S [--reveal] [--lang en|ko]``: one JSON object ``{"id", "lesson", "kind", "unit",
  "rtol", "atol", "params", "prompt"}`` (``params``: the variant's values in SI under the command line's names;
  ``rtol``/``atol`` null where they do not apply; a pose's ``atol`` is the force tolerance in N); ``--reveal``
  adds ``"answer"``: the reference as a list of numbers in the exercise's unit (a pose: ``[p1, p2]`` in mm that
  passes; gains: ``[omega_n_hz, zeta]``; a choice: ``[option number]``);
- ``exercise grade ID --seed S --answer TEXT [--attempt K] [--lang en|ko]``: one JSON object ``{"score",
  "format_error", "feedback", "attempts_used"}`` (a format error: score null, ``attempts_used`` 0; else the score
  after the attempt ladder for attempt K). Exit 0 for any answer, graded or not; 2 for an unknown id, a bad seed,
  a bad attempt or flag. An answer that starts with ``-`` is written ``--answer=-35;20``.
- ``exercise selftest [--variants N]``: for every exercise and the seeds ``0 .. N-1``, one CSV row
  ``id,variants,reference_ok,perturbed_ok,format_ok,p95_ms`` (:mod:`tpm_viz.app.exercises.selftest`); the failures
  on stderr; exit 1 if any fails.

``--lessons DIR`` reads a lecturer's folder of lesson files instead of the packaged tour (a refused file is named on
stderr; the selftest then fails). The engine (:mod:`tpm_viz.app.exercises`) is imported by the handlers.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys

from tpm_viz.cli.common import within
from tpm_viz.core.errors import InputError

__all__ = ["MAX_VARIANTS", "register"]

MAX_VARIANTS = 1000
"""Most variants the selftest runs per exercise."""


def _lessons(args: argparse.Namespace, strict: bool = False):  # -> tuple[Demo, ...]
    from tpm_viz.app.lessons import DEMOS, load_lessons

    if args.lessons is None:
        return DEMOS, ()
    lessons, problems = load_lessons(args.lessons)
    if not lessons and not strict:  # nothing to list, show or grade (selftest reports it as a failure)
        raise InputError(str(problems[0]) if problems else f"{args.lessons}: no lesson files (*.toml)")
    for problem in problems:
        print(f"tpm-viz: {'error' if strict else 'warning'}: {problem}", file=sys.stderr)
    return lessons, problems


def _lang(args: argparse.Namespace):
    from tpm_viz.core.words import Lang

    return Lang.parse(args.lang)


def _cmd_list(args: argparse.Namespace) -> int:
    from tpm_viz.app.exercises.catalogue import listed

    if args.lesson is not None:
        within(args.lesson, "--lesson", 1, 1000)
    lessons, _ = _lessons(args)
    writer = csv.writer(sys.stdout, lineterminator="\n")
    writer.writerow(["id", "lesson", "kind", "unit", "title"])
    for item in listed(lessons, args.lesson):
        ex = item.exercise
        writer.writerow([ex.id, item.lesson_number, ex.kind.value, ex.unit, ex.title.get(_lang(args))])
    return 0


def _found(args: argparse.Namespace):
    from tpm_viz.app.exercises.catalogue import by_id
    from tpm_viz.app.exercises.grading import variant_of
    from tpm_viz.app.exercises.variants import parse_seed

    lessons, _ = _lessons(args)
    item = by_id(args.id, lessons)
    return item, variant_of(item.exercise, parse_seed(args.seed))


def _cmd_show(args: argparse.Namespace) -> int:
    from tpm_viz.app.exercises.grading import prompt, reference, tolerance
    from tpm_viz.app.exercises.model import Kind
    from tpm_viz.core.words import Phrase

    item, variant = _found(args)
    ex, lang = item.exercise, _lang(args)
    text = prompt(ex, variant).render(lang)
    if ex.options:
        listed = ", ".join(f"{n} = {o.label.get(lang)}" for n, o in enumerate(ex.options, 1))
        text = f"{text} {Phrase('Options: {options}.', options=listed).render(lang)}"
    tolerant = ex.kind in (Kind.NUMBER, Kind.POSE)
    rtol, atol = tolerance(ex, variant) if tolerant else (None, None)
    out: dict[str, object] = {
        "id": ex.id,
        "lesson": item.lesson_number,
        "kind": ex.kind.value,
        "unit": ex.unit,
        "rtol": rtol,
        "atol": atol,
        "params": variant.values(),
        "prompt": text,
    }
    if args.reveal:
        ref = reference(ex, variant)
        keys = [o.key for o in ex.options]
        out["answer"] = [keys.index(ref) + 1] if isinstance(ref, str) else [float(x) for x in ref]
    print(json.dumps(out, ensure_ascii=False))
    return 0


def _cmd_grade(args: argparse.Namespace) -> int:
    from tpm_viz.app.exercises.grading import grade

    item, variant = _found(args)
    result = grade(item.exercise, variant, args.answer, args.attempt)
    print(json.dumps(result.json(_lang(args)), ensure_ascii=False))
    return 0


def _cmd_selftest(args: argparse.Namespace) -> int:
    from tpm_viz.app.exercises.catalogue import listed
    from tpm_viz.app.exercises.selftest import COLUMNS, selftest

    within(args.variants, "--variants", 1, MAX_VARIANTS)
    lessons, problems = _lessons(args, strict=True)
    writer = csv.writer(sys.stdout, lineterminator="\n")
    writer.writerow(COLUMNS)
    ok = not problems
    for item in listed(lessons):
        row = selftest(item.exercise, args.variants)
        writer.writerow(row.cells())
        sys.stdout.flush()
        for failure in row.failures:
            print(f"tpm-viz: {row.id}: {failure}", file=sys.stderr)
        ok = ok and row.ok
    return 0 if ok else 1


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``exercise`` (with ``list``, ``show``, ``grade``, ``selftest``) to the ``tpm-viz`` subparsers."""
    del common_parent  # exercises carry their own parameters
    e = subparsers.add_parser(
        "exercise",
        help="the lessons' exercises: list, show a variant, grade an answer, run the grader's selftest",
        description="Exercises of the lessons (assets/lessons/*.toml), a variant per seed, graded with "
        "PrairieLearn's semantics (docs/exercises.md). JSON or CSV on stdout.",
    )
    sub = e.add_subparsers(dest="action", required=True, parser_class=type(e))
    lessons = argparse.ArgumentParser(add_help=False)
    lessons.add_argument("--lessons", metavar="DIR", help="a folder of lesson files (default: the packaged tour)")
    lang = argparse.ArgumentParser(add_help=False)
    lang.add_argument("--lang", choices=["en", "ko"], default="en", help="language of the texts (en)")
    seeded = argparse.ArgumentParser(add_help=False)
    seeded.add_argument("id", metavar="ID", help="the exercise's id (tpm-viz exercise list)")
    seeded.add_argument("--seed", required=True, metavar="S", help="the variant's seed, 0 to 2^53 - 1")

    c = sub.add_parser("list", parents=[lessons, lang], help="CSV: id,lesson,kind,unit,title")
    c.add_argument("--lesson", type=int, metavar="N", help="only the exercises of lesson N (1-based)")
    c.set_defaults(func=_cmd_list)

    c = sub.add_parser("show", parents=[seeded, lessons, lang], help="JSON: a variant, its prompt, its numbers")
    c.add_argument("--reveal", action="store_true", help="add the reference answer")
    c.set_defaults(func=_cmd_show)

    c = sub.add_parser("grade", parents=[seeded, lessons, lang], help="JSON: the grade of one answer")
    c.add_argument("--answer", required=True, metavar="TEXT", help="the answer as typed (--answer=-35;20 for a minus)")
    c.add_argument("--attempt", type=int, default=1, metavar="K", help="the counted attempt it is (1)")
    c.set_defaults(func=_cmd_grade)

    c = sub.add_parser("selftest", parents=[lessons], help="CSV: the grader on N variants of every exercise")
    c.add_argument("--variants", type=int, default=20, metavar="N", help="variants per exercise (20)")
    c.set_defaults(func=_cmd_selftest)
