"""``tpm-viz serve``: the browser app (``python app.py`` runs the same command).

The UI layer (viser, trimesh: ~1.5 s to import) is imported when the command runs, not when the parser is built,
so that ``tpm-viz kinematics`` and the other file commands start in a fraction of that.
"""

from __future__ import annotations

import argparse

__all__ = ["register"]


def _cmd_serve(args) -> int:
    from tpm_viz.ui.app import main as serve  # start-up speed of the other commands (module docstring)

    serve(host=args.host, port=args.port, presenter_token=args.presenter_token)
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``serve`` to the ``tpm-viz`` subparsers (``common`` is unused: the app edits parameters itself)."""
    s = sub.add_parser("serve", help="start the browser app")
    s.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1, loopback only)")
    s.add_argument("--port", type=int, default=8080, help="port (default 8080; the next free one if busy)")
    s.add_argument(
        "--presenter-token",
        metavar="TOKEN",
        help="only a tab that logs in with TOKEN changes the shared mechanism (others use their own copy)",
    )
    s.set_defaults(func=_cmd_serve)
