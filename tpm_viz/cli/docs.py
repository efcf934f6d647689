"""``tpm-viz docs``: build the docs site and, with ``--serve``, serve it on 127.0.0.1.

The site is Sphinx with furo and MyST (the ``docs`` extra: ``pip install -e ".[docs]"``), built from the repository's
``docs/`` folder (a clone or an editable install has it; a wheel does not). Sphinx runs in a child process
(``python -m sphinx``), so the command line never imports it; a missing extra is one line naming the install
command. The build is incremental: a second run rewrites only what changed. ``--strict`` is CI's build (warnings
are errors). ``--serve`` serves the built folder with the standard library's HTTP server (:func:`serve_folder`) on
127.0.0.1 only, on ``--port`` or the next free one, until Ctrl-C.
"""

from __future__ import annotations

import argparse
import errno
import functools
import http.server
import importlib.util
import subprocess
import sys
from pathlib import Path

from tpm_viz.cli.common import port_number
from tpm_viz.core.errors import InputError

__all__ = ["DEFAULT_PORT", "NEEDED", "PORT_TRIES", "SOURCES", "build", "register", "serve_folder"]

SOURCES = Path(__file__).resolve().parents[2] / "docs"
"""The site's sources: ``docs/`` beside the package in the repository."""
NEEDED = ("sphinx", "furo", "myst_parser")
"""The modules the build imports (the ``docs`` extra)."""
DEFAULT_PORT = 8000
PORT_TRIES = 100
"""Ports tried from ``--port`` up when it is busy."""


def _check_installed(sources: Path) -> None:
    missing = [name for name in NEEDED if importlib.util.find_spec(name) is None]
    if missing:
        raise InputError(f'the docs need {", ".join(missing)}: pip install -e ".[docs]"')
    if not (sources / "conf.py").is_file():
        raise InputError(
            f"the docs' sources are not here ({sources}): run tpm-viz docs in a clone of the repository "
            "(pip install -e . there)"
        )


def build(output: Path, strict: bool = False, sources: Path | None = None) -> int:
    """Build the site from ``sources`` (default :data:`SOURCES`) into ``output`` (HTML); Sphinx's exit status (0:
    built). ``strict``: warnings are errors."""
    sources = SOURCES if sources is None else sources
    _check_installed(sources)
    command = [sys.executable, "-m", "sphinx", "-b", "html", "-q", str(sources), str(output)]
    if strict:
        command[3:3] = ["-W", "--keep-going"]
    return subprocess.run(command, check=False).returncode


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    """Files of one folder, without a log line per request."""

    def log_message(self, format: str, *args: object) -> None:
        pass


def serve_folder(folder: Path, port: int) -> http.server.ThreadingHTTPServer:
    """An HTTP server of ``folder`` bound to 127.0.0.1 on ``port`` or the next free one (0: any free port), not yet
    serving (call ``serve_forever``)."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    for candidate in range(port, min(port + PORT_TRIES, 65536)) if port else [0]:
        try:
            return http.server.ThreadingHTTPServer(("127.0.0.1", candidate), handler)
        except OSError as exc:
            if exc.errno != errno.EADDRINUSE:
                raise InputError(f"cannot serve on 127.0.0.1 port {candidate}: {exc.strerror or exc}") from None
    raise InputError(f"ports {port} to {port + PORT_TRIES - 1} are all busy: choose another with --port")


def _cmd_docs(args: argparse.Namespace) -> int:
    output = args.output if args.output is not None else SOURCES / "_build" / "html"
    _check_installed(SOURCES)  # nothing is made when the site cannot be built
    try:  # a folder, made if missing; never a file, a FIFO or a device named as one
        output.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError) as exc:
        raise InputError(f"cannot write into --output {str(output)!r}: {exc.strerror} (give a folder)") from None
    status = build(output, args.strict)
    if status != 0:
        print(f"tpm-viz: error: the docs build failed (sphinx exit status {status}): see above", file=sys.stderr)
        return 1
    print(f"docs built: {output / 'index.html'}", flush=True)
    if not args.serve:
        return 0
    server = serve_folder(output, args.port)
    print(f"tpm-viz docs at http://127.0.0.1:{server.server_address[1]}/ (Ctrl-C stops)", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``docs`` to the ``tpm-viz`` subparsers (``common`` is unused: no mechanism parameters)."""
    d = sub.add_parser("docs", help="build the docs site (and serve it on 127.0.0.1 with --serve)")
    d.add_argument(
        "--output", type=Path, metavar="DIR", help="where the HTML goes (default: docs/_build/html in the repository)"
    )
    d.add_argument("--serve", action="store_true", help="then serve it on 127.0.0.1 until Ctrl-C")
    d.add_argument(
        "--port",
        type=port_number,
        default=DEFAULT_PORT,
        help=f"port to serve on (default {DEFAULT_PORT}; the next free one if busy; 0: any free port)",
    )
    d.add_argument("--strict", action="store_true", help="warnings are errors (as CI builds it)")
    d.set_defaults(func=_cmd_docs, output_is_folder=True)
