"""What every ``tpm-viz`` subcommand shares: the one-line-error parser, ``--set NAME=VALUE`` and number checks."""

from __future__ import annotations

import argparse
import math

import numpy as np

from tpm_viz.errors import InputError
from tpm_viz.params import PARAM_INFO, Params

__all__ = ["Parser", "common_parent", "params_from_args", "positive", "positive_float"]


class Parser(argparse.ArgumentParser):
    """An argparse parser whose usage errors are one line and exit status 2."""

    def error(self, message: str):  # pragma: no cover - exercised through main()
        raise InputError(f"{self.prog}: {message}")


def common_parent() -> argparse.ArgumentParser:
    """The options every model subcommand takes: ``--set NAME=VALUE`` (SI units, repeatable)."""
    known = ", ".join(k for k in PARAM_INFO if k not in ("stroke", "pivot_spacing"))
    common = Parser(add_help=False)
    common.add_argument(
        "--set",
        action="append",
        metavar="NAME=VALUE",
        help=f"override a parameter in SI units (repeatable); names: {', '.join(PARAM_INFO)} (paper: {known})",
    )
    return common


def params_from_args(args: argparse.Namespace) -> Params:
    """The parameter set from ``--set NAME=VALUE`` options (SI units) over the paper's defaults."""
    overrides: dict[str, str] = {}
    for item in getattr(args, "set", None) or []:
        name, sep, value = item.partition("=")
        if not sep:
            raise InputError(f"--set expects NAME=VALUE, got {item!r}")
        overrides[name.strip()] = value.strip()
    return Params.paper().with_overrides(overrides)


def positive(value: float | None, name: str) -> float | None:
    """``value`` if None or positive and finite; else :class:`~tpm_viz.errors.InputError` naming ``name``."""
    if value is not None and (not math.isfinite(value) or value <= 0):
        raise InputError(f"{name} must be a positive, finite number, got {value:g}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a positive, finite number of seconds."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive, finite number of seconds, got {text!r}")
    return value
