"""``tpm-viz clip | report``: a run taken out of the room, as an animated clip or a self-contained lab report.

:func:`register` adds the subcommands to the ``tpm-viz`` parser (:mod:`tpm_viz.cli`). The run is the app's
(:func:`tpm_viz.app.runs.build_run`: the paper's line or circle, or a CSV ``t,p1,p2`` followed through its spline,
checked sample by sample); matplotlib, PyAV and Pinocchio are imported by the handler that runs. Files are replaced
atomically; bad input raises :class:`~tpm_viz.core.errors.TpmVizError` (``cli.main`` prints one line, exits with 2).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import sys

from tpm_viz.app.runs import MAX_DURATION, RUN_SAMPLES, Run, Source, build_run
from tpm_viz.cli.common import check_output, params_from_args
from tpm_viz.core.csvio import read_text
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import write_atomically
from tpm_viz.media.clipopts import FORMATS, check_fps, parse_size
from tpm_viz.paper.trajectories import parse_trajectory_csv

__all__ = ["MAX_SAMPLES", "register", "run_from_args", "write_bytes"]

MAX_SAMPLES = 2001
"""Most samples of a run on the command line (a clip has one frame per sample)."""


def run_from_args(args: argparse.Namespace, reference=None) -> Run:
    """The run of ``--trajectory line|circle|FILE [--duration T] [--samples N] [--set ...]``."""
    params = params_from_args(args)
    if not 2 <= args.samples <= MAX_SAMPLES:
        raise InputError(f"--samples must be from 2 to {MAX_SAMPLES}, got {args.samples}")
    if args.trajectory in ("line", "circle"):
        source = Source.paper(args.trajectory, args.duration)
    else:
        if args.duration is not None:
            raise InputError("--duration applies to line and circle; a FILE's times are its own")
        check_output(args.output, args.trajectory)
        try:
            text = read_text(args.trajectory)
        except OSError as exc:
            raise InputError(f"cannot read --trajectory {args.trajectory!r}: {exc.strerror or exc}") from None
        traj = parse_trajectory_csv(text, name=os.path.basename(args.trajectory))
        source = Source.from_trajectory(traj)
    return build_run(params, source, reference, samples=args.samples)


write_bytes = write_atomically
"""Write a clip, sidecar or report atomically: :func:`tpm_viz.core.files.write_atomically`, the CLI's one writer."""


def _check_trajectory(name: str) -> None:
    """``line``, ``circle`` or an existing file: a name that is none of them names the choices (one line)."""
    if name not in ("line", "circle") and not os.path.lexists(name):
        raise InputError(f"--trajectory {name!r}: no such file; give line, circle or a CSV file with columns t,p1,p2")


def _suffix(path: str, allowed: tuple[str, ...]) -> str:
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if ext not in allowed:
        raise InputError(f"--output must end in {' or '.join('.' + a for a in allowed)}, got {path!r}")
    return ext


def _cmd_clip(args) -> int:
    fmt = _suffix(args.output, FORMATS)  # the options first: a typo is refused before the heavy imports
    fps = check_fps(args.fps)
    size = parse_size(args.size)
    _check_trajectory(args.trajectory)

    from tpm_viz.media.clips import ClipRenderer  # matplotlib
    from tpm_viz.media.videos import encode_clip  # Pillow, PyAV

    run = run_from_args(args)
    renderer = ClipRenderer(run, run.source.label, size)
    data = encode_clip(fmt, renderer.frame, len(renderer), fps)
    write_bytes(args.output, data)
    if args.sidecar:
        geometry = renderer.geometry()
        side = {
            "fps": fps,
            "size": list(renderer.size),
            "frames": len(renderer),
            "t": run.t.tolist(),
            "tau": run.tau.tolist(),
            "texts": [list(renderer.texts(k)) for k in range(len(renderer))],
            "bars": {
                "zero_x": geometry.zero_x,
                "px_per_newton": geometry.px_per_newton,
                "rows": list(geometry.rows),
                "height": geometry.height,
            },
        }
        write_bytes(args.sidecar, json.dumps(side, indent=1).encode())
    print(
        f"tpm-viz clip: {args.output}: {len(renderer)} frames at {fps} frames/s ({len(renderer) / fps:.1f} s), "
        f"{size[0]}x{size[1]}, {len(data) / 1024:.0f} KiB",
        file=sys.stderr,
    )
    return 0


