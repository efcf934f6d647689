"""Every refusal of the LTI service: one line with the word a lecturer looks for, an HTTP status, logged once.

:class:`Refused` carries a :class:`Why` (the word: signature, key, audience, issuer, expired, nonce, replayed,
state, deployment, role, version, message type, ...) and a :class:`~tpm_viz.core.words.Phrase` saying what is wrong and
what to do, in English and Korean. The service answers it with a 4xx page of that one line
(:func:`tpm_viz.lti.pages.refusal_page`) and logs it once (:func:`log_refusal`, at most one line a second in a flood,
with the number left out); no traceback, and nothing is created (each check runs before anything is written).
"""

from __future__ import annotations

import enum
import logging
import threading
import time

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["Refused", "Why", "log", "log_refusal"]

log = logging.getLogger("tpm_viz.lti")


class Why(enum.Enum):
    """What a refusal is about: ``value`` is the word in its line (what a lecturer searches the log for)."""

    SIGNATURE = "signature"
    KEY = "key"
    AUDIENCE = "audience"
    ISSUER = "issuer"
    EXPIRED = "expired"
    NONCE = "nonce"
    REPLAYED = "replayed"
    STATE = "state"
    DEPLOYMENT = "deployment"
    ROLE = "role"
    VERSION = "version"
    MESSAGE_TYPE = "message type"
    USER = "user"
    LINK = "link"
    COURSE = "course"
    DEEP_LINKING = "deep linking"
    REQUEST = "request"
    TOO_LARGE = "too large"
    TOO_MANY = "too many"


STATUS = {Why.TOO_LARGE: 413, Why.TOO_MANY: 429, Why.COURSE: 409, Why.ROLE: 403}
"""HTTP status of a refusal (400 for any other)."""


class Refused(InputError):
    """A request the LTI service refuses: ``why`` (the word), the one-line ``phrase`` and the HTTP ``status``."""

    def __init__(self, why: Why, phrase: Phrase, detail: str = "", status: int | None = None) -> None:
        super().__init__(phrase)
        self.why, self.phrase, self.detail = why, phrase, detail
        self.status = status if status is not None else STATUS.get(why, 400)


LINES_PER_SECOND = 10
"""Most refusal lines logged in one second (a flood is counted in the next line, not written line by line)."""
_lock = threading.Lock()
_window = [0.0, 0, 0]  # start of the current second, lines written in it, refusals left out


def log_refusal(exc: Refused, address: str, path: str) -> None:
    """One log line for a refusal (at most :data:`LINES_PER_SECOND`; the next line counts the ones left out)."""
    with _lock:
        now = time.monotonic()
        if now - _window[0] >= 1.0:
            _window[0], _window[1] = now, 0
        if _window[1] >= LINES_PER_SECOND:
            _window[2] += 1
            return
        _window[1] += 1
        more, _window[2] = _window[2], 0
    extra = f" ({more} more refused meanwhile)" if more else ""
    detail = f" [{exc.detail[:200]}]" if exc.detail else ""
    log.warning("LTI %s refused (%s) from %s: %s%s%s", path, exc.why.value, address, exc.phrase, detail, extra)
