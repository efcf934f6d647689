"""Who may change the shared mechanism: everybody (default) or, with a presenter token, the presenter only.

``tpm-viz serve --presenter-token TOKEN`` (``main(..., presenter_token=TOKEN)``) turns presenter mode on. A tab
becomes the presenter's by typing the token into *Presenter login* and pressing *Log in*: viser 1.1.1 does not
pass the page's URL parameters to the server (its client strips ``?...`` from the websocket address) and has no
password input, so the token goes through a text field that the server clears at once. Every other tab still
sees the shared mechanism and may do anything on its own copy (*Work on my own copy*), but a change it makes to
the shared one is refused with a message to that tab only.

No viser in :class:`Access` (tested without a server); :class:`LoginPanel` is the small widget group.
Tokens are compared in constant time; a tab gets :data:`MAX_FAILURES` wrong attempts per :data:`LOCKOUT_SECONDS`.
"""

from __future__ import annotations

import hmac
import threading
import time
import weakref

from tpm_viz.errors import InputError

__all__ = ["LOCKOUT_SECONDS", "MAX_FAILURES", "Access", "AccessDenied"]

MAX_FAILURES = 5
LOCKOUT_SECONDS = 60.0
MAX_TOKEN_CHARS = 256

DENIED = (
    "only the presenter can change the shared mechanism; tick 'Work on my own copy' (Class & view) "
    "to try it on your own copy"
)


class AccessDenied(InputError):
    """A change to the shared mechanism from a tab that is not the presenter's (presenter mode only)."""


def check_token(token: str | None) -> str | None:
    """The presenter token from the command line: None (no presenter mode) or a non-blank string."""
    if token is None:
        return None
    if not isinstance(token, str) or not token.strip() or len(token) > MAX_TOKEN_CHARS:
        raise InputError(f"the presenter token must be 1 to {MAX_TOKEN_CHARS} characters (not only spaces)")
    return token


class Access:
    """The presenter token (or None) and the set of tabs that proved it. Thread-safe."""

    def __init__(self, token: str | None = None, clock=time.monotonic) -> None:
        checked = None if token is None else check_token(token)
        self._token = None if checked is None else checked.encode()
        self._presenters: weakref.WeakSet = weakref.WeakSet()
        self._failures: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
        self._lock = threading.Lock()
        self._clock = clock

    @property
    def enabled(self) -> bool:
        """Whether presenter mode is on (a token was given)."""
        return self._token is not None

    def is_presenter(self, view) -> bool:
        """Whether ``view`` may change the shared mechanism (always True without presenter mode)."""
        if self._token is None:
            return True
        with self._lock:
            return view in self._presenters

    def may_change(self, view, session) -> bool:
        """Whether ``view`` may commit to ``session`` (private copies: always)."""
        return not getattr(session, "shared", False) or self.is_presenter(view)

    def check(self, view, session) -> None:
        """Raise :class:`AccessDenied` unless ``view`` may commit to ``session``."""
        if not self.may_change(view, session):
            raise AccessDenied(DENIED)

    def login(self, view, attempt) -> bool:
        """Make ``view`` a presenter tab if ``attempt`` is the token; raises after too many wrong attempts."""
        if self._token is None:
            return True
        now = self._clock()
        with self._lock:
            recent = [t for t in self._failures.get(view, []) if now - t < LOCKOUT_SECONDS]
            if len(recent) >= MAX_FAILURES:
                wait = LOCKOUT_SECONDS - (now - recent[0])
                raise InputError(f"too many wrong presenter tokens from this tab; try again in {wait:.0f} s")
            text = attempt if isinstance(attempt, str) else ""
            ok = len(text) <= MAX_TOKEN_CHARS and hmac.compare_digest(text.encode(), self._token)
            if ok:
                self._presenters.add(view)
                self._failures.pop(view, None)
            else:
                self._failures[view] = [*recent, now]
            return ok

    def logout(self, view) -> None:
        """``view`` is no longer a presenter tab (it closed or logged out)."""
        with self._lock:
            self._presenters.discard(view)
            self._failures.pop(view, None)
