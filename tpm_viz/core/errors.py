"""One error hierarchy for tpm-viz.

Every error the library raises on purpose is a :class:`TpmVizError` (itself a
``ValueError``), and its message is one line that names the problem, so that the
command line and the app can show it as it is.
"""

from __future__ import annotations

__all__ = [
    "BusyError",
    "FileRefusedError",
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


class FileRefusedError(InputError):
    """A file the app would not read (too big, not a regular file, outside its folder, nested too deep, not
    text); the one-line message names the path and what to change, and never quotes the file's contents.
    ``why``: the same words without the path (to quote inside another line that names the file already)."""

    def __init__(self, message: object, why: object = None) -> None:
        super().__init__(message)
        self.why = message if why is None else why


class BusyError(TpmVizError):
    """The server refused a job over a bound of its queue (``tpm_viz.classroom.jobs``): try again in a moment."""
