"""``tpm-viz design | compare | atlas``: design indices of one design, the two arrangements compared, an atlas.

:func:`register` adds the subcommands (:mod:`tpm_viz.cli`). The design modules (toppra, which loads matplotlib;
scipy; Dask for ``--scheduler``) are imported by the handler that runs. CSV out, SI units; an infeasible design
has empty index cells (never NaN); ``compare`` shows a terminal a table in mm, N, kg, s instead
(:mod:`tpm_viz.design.compare_text`), its searches' progress on stderr. Definitions: ``docs/design.md``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from tpm_viz.cli.common import params_from_args, write_output
from tpm_viz.core.errors import InputError

__all__ = ["register"]

ARRANGEMENTS = ("perpendicular", "parallel")


def _settings(args):
    from tpm_viz.design.indices import Settings  # toppra (matplotlib): only for these commands

    force = args.force_limit
    if not (math.isfinite(force) and 1e-6 <= force <= 1e9):
        raise InputError(f"--force-limit must be a positive number of newtons up to 1e9, got {force:g}")
    if not 10 <= args.grid <= 20_000:
        raise InputError(f"--grid must be a whole number of points from 10 to 20000, got {args.grid}")
    return Settings(force_limit=force, planner_grid=args.grid, pick=args.pick)


def _table(rows: list[dict], columns: list[str]) -> dict[str, np.ndarray]:
    """Rows as CSV columns: text columns as text, numbers as floats (NaN, i.e. missing, as an empty cell)."""
    out: dict[str, np.ndarray] = {}
    for name in columns:
        values = [row.get(name, math.nan) for row in rows]
        if name in ("arrangement", "case", "tag"):
            out[name] = np.array([str(v) for v in values], dtype=object)
        elif name in ("feasible", "pareto"):
            out[name] = np.array([int(bool(v)) for v in values], dtype=np.int64)
        else:
            cells = [float(v) for v in values]
            feasible = [bool(row.get("feasible", True)) for row in rows]
            keep = name in ("a", "b", "l_a", "stroke", "m_a", "m_b", "m_p")
            out[name] = np.array([v if keep or ok else math.nan for v, ok in zip(cells, feasible, strict=True)])
    return out


def _cmd_design(args) -> int:
    from tpm_viz.design.atlas import PARAMETER_COLUMNS, design_row, values_of
    from tpm_viz.design.indices import INDEX_COLUMNS, Task

    task = Task.parse(args.task)
    params = params_from_args(args)
    row = design_row(args.arrangement, values_of(params), {}, (task.x0, task.x1, task.y0, task.y1), _settings(args))
    write_output(args.output, _table([row], [*PARAMETER_COLUMNS, *INDEX_COLUMNS]))
    if not row["feasible"]:
        print(f"tpm-viz: infeasible: {row['why']}", file=sys.stderr)
    return 0


def _search(args):
    from tpm_viz.design.optimum import Search

    if not 0 <= args.seed < 2**32:
        raise InputError(f"--seed must be a whole number from 0 to 4294967295, got {args.seed}")
    if not 1 <= args.generations <= 10_000:
        raise InputError(f"--generations must be a whole number from 1 to 10000, got {args.generations}")
    return Search(seed=args.seed, generations=args.generations)


def _cmd_compare(args) -> int:
    """The comparison: a table for people when stdout is a terminal (as well as the CSV when ``--output FILE``), the
    CSV on stdout otherwise; the searches' progress on stderr."""
    from tpm_viz.design.compare import COMPARE_COLUMNS, Hold, compare, populations
    from tpm_viz.design.compare_text import compare_text
    from tpm_viz.design.indices import Task
    from tpm_viz.design.tally import Tally

    task, hold, params = Task.parse(args.task), Hold.parse(args.hold), params_from_args(args)
    settings, how = _settings(args), _search(args)
    progress = _Progress(0)
    tally = Tally(populations(params, hold, how), how, progress)
    progress(0, tally.total)
    try:
        rows = compare(params, task, hold, settings, how, evaluate=tally)
        tally.finish()
    finally:
        progress.close()  # an error's line (or ^C) starts on a line of its own
    people = args.output != "-" and sys.stdout.isatty()
    if args.output not in (None, "-") or not people:
        write_output(args.output, _table(rows, list(COMPARE_COLUMNS)))
    if people:
        print(compare_text(rows, hold, task, settings, how))
    return 0


