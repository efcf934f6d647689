"""One error hierarchy for tpm-viz.

Every error the library raises on purpose is a :class:`TpmVizError` (itself a
``ValueError``), and its message is one line that names the problem, so that the
command line and the app can show it as it is.
"""

from __future__ import annotations

__all__ = [
    "InputError",
    "InvalidParametersError",
    "SingularConfigurationError",
    "TpmVizError",
    "UnreachablePoseError",
]


class TpmVizError(ValueError):
    """Base class of every deliberate tpm-viz error (one-line, user-facing message)."""


class InvalidParametersError(TpmVizError):
    """A parameter set breaks a rule (non-positive length or mass, empty workspace, ...)."""


class UnreachablePoseError(TpmVizError):
    """A platform pose or an actuator position that the mechanism cannot assemble in."""


class SingularConfigurationError(TpmVizError):
    """A computation that needs a regular configuration was asked at a singular one."""


class InputError(TpmVizError):
    """Malformed user input: a CSV file, a command-line value, a non-finite number."""
