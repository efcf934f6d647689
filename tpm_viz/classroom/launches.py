"""What an LMS launch hands the app: who the tab is (a server-issued identity of the LMS user), whether it presents,
the course, and what to open; carried by a one-time ticket (no viser, no JOSE: :mod:`tpm_viz.lti` makes launches,
:mod:`tpm_viz.ui.launched` applies them to a tab).

The LTI service (:mod:`tpm_viz.lti.service`) checks a launch and :meth:`Tickets.issue` s a ticket for it: a random
token the browser is sent to the app with (``/?lti=TICKET``). The app's page request spends it at once
(:meth:`Tickets.arrive`: a second request with the same ticket, from this browser or another, gets nothing) and its
launch waits under a random nonce, in a short-lived cookie, for the tab's websocket (:meth:`Tickets.take`), as a
share link's token does (:mod:`tpm_viz.classroom.links`). Bounded: :data:`MAX_TICKETS` tickets and
:data:`MAX_ARRIVALS` arrivals at once (the oldest go first), each for :data:`TICKET_SECONDS`.

A tab that reconnects (a wifi blip, a restart) sends no ticket: ``Tickets.recall`` finds the launch of the
browser it comes from (by its hashed identity cookie; the LTI layer keeps them in the store), so that the LMS user
keeps their identity and grades; the presenter's right is never restored from it (see :mod:`tpm_viz.classroom.away`).
"""

from __future__ import annotations

import enum
import re
import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol
from urllib.parse import parse_qs

from tpm_viz.classroom.identity import hashed

__all__ = [
    "LTI_PARAMETER",
    "MAX_ARRIVALS",
    "MAX_TICKETS",
    "TICKET_SECONDS",
    "Grades",
    "Launch",
    "News",
    "Plug",
    "Role",
    "Rule",
    "Tickets",
    "ticket_of_query",
]

LTI_PARAMETER = "lti"
"""The query parameter of the app's URL that carries a launch's ticket (``/?lti=TICKET``)."""
TICKET_SECONDS = 120.0
"""How long a ticket waits for its page, and the page's launch for its websocket [s]."""
MAX_TICKETS = 2000
MAX_ARRIVALS = 2000
_TICKET = re.compile(r"^[A-Za-z0-9_-]{20,64}$")


class Role(enum.Enum):
    """What a launch makes a tab: the class's presenter (Instructor, Administrator, TeachingAssistant) or a
    student (every other role)."""

    PRESENTER = "presenter"
    STUDENT = "student"


class Rule(enum.Enum):
    """Which score of an exercise's attempts the course keeps: the best one or the latest one."""

    BEST = "best"
    LATEST = "latest"


class News(enum.Enum):
    """What became of a grade: not for this launch (no grade service, another exercise), nothing new (not better
    than the best sent), queued, on its way (the LMS does not answer yet: told once), sent, or refused by the LMS."""

    NOT_GRADED = "not graded"
    UNCHANGED = "unchanged"
    QUEUED = "queued"
    ON_ITS_WAY = "on its way"
    SENT = "sent"
    REFUSED = "refused"


class Grades(Protocol):
    """What the exercise UI calls to send a score to the course (:class:`tpm_viz.lti.grades.GradeSender`)."""

    def submit(
        self, ref: str, exercise: str, fraction: float, rule: Rule, tell: Callable[[News], None] | None = None
    ) -> News: ...


class Plug(Protocol):
    """The LTI tool as the app sees it (``tpm-viz serve --lti``: :class:`tpm_viz.lti.run.LtiPlug`)."""

    tickets: Tickets
    grades: Grades | None

    def start(self, app_url: str, store: Path | None) -> None:
        """Serve the LTI endpoints (the app's URL and its store are known)."""

    def stop(self) -> None:
        """Stop serving and sending grades."""