def _report_date(text: str | None) -> datetime.date:
    if text is None:
        return datetime.datetime.now(datetime.UTC).date()
    try:
        return datetime.date.fromisoformat(text)
    except ValueError:
        raise InputError(f"--date must be YYYY-MM-DD, got {text!r}") from None


def _cmd_report(args) -> int:
    _suffix(args.output, ("html", "htm"))  # the options first: a typo is refused before the heavy imports
    date = _report_date(args.date)
    _check_trajectory(args.trajectory)

    from tpm_viz.media.report import report_html
    from tpm_viz.multibody import inverse_dynamics  # the Pinocchio model, the closed form's cross-check

    run = run_from_args(args, reference=inverse_dynamics)
    data = report_html(run, lang=args.lang, date=date).encode("utf-8")
    write_bytes(args.output, data)
    print(
        f"tpm-viz report: {args.output}: {run.source.label}, {len(run.t)} samples over {run.t[-1]:.3f} s, "
        f"{len(data) / 1024:.0f} KiB (opens offline)",
        file=sys.stderr,
    )
    return 0


def _run_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--trajectory",
        required=True,
        metavar="line|circle|FILE",
        help="the paper's Fig. 4 line, Fig. 5 circle, or a CSV file with columns t,p1,p2 (s, m; docs/csv.md)",
    )
    p.add_argument(
        "--duration", type=float, metavar="T", help=f"line/circle duration [s] up to {MAX_DURATION:g} (0.2 / 0.5)"
    )
    p.add_argument(
        "--samples", type=int, default=RUN_SAMPLES, help=f"samples of the run, uniform in time ({RUN_SAMPLES})"
    )


def register(subparsers, common_parent: argparse.ArgumentParser) -> None:
    """Add ``clip`` and ``report`` to the ``tpm-viz`` subparsers (``common_parent`` provides ``--set``)."""
    c = subparsers.add_parser(
        "clip",
        parents=[common_parent],
        help="an animated GIF or MP4 (H.264) of a run: top view of the mechanism and the forces, one frame per sample",
        description="One frame per sample of the run (its times, not the wall clock: the same inputs give the same "
        "bytes), played at --fps: the mechanism from above with its path, trace and force arrows, the time and "
        "both forces as text, force bars and the force curves with a time marker.",
    )
    _run_options(c)
    c.add_argument("--output", required=True, metavar="FILE.gif|FILE.mp4", help="the clip (replaced atomically)")
    c.add_argument("--fps", type=int, default=20, metavar="N", help="frames per second of playback (20)")
    c.add_argument("--size", default="800x450", metavar="WxH", help="frame size in pixels (800x450, up to 1920x1080)")
    c.add_argument("--sidecar", metavar="FILE.json", help="also write each frame's time, forces and texts (JSON)")
    c.set_defaults(func=_cmd_clip)

    r = subparsers.add_parser(
        "report",
        parents=[common_parent],
        help="a self-contained HTML lab report of a run (opens offline, prints to PDF)",
    )
    _run_options(r)
    r.add_argument("--output", required=True, metavar="FILE.html", help="the report (replaced atomically)")
    r.add_argument("--lang", choices=["en", "ko"], default="en", help="language of the report (en)")
    r.add_argument("--date", metavar="YYYY-MM-DD", help="date printed in the report (default: today, UTC)")
    r.set_defaults(func=_cmd_report)