class _Progress:
    """A progress bar on stderr: redrawn in place on a terminal (when the percentage changes), one line per tenth
    otherwise."""

    def __init__(self, total: int) -> None:
        self.total, self.start, self.shown, self.width = total, time.monotonic(), -1, 0
        self.tty = sys.stderr.isatty()

    def __call__(self, done: int, total: int) -> None:
        step = (100 if self.tty else 10) * done // max(total, 1)
        if step == self.shown and done < total:
            return
        self.shown = step
        rate = done / max(time.monotonic() - self.start, 1e-9)
        bar = "#" * (30 * done // max(total, 1))
        text = f"[{bar:<30}] {done}/{total} designs, {rate:.1f} designs/s"
        end = "\n" if (not self.tty or done >= total) else ""
        sys.stderr.write(f"\r{text:<{self.width}}{end}" if self.tty else f"{text}{end}")
        self.width = 0 if end else len(text)
        sys.stderr.flush()

    def close(self) -> None:
        """End a bar left drawn in place (the work stopped before its end)."""
        if self.width:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.width = 0


def _footprint_limit(text: str | None) -> tuple[float | None, float | None]:
    if text is None:
        return None, None
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--footprint expects X,Y in metres (e.g. 0.6,0.6), got {text[:40]!r}") from None
    if not all(math.isfinite(v) and v > 0 for v in (x, y)):
        raise InputError("--footprint X,Y must be positive numbers of metres")
    return x, y


def _cmd_atlas(args) -> int:
    from tpm_viz.core.params import Params
    from tpm_viz.design.atlas import Limits, Vary, best, columns_for, design_row, designs, pareto, sweep
    from tpm_viz.design.atlas import values_of as values
    from tpm_viz.design.indices import Task
    from tpm_viz.design.optimum import search
    from tpm_viz.paper.arrangement import Arrangement

    task = Task.parse(args.task)
    settings = _settings(args)
    how = _search(args)
    varies = [Vary.parse(text) for text in args.vary]
    grid = designs(varies)
    base = params_from_args(args)
    limits = Limits(*_footprint_limit(args.footprint))
    if args.workers is not None and not 1 <= args.workers <= 1024:
        raise InputError(f"--workers must be from 1 to 1024, got {args.workers}")
    arrangement = Arrangement.parse(args.arrangement)
    progress = _Progress(len(grid))
    if args.scheduler:
        try:
            from tpm_viz.design.cluster import sweep_on_cluster  # Dask: the optional extra .[cluster]
        except ImportError:
            raise InputError("--scheduler needs Dask: pip install 'tpm-viz[cluster]'") from None
        rows = sweep_on_cluster(args.scheduler, arrangement, base, grid, task, settings, progress)
    else:
        rows = sweep(arrangement, base, grid, task, settings, args.workers, progress)
    front = pareto(rows)
    for row, on in zip(rows, front, strict=True):
        row["pareto"], row["tag"] = bool(on), ""
    key = (task.x0, task.x1, task.y0, task.y1)
    prototype = design_row(arrangement.value, values(Params.paper()), {}, key, settings)
    prototype.update(pareto=False, tag="prototype")
    rows.append(prototype)
    k = best(rows[:-1], limits)
    if k is not None and not args.no_optimum:
        bounds = {v.name: (min(v.start, v.stop), max(v.start, v.stop)) for v in varies if v.count > 1}
        start = {name: float(rows[k][name]) for name in bounds}
        found = (
            search(arrangement, values(base), bounds, task, settings, limits, how=how, starts=[start])
            if bounds
            else None
        )
        rows.append({**(found or rows[k]), "pareto": False, "tag": "optimum"})
    feasible = sum(bool(r["feasible"]) for r in rows[: len(grid)])
    write_output(args.output, _table(rows, [*columns_for(v.name for v in varies), "pareto", "tag"]))
    summary = f"{len(grid)} designs, {feasible} feasible, {int(front.sum())} on the Pareto front"
    if k is None:
        summary += "; no feasible design within the limits, no optimum"
    elif not args.no_optimum:
        opt = rows[-1]
        summary += (
            f"; optimum cycle {float(opt['cycle_time']):.4f} s (best grid point {float(rows[k]['cycle_time']):.4f} s)"
        )
    print(summary, file=sys.stderr)
    return 0


def _common_design(p: argparse.ArgumentParser, grid: int = 300) -> None:
    p.add_argument(
        "--task", required=True, metavar="X0,X1,Y0,Y1", help="task rectangle [m]; negative values: --task=-0.1,..."
    )
    p.add_argument("--force-limit", type=float, default=100.0, metavar="N", help="|tau_i| <= N for the cycle time")
    p.add_argument("--grid", type=int, default=grid, metavar="K", help=f"planner grid points (default {grid})")
    p.add_argument(
        "--pick",
        choices=("x", "y"),
        default="x",
        help="the standard pick runs across the task's width (x, default) or along its height (y)",
    )


def _common_search(p: argparse.ArgumentParser) -> None:
    p.add_argument("--seed", type=int, default=0, metavar="N", help="seed of the optimiser's search (default 0)")
    p.add_argument(
        "--generations",
        type=int,
        default=100,
        metavar="K",
        help="most generations of differential evolution (default 100; 15 designs per free variable each)",
    )


def register(sub, common) -> None:
    """Add ``design``, ``compare`` and ``atlas`` to the ``tpm-viz`` subparsers."""
    de = sub.add_parser(
        "design",
        parents=[common],
        help="design indices over a task rectangle (feasible, GCI, cond, dynamic index, cycle time, footprint)",
    )
    de.add_argument("--arrangement", choices=ARRANGEMENTS, default="perpendicular")
    _common_design(de)
    de.add_argument("--output", metavar="FILE", help="CSV out (default stdout)")
    de.set_defaults(func=_cmd_design)
    co = sub.add_parser(
        "compare",
        parents=[common],
        help="perpendicular vs parallel at the given dimensions and at each one's optimum, holding one thing equal",
    )
    _common_design(co)
    co.add_argument("--hold", choices=("link", "footprint", "mass"), default="link")
    _common_search(co)
    co.add_argument(
        "--output",
        metavar="FILE",
        help="CSV out, SI (default: stdout when piped; a terminal gets a table in mm, N, kg, s; - forces the CSV)",
    )
    co.set_defaults(func=_cmd_compare)
    at = sub.add_parser(
        "atlas", parents=[common], help="indices of a grid of designs, Pareto front, best design under constraints"
    )
    at.add_argument("--arrangement", choices=ARRANGEMENTS, default="perpendicular")
    at.add_argument("--vary", action="append", required=True, metavar="NAME=START:STOP:COUNT")
    _common_design(at, grid=100)  # cycle times within 1.4 % (docs/design.md), 10,000 designs in minutes
    at.add_argument("--output", required=True, metavar="FILE")
    at.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="processes for the grid (default: every core; never more than the cores or the chunks of 8 designs)",
    )
    at.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="run on this Dask distributed scheduler")
    at.add_argument("--footprint", metavar="X,Y", help="largest footprint [m] of the best design")
    at.add_argument("--no-optimum", action="store_true", help="skip the optimiser")
    _common_search(at)
    at.set_defaults(func=_cmd_atlas)
