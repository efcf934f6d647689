"""``tpm-viz lti keygen --output DIR``: the LTI tool's key; and the ``--lti`` plug of ``tpm-viz serve``.

The LTI layer (PyJWT, cryptography, Starlette, uvicorn, httpx: the ``.[lti]`` extra) is imported when a command
needs it, never when the parser is built; when it is not installed the command says which extra to install.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from tpm_viz.cli.common import Parser
from tpm_viz.core.errors import InputError

__all__ = ["EXTRA", "lti_plug", "register"]

EXTRA = 'the LTI extra is not installed: pip install -e ".[lti]" (PyJWT[crypto], starlette, uvicorn, httpx)'


def _missing(exc: ImportError) -> InputError:
    return InputError(f"{EXTRA}; missing: {exc.name or exc}")


def lti_plug(config: Path, host: str, lessons: Path | None, trusted: list[str], allowed: list[str]):
    """The LTI tool of ``serve --lti CONFIG`` (its file, key and port checked now: one line and exit 2 if not)."""
    from tpm_viz.app.lessons import DEMOS, load_lessons
    from tpm_viz.classroom.network import Network

    try:
        from tpm_viz.lti.exercises import exercises_catalogue
        from tpm_viz.lti.run import LtiPlug
    except ImportError as exc:
        raise _missing(exc) from None
    tour = DEMOS if lessons is None else load_lessons(lessons)[0]
    return LtiPlug(config, host, tour, Network.of(trusted, allowed), exercises_catalogue(tour))


def _cmd_keygen(args) -> int:
    try:
        from tpm_viz.lti.keys import KEY_FILE, keygen
    except ImportError as exc:
        raise _missing(exc) from None
    key = keygen(args.output)
    print(json.dumps(key.jwks(), indent=2))
    print(
        f"wrote {Path(args.output) / KEY_FILE} (mode 0600): the [tool] private_key of the LTI configuration",
        file=sys.stderr,
    )
    return 0


def register(sub, common: argparse.ArgumentParser) -> None:
    """Add ``lti`` (``keygen``) to the ``tpm-viz`` subparsers (``common`` is unused)."""
    lti = sub.add_parser("lti", help="the LTI 1.3 tool's key (tpm-viz serve --lti CONFIG.toml: docs/lti.md)")
    commands = lti.add_subparsers(dest="lti_command", required=True, parser_class=Parser)
    keygen = commands.add_parser("keygen", help="make the tool's RSA key: DIR/tool-key.pem (0600); print its JWKS")
    keygen.add_argument("--output", type=Path, required=True, metavar="DIR", help="the folder of tool-key.pem")
    keygen.set_defaults(func=_cmd_keygen, output_is_folder=True)
