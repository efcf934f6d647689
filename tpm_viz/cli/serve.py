"""``tpm-viz serve``: the browser app (``python app.py`` runs the same command).

The UI layer (viser, trimesh: ~1.5 s to import) is imported when the command runs, not when the parser is built,
so that ``tpm-viz kinematics`` and the other file commands start in a fraction of that.

Before the app starts, :func:`check_bind` binds a socket to ``(host, port)`` once: a port outside 0..65535 is
refused by the parser, and a host that is not an address of this machine (or cannot be resolved within
:data:`RESOLVE_SECONDS`) fails at once with one line, instead of a server that never prints its URL.
A busy port is fine: the app moves to the next free one.
"""

from __future__ import annotations

import argparse
import errno
import socket
import threading
from pathlib import Path

from tpm_viz.cli.common import port_number
from tpm_viz.cli.lti import lti_plug
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import shorten

__all__ = ["MAX_TABS", "RESOLVE_SECONDS", "TABS_PER_ADDRESS", "check_bind", "register", "tabs_per_address"]

RESOLVE_SECONDS = 4.0
"""Longest wait for the host name to resolve [s]."""
TABS_PER_ADDRESS, MAX_TABS = 50, 200
"""``--tabs-per-address``: its default and its largest value (the server's connection limit), tabs."""


def _resolve(host: str, port: int) -> list:
    result: list = []

    def work() -> None:
        try:
            result.append(socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE))
        except (OSError, UnicodeError) as exc:
            result.append(exc)

    thread = threading.Thread(target=work, daemon=True)
    thread.start()
    thread.join(RESOLVE_SECONDS)
    if not result:
        raise InputError(f"--host {shorten(host)} did not resolve within {RESOLVE_SECONDS:g} s")
    if isinstance(result[0], BaseException):
        raise InputError(f"--host {shorten(host)} is not a known address or name of this machine")
    return result[0]


def tabs_per_address(text: str) -> int:
    """argparse type of ``--tabs-per-address``: a whole number from 1 to :data:`MAX_TABS`."""
    try:
        value = int(text.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of tabs from 1 to {MAX_TABS}") from None
    if not 1 <= value <= MAX_TABS:
        raise argparse.ArgumentTypeError(f"expected a whole number of tabs from 1 to {MAX_TABS}, got {value}")
    return value


def check_bind(host: str, port: int) -> None:
    """One bind to ``(host, port)`` and close; one-line :class:`InputError` if this machine cannot serve there."""
    family, kind, proto, _, address = _resolve(host, port)[0]
    with socket.socket(family, kind, proto) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind(address)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                return  # the app takes the next free port
            if exc.errno == errno.EADDRNOTAVAIL:
                raise InputError(
                    f"--host {shorten(host)} is not an address of this machine; use 127.0.0.1 (this machine only) "
                    "or 0.0.0.0 (all its addresses)"
                ) from None
            raise InputError(f"cannot serve on {shorten(host)} port {port}: {exc.strerror or exc}") from None


def _cmd_serve(args) -> int:
    host = args.host if args.host is not None else "0.0.0.0" if args.classroom else "127.0.0.1"
    check_bind(host, args.port)
    plug = (
        None
        if args.lti is None
        else lti_plug(args.lti, host, args.lessons, args.trusted_proxy or [], args.allowed_host or [])
    )
    from tpm_viz.ui.app import main as serve  # start-up speed of the other commands (module docstring)
    from tpm_viz.ui.continuity import default_path

    serve(
        host=host,
        port=args.port,
        presenter_token=args.presenter_token,
        classroom=args.classroom,
        session=args.session if args.session is not None else default_path(),
        fresh=args.fresh,
        lessons=args.lessons,
        trusted_proxies=args.trusted_proxy or (),
        allowed_hosts=args.allowed_host or (),
        lti=plug,
        tabs_per_address=args.tabs_per_address,
    )
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``serve`` to the ``tpm-viz`` subparsers (``common`` is unused: the app edits parameters itself)."""
    s = sub.add_parser("serve", help="start the browser app")
    s.add_argument(
        "--host",
        default=None,
        help="address to bind (default 127.0.0.1, loopback only; 0.0.0.0 with --classroom: every network address)",
    )
    s.add_argument(
        "--classroom",
        action="store_true",
        help="serve the room's network: print the URLs and a QR code for students; only the presenter (a tab on "
        "this computer, or another device with the printed token) changes the shared mechanism",
    )
    s.add_argument(
        "--session",
        type=Path,
        metavar="FILE",
        help="the session store: read at start, saved on every change (default: classroom.sqlite3 in the user data "
        "folder); a JSON session file is imported once into FILE.sqlite3 beside it and never written",
    )
    s.add_argument(
        "--fresh", action="store_true", help="start with the defaults (the old store is set aside, never overwritten)"
    )
    s.add_argument(
        "--lessons",
        type=Path,
        metavar="DIR",
        help="your own lessons for the Demos tab: a folder of *.toml files (format: assets/lessons/README.md)",
    )
    s.add_argument(
        "--port",
        type=port_number,
        default=8080,
        help="port 0-65535 (default 8080; the next free one if busy; 0: any free port)",
    )
    s.add_argument(
        "--presenter-token",
        metavar="TOKEN",
        help="only a tab that logs in with TOKEN changes the shared mechanism (others use their own copy)",
    )
    s.add_argument(
        "--trusted-proxy",
        action="append",
        metavar="ADDR",
        help="a reverse proxy (nginx, Caddy) in front of the app: its X-Forwarded-For / Forwarded name the client "
        "(an address or a network; repeatable; docs/classroom.md)",
    )
    s.add_argument(
        "--allowed-host",
        action="append",
        metavar="NAME",
        help="answer to this host name too (the name students type when a proxy or DNS serves the app; repeatable)",
    )
    s.add_argument(
        "--lti",
        type=Path,
        metavar="CONFIG",
        help="serve as an LTI 1.3 tool of the LMS in CONFIG.toml (docs/lti.md): only an instructor's launch (or the "
        "presenter token) presents; needs the .[lti] extra",
    )
    s.add_argument(
        "--tabs-per-address",
        type=tabs_per_address,
        default=TABS_PER_ADDRESS,
        metavar="N",
        help=f"most tabs from one network address ({TABS_PER_ADDRESS}; 1-{MAX_TABS}): one student's idle sockets "
        "never lock the class out. Without --trusted-proxy a class behind one router (NAT) or one proxy counts as "
        "one address: raise N for more students than that; tabs on this computer (the lecturer's) are never "
        "refused for the students' (docs/classroom.md)",
    )
    s.set_defaults(func=_cmd_serve)