@dataclass(frozen=True)
class Launch:
    """One checked launch as the app needs it. ``user``: the server-issued identity of the LMS user (32 hex, the
    same from every launch and device); ``ref``: the launch's record (grades are sent through it); ``course``: the
    course title (the class label); ``lesson`` (1-based) or ``exercise``: what the link opens; ``lang``: the
    launch's locale tag ('' if none)."""

    ref: str
    user: str
    role: Role
    course: str
    lesson: int | None = None
    exercise: str | None = None
    lang: str = ""

    @property
    def key(self) -> str:
        """The tab identity the app keeps this user's records under (``u:`` + SHA-256 of ``user``)."""
        return hashed("u", self.user)


def ticket_of_query(query: str) -> str | None:
    """The ticket a page request's query carries (None: no ``lti`` parameter; '' for a malformed one)."""
    try:
        values = parse_qs(str(query)[:4096], keep_blank_values=True, max_num_fields=32)
    except ValueError:
        return ""
    found = values.get(LTI_PARAMETER)
    if not found:
        return None
    return found[0] if _TICKET.match(found[0]) else ""


class _Expiring:
    """An insertion-ordered map whose entries expire after ``seconds`` and that keeps at most ``most``."""

    def __init__(self, seconds: float, most: int, clock: Callable[[], float]) -> None:
        self.seconds, self.most, self.clock = seconds, most, clock
        self.items: OrderedDict[str, tuple[float, Launch | None]] = OrderedDict()

    def put(self, key: str, launch: Launch | None) -> None:
        now = self.clock()
        self.expire(now)
        while len(self.items) >= self.most:
            self.items.popitem(last=False)
        self.items[key] = (now + self.seconds, launch)

    def pop(self, key: str) -> tuple[bool, Launch | None]:
        self.expire(self.clock())
        item = self.items.pop(key, None)
        return (False, None) if item is None else (True, item[1])

    def expire(self, now: float) -> None:
        while self.items and next(iter(self.items.values()))[0] <= now:
            self.items.popitem(last=False)


class Tickets:
    """One-time tickets of checked launches (thread-safe; ``clock``: seconds). ``course`` is the class label of
    the course this server serves (None until the first launch), shown in every tab's classroom line."""

    def __init__(self, seconds: float = TICKET_SECONDS, clock: Callable[[], float] = time.monotonic) -> None:
        self._lock = threading.Lock()
        self._tickets = _Expiring(seconds, MAX_TICKETS, clock)
        self._arrivals = _Expiring(seconds, MAX_ARRIVALS, clock)
        self.course: str | None = None
        self.recall: Callable[[str], Launch | None] = lambda browser: None
        """The launch a browser (its hashed cookie identity) last arrived with, or None (set by the LTI layer)."""
        self.remember: Callable[[str, Launch], None] = lambda browser, launch: None
        """Keep that a browser arrived with a launch (set by the LTI layer, which keeps it in the store)."""

    def issue(self, launch: Launch) -> str:
        """A new ticket for ``launch`` (good for one page request within :data:`TICKET_SECONDS`)."""
        ticket = secrets.token_urlsafe(24)
        with self._lock:
            self._tickets.put(ticket, launch)
            self.course = launch.course
        return ticket

    def arrive(self, ticket: str) -> str:
        """A page asked with ``?lti=TICKET``: spend the ticket (once) and keep its launch for the page's websocket;
        returns the nonce for the page's cookie (an unknown, spent or expired ticket keeps None: the tab says so)."""
        nonce = secrets.token_urlsafe(16)
        with self._lock:
            _, launch = self._tickets.pop(ticket) if ticket else (False, None)
            self._arrivals.put(nonce, launch)
        return nonce

    def take(self, nonce: str | None) -> tuple[bool, Launch | None]:
        """``(the page came with a ticket, its launch or None when the ticket was spent)``, once per nonce."""
        if not nonce:
            return False, None
        with self._lock:
            return self._arrivals.pop(str(nonce))

    def __len__(self) -> int:
        with self._lock:
            now = self._tickets.clock()
            self._tickets.expire(now)
            self._arrivals.expire(now)
            return len(self._tickets.items) + len(self._arrivals.items)
