"""A plain argparse parser with one family of ``tpm-viz`` subcommands, for testing a family's ``register``."""

from __future__ import annotations

import argparse
from types import ModuleType


def parser_for(family: ModuleType) -> argparse.ArgumentParser:
    """``tpm-viz`` with only ``family``'s subcommands (``--set`` as the shared option), on a plain parser."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--set", action="append", metavar="NAME=VALUE")
    parser = argparse.ArgumentParser(prog="tpm-viz")
    family.register(parser.add_subparsers(dest="command", required=True), common)
    return parser
