"""Who may change the shared mechanism: everybody (default) or, with a presenter token, the presenter only.

``tpm-viz serve --presenter-token TOKEN`` (``main(..., presenter_token=TOKEN)``) turns presenter mode on. A tab
becomes the presenter's by typing the token into *Presenter login* and pressing *Log in*: viser 1.1.1 does not
pass the page's URL parameters to the server (its client strips ``?...`` from the websocket address) and has no
password input, so the token goes through a text field that the server clears at once. Every other tab still
sees the shared mechanism and may do anything on its own copy (*Work on my own copy*), but a change it makes to
the shared one is refused with a message to that tab only.

No viser in :class:`Access` (tested without a server); :class:`tpm_viz.ui.login.LoginPanel` is the small widget group.
Tokens are compared in constant time. Wrong attempts are counted per *source address* (a tab that reconnects
does not start again) and server-wide: :data:`MAX_FAILURES` per address per :data:`LOCKOUT_SECONDS`, after which
each new lockout of that address lasts twice as long (up to :data:`MAX_LOCKOUT_SECONDS`), and at most
:data:`MAX_FAILURES_SERVER` wrong attempts per :data:`LOCKOUT_SECONDS` from everybody together.

With ``serve --lti`` presenter mode is on without a token too (``Access(required=True)``): only an instructor's
launch (:mod:`tpm_viz.ui.launched`, :meth:`Access.grant`) or the ``--presenter-token`` login makes a presenter.

Classroom mode (``tpm-viz serve --classroom``): a tab opened on the serving machine itself is a presenter
(:meth:`Access.grant`), and the presenter can hand the shared mechanism to the class and take it back
(``Access.open_to_class``).
"""

from __future__ import annotations

import hmac
import threading
import time
import weakref
from collections.abc import Callable
from typing import Protocol

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["LOCKOUT_SECONDS", "MAX_FAILURES", "MAX_FAILURES_SERVER", "MAX_LOCKOUT_SECONDS", "Access", "AccessDenied"]

MAX_FAILURES = 5
LOCKOUT_SECONDS = 60.0
MAX_LOCKOUT_SECONDS = 900.0
MAX_FAILURES_SERVER = 30
MAX_TOKEN_CHARS = 256

DENIED = Phrase(
    "only the presenter can change the shared mechanism; tick 'Work on my own copy' (Class & view) "
    "to try it on your own copy"
)


class Tab(Protocol):
    """A browser tab as :class:`Access` sees it: only its identity counts (kept in a weak set, so hashable)."""

    def __hash__(self) -> int: ...


class Committed(Protocol):
    """A session as :class:`Access` sees it: the class's shared mechanism or a tab's private copy."""

    @property
    def shared(self) -> bool: ...


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

    def __init__(
        self, token: str | None = None, clock: Callable[[], float] = time.monotonic, required: bool = False
    ) -> None:
        """``required``: presenter mode even without a token (``serve --lti``: an instructor's launch grants it)."""
        checked = None if token is None else check_token(token)
        self._token = None if checked is None else checked.encode()
        self._required = required
        self._presenters: weakref.WeakSet = weakref.WeakSet()
        self._failures: dict[str, list[float]] = {}  # source address -> times of recent wrong attempts
        self._lockouts: dict[str, tuple[float, int]] = {}  # source address -> (locked until, lockouts so far)
        self._server_failures: list[float] = []
        self._lock = threading.Lock()
        self._clock = clock
        self.open_to_class = False
        """Classroom mode: the presenter handed the shared mechanism to the class (everybody may change it)."""

    @property
    def enabled(self) -> bool:
        """Whether presenter mode is on (a token was given, or it is ``required``)."""
        return self._token is not None or self._required

    def is_presenter(self, view: Tab) -> bool:
        """Whether ``view`` may change the shared mechanism (always True without presenter mode)."""
        if not self.enabled:
            return True
        with self._lock:
            return view in self._presenters

    def is_presenter_tab(self, view: Tab) -> bool:
        """Whether ``view`` logged in (or was granted): presenter mode only; False without a token."""
        with self._lock:
            return self.enabled and view in self._presenters

    def grant(self, view: Tab) -> None:
        """Make ``view`` a presenter tab without a token (a tab opened on the serving machine, classroom mode)."""
        with self._lock:
            self._presenters.add(view)

    def may_change(self, view: Tab, session: Committed) -> bool:
        """Whether ``view`` may commit to ``session`` (private copies: always)."""
        return not getattr(session, "shared", False) or self.open_to_class or self.is_presenter(view)

    def check(self, view: Tab, session: Committed) -> None:
        """Raise :class:`AccessDenied` unless ``view`` may commit to ``session``."""
        if not self.may_change(view, session):
            raise AccessDenied(DENIED)

    def login(self, view: Tab, attempt: object, source: str | None = None) -> bool:
        """Make ``view`` a presenter tab if ``attempt`` is the token; raises after too many wrong attempts from
        ``source`` (the tab's address; default: the tab itself) or from everybody (see the module docstring)."""
        if self._token is None:
            return not self._required  # presenter mode without a token: no login makes a presenter
        now = self._clock()
        where = source if source is not None else f"tab-{id(view)}"
        with self._lock:
            until, count = self._lockouts.get(where, (0.0, 0))
            if now < until:
                raise InputError(
                    Phrase(
                        "too many wrong presenter tokens from this address; try again in {wait:.0f} s", wait=until - now
                    )
                )
            self._server_failures = [t for t in self._server_failures if now - t < LOCKOUT_SECONDS]
            if len(self._server_failures) >= MAX_FAILURES_SERVER:
                wait = LOCKOUT_SECONDS - (now - self._server_failures[0])
                raise InputError(
                    Phrase("too many wrong presenter tokens on this server; try again in {wait:.0f} s", wait=wait)
                )
            text = attempt if isinstance(attempt, str) else ""
            ok = len(text) <= MAX_TOKEN_CHARS and hmac.compare_digest(text.encode(), self._token)
            if ok:
                self._presenters.add(view)
                self._failures.pop(where, None)
                return True
            recent = [t for t in self._failures.get(where, []) if now - t < LOCKOUT_SECONDS] + [now]
            self._server_failures.append(now)
            if len(recent) >= MAX_FAILURES:  # locked out, each time twice as long
                wait = min(LOCKOUT_SECONDS * 2**count, MAX_LOCKOUT_SECONDS)
                self._lockouts[where] = (now + wait, count + 1)
                recent = []
            self._failures[where] = recent
            if len(self._failures) > 10_000:  # bounded: forget the oldest addresses
                for old in list(self._failures)[:5000]:
                    del self._failures[old]
            return False

    def logout(self, view: Tab) -> None:
        """``view`` is no longer a presenter tab (it closed or logged out)."""
        with self._lock:
            self._presenters.discard(view)
