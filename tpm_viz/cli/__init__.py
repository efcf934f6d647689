"""The ``tpm-viz`` command line: CSV in, CSV out, SI units. Bad input exits with status 2 and one line on stderr.

One module per family of subcommands, each with a ``register(subparsers, common)``:

- :mod:`.paper`: ``kinematics``, ``dynamics``, ``trajectory`` (the paper's closed form);
- :mod:`.multibody`: ``replay``, ``crosscheck``, ``figures`` (the Pinocchio model);
- :mod:`.serve`: ``serve`` (the browser app; ``--lti``: as an LTI 1.3 tool of an LMS);
- :mod:`.lti`: ``lti keygen`` (the LTI tool's key);
- :mod:`.plan`: ``plan`` (minimum-time timing within force limits) and ``size`` (the motors a motion needs);
- :mod:`.control`: ``control`` (a controller tracking a trajectory on the Pinocchio plant);
- :mod:`.export`: ``export`` (the model as MJCF or URDF);
- :mod:`.outputs`: ``clip`` (an animated GIF or MP4 of a run) and ``report`` (a self-contained HTML lab report);
- :mod:`.design`: ``design``, ``compare``, ``atlas`` (design indices over a task, the two arrangements, sweeps);
- :mod:`.exercise`: ``exercise`` (the lessons' exercises: list, show a variant, grade an answer, selftest);
- :mod:`.page`: ``page`` (a lesson to take home: one offline HTML page, or a SCORM 1.2 package);
- :mod:`.docs`: ``docs`` (the docs site, built and served on 127.0.0.1).

Import rule (checked by ``tests/test_layering.py``): the command line may import every layer and nothing imports
it (except ``__main__``).
"""

from __future__ import annotations

import csv
import sys

from tpm_viz.cli import control, design, docs, exercise, export, lti, multibody, outputs, page, paper, plan, serve
from tpm_viz.cli.common import Parser, check_outputs, common_parent, one_line, params_from_args
from tpm_viz.core.errors import TpmVizError

__all__ = ["build_parser", "main", "params_from_args"]


def build_parser() -> Parser:
    """The ``tpm-viz`` argument parser with every subcommand."""
    parser = Parser(prog="tpm-viz", description=(__doc__ or "").splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    common = common_parent()
    for family in (paper, serve, lti, multibody, control, plan, export, outputs, design, exercise, page, docs):
        family.register(sub, common)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``tpm-viz``; returns the exit status (2 for bad input)."""
    try:
        args = build_parser().parse_args(argv)
        check_outputs(args)  # a device, FIFO or folder as --output: refused before any work
        return int(args.func(args) or 0)
    except TpmVizError as exc:
        print(f"tpm-viz: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(one_line(f"tpm-viz: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": ")), file=sys.stderr)
        return 2
    except UnicodeDecodeError as exc:
        print(
            f"tpm-viz: error: the input is not text in a known encoding (save it as UTF-8): {exc.reason}",
            file=sys.stderr,
        )
        return 2
    except (OverflowError, csv.Error) as exc:
        print(one_line(f"tpm-viz: error: a number or a CSV cell is out of range: {exc}"), file=sys.stderr)
        return 2
    except MemoryError:
        print("tpm-viz: error: out of memory: the input is too large; split it", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
