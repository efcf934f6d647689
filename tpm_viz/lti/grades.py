"""Grades back to the course (AGS 2.0 score publish service), none lost, each in effect exactly once.

:meth:`GradeSender.submit` (what the exercise UI calls with the tab's launch ``ref``) checks that the launch may
be graded (its AGS claim has the score scope and a ``lineitem``, and its link names this exercise), applies the
exercise's attempt rule (:class:`~tpm_viz.classroom.launches.Rule`: the best or the latest fraction) and queues the
score in the store's outbox (:meth:`~tpm_viz.lti.ledger.Ledger.queue`) before it returns: a kill -9 after that
loses nothing. A background thread sends what is due: an access token (:mod:`.tokens`), then a POST to
``{lineitem}/scores`` (``/scores`` inserted before any query) as ``application/vnd.ims.lis.v1.score+json``:
``userId`` = ``sub``, ``scoreGiven`` = fraction x ``scoreMaximum``, ``scoreMaximum`` the line item's (read from it
when the launch may read line items, else the exercise's), ``activityProgress`` ``Completed``, ``gradingProgress``
``FullyGraded``, ``timestamp`` ISO 8601 in UTC with milliseconds. A platform down, slow or answering 5xx/429 is tried
again with back-off (:class:`Backoff`), also after a restart.

Exactly once, in effect. AGS keeps, per line item and user, the latest score by ``timestamp``, and a platform must
not apply a score older than the one it holds. A score's body, its timestamp included, is fixed when it is queued
(timestamps strictly increase per line item and user). A POST whose answer was lost is sent again *identically*:
the platform either applies the same value again (the gradebook does not change) or refuses it as not newer (409,
counted as delivered); either way the gradebook holds that score once. A newer score of the same line item and user
replaces a waiting older one in the outbox (the older could only be overwritten). Answers other than 2xx, 409, 401
(token renewed, retried) and the transient ones are the platform's refusal: the score stays in the outbox as
``failed`` with the reason, and the log says so once.
"""

from __future__ import annotations

import datetime
import json
import logging
import math
import random
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit, urlunsplit

import httpx

from tpm_viz.classroom.launches import News, Rule
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import T
from tpm_viz.lti.config import Config
from tpm_viz.lti.deeplinking import Catalogue
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.ledger import Ledger, Outgoing, grade_key
from tpm_viz.lti.platform_keys import read_limited
from tpm_viz.lti.tokens import SCORE_SCOPE, TokenError, Tokens, transient

__all__ = ["SCORE_TYPE", "Backoff", "GradeSender", "scores_url", "stamp"]

log = logging.getLogger("tpm_viz.lti")
SCORE_TYPE = "application/vnd.ims.lis.v1.score+json"
LINEITEM_TYPE = "application/vnd.ims.lis.v2.lineitem+json"
AGS = "https://purl.imsglobal.org/spec/lti-ags/scope/"
READ_SCOPES = (AGS + "lineitem.readonly", AGS + "lineitem")
REQUEST_SECONDS = 10.0


@dataclass(frozen=True)
class Backoff:
    """Waits between tries [s]: ``first`` x ``factor`` ^ tries, at most ``most``, stretched by up to ``jitter``."""

    first: float = 2.0
    factor: float = 2.0
    most: float = 300.0
    jitter: float = 0.2

    def wait(self, tries: int, rng: random.Random) -> float:
        return min(self.most, self.first * self.factor ** min(tries, 30)) * (1.0 + self.jitter * rng.random())


def stamp(at: float) -> str:
    """``at`` [s since the epoch] as ISO 8601 in UTC with milliseconds (``2026-11-29T10:00:00.000Z``)."""
    moment = datetime.datetime.fromtimestamp(at, datetime.UTC)
    return moment.isoformat(timespec="milliseconds").replace("+00:00", "Z")


def scores_url(lineitem: str) -> str:
    """The score endpoint of a line item: ``/scores`` appended to its path, before any query."""
    parts = urlsplit(lineitem)
    return urlunsplit((parts.scheme, parts.netloc, parts.path.rstrip("/") + "/scores", parts.query, ""))


class GradeSender:
    """Queues scores (:meth:`submit`) and sends them in the background (:meth:`start`, :meth:`stop`)."""

    def __init__(
        self,
        ledger: Ledger,
        config: Config,
        key: ToolKey,
        catalogue: Catalogue | None = None,
        client: httpx.Client | None = None,
        backoff: Backoff = Backoff(),
        seed: int | None = None,
        timeout: float = REQUEST_SECONDS,
    ) -> None:
        """``timeout``: longest wait for one answer of the platform [s] (a slower one is tried again later)."""
        self.ledger, self.config, self.catalogue, self.backoff = ledger, config, catalogue, backoff
        self.timeout = timeout
        self.client = client if client is not None else httpx.Client(timeout=timeout, follow_redirects=False)
        self.tokens = Tokens(key, self.client, clock=ledger.clock, timeout=timeout)
        self._rng = random.Random(seed)
        self._wake = threading.Condition()
        self._stopping = False
        self._thread: threading.Thread | None = None
        self._told: dict[str, list[list[Any]]] = {}  # grade -> [listener, told "on its way"] still waiting
        self._maxima: dict[str, float] = {}  # line item -> its scoreMaximum, read once

    # -- the API of the exercise UI -----------------------------------------------------------------------------------
    def submit(
        self, ref: str, exercise: str, fraction: float, rule: Rule, tell: Callable[[News], None] | None = None
    ) -> News:
        """Queue the score ``fraction`` (0..1) of ``exercise`` in the launch ``ref``; ``tell`` hears later, once
        each, :attr:`News.ON_ITS_WAY` (the LMS does not answer yet) and :attr:`News.SENT` or :attr:`News.REFUSED`."""
        if not (isinstance(fraction, (int, float)) and math.isfinite(fraction) and 0.0 <= fraction <= 1.0):
            raise InputError(T("a score must be a fraction from 0 to 1"))
        record = self.ledger.launch(ref)
        if record is None or record.get("exercise") != exercise or not record.get("lineitem"):
            return News.NOT_GRADED
        if SCORE_SCOPE not in (record.get("scopes") or []):
            return News.NOT_GRADED
        grade = grade_key(record["issuer"], record["client_id"], record["lineitem"], record["subject"])
        hint = next((i.score_maximum for i in (self.catalogue() if self.catalogue else []) if i.id == exercise), None)

        def body(send: float, at: float) -> dict[str, Any]:
            keys = ("issuer", "client_id", "lineitem", "scopes", "subject")
            return {**{k: record[k] for k in keys}, "fraction": send, "timestamp": stamp(at), "hint": hint}

        if not self.ledger.queue(grade, float(fraction), rule is Rule.BEST, body):
            return News.UNCHANGED
        with self._wake:
            if tell is not None:
                self._told.setdefault(grade, []).append([tell, False])
            self._wake.notify_all()
        return News.QUEUED

    # -- the sending thread ------------------------------------------------------------------------------------------
    def start(self) -> None:
        """Send what is waiting (what a restart found in the outbox too), in a background thread."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="tpm-viz-lti-grades", daemon=True)
            self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        with self._wake:
            self._stopping = True
            self._wake.notify_all()
        if self._thread is not None:
            self._thread.join(timeout)

    def wake(self) -> None:
        """Try what is waiting now (tests; the platform is said to be back)."""
        with self._wake:
            self._wake.notify_all()

    def _run(self) -> None:
        while True:
            with self._wake:
                if self._stopping:
                    return
            try:
                rows, nxt = self.ledger.due()
            except Exception as exc:  # the store closed under us, or a disk error: log, try again later
                log.warning("LTI grades: cannot read the outbox (%s)", type(exc).__name__)
                rows, nxt = [], self.ledger.clock() + 5.0
            for row in rows:
                if self._stopping:
                    return
                try:
                    self._send(row)
                except Exception as exc:  # a store closed under us or a disk error: the row stays waiting
                    log.warning("LTI grades: a score could not be handled (%s); it stays waiting", type(exc).__name__)
                    nxt, rows = self.ledger.clock() + 5.0, []
                    break
            if rows:
                continue
            with self._wake:
                if self._stopping:
                    return
                wait = None if nxt is None else max(0.0, nxt - self.ledger.clock())
                self._wake.wait(timeout=None if wait is None else min(wait, 60.0))

    def _send(self, row: Outgoing) -> None:
        body = row.body
        platform = self.config.platform(str(body.get("issuer")), str(body.get("client_id")))
        if platform is None:
            self._fail(row, "the platform is no longer in the configuration")
            return
        try:
            readable = [s for s in READ_SCOPES if s in (body.get("scopes") or [])][:1]
            token = self.tokens.get(platform, [SCORE_SCOPE, *readable])
            maximum = self._maximum(body, token, bool(readable))
            status = self._post(body, token, maximum)
        except TokenError as exc:
            self._later(row, exc.why) if exc.transient else self._fail(row, exc.why)
            return
        except httpx.HTTPError as exc:
            self._later(row, f"score endpoint unreachable ({type(exc).__name__})")
            return
        if status in (200, 201, 202, 204, 409):
            self.ledger.sent(row.id)
            log.info("LTI grade sent (HTTP %s) after %d tries", status, row.tries + 1)
            self._tell(row.grade, News.SENT, done=True)
        elif status == 401:
            self.tokens.forget(platform)
            self._later(row, "HTTP 401: token renewed")
        elif transient(status):
            self._later(row, f"HTTP {status}")
        else:
            self._fail(row, f"the platform refused the score (HTTP {status})")

    def _maximum(self, body: dict[str, Any], token: str, readable: bool) -> float:
        """The line item's scoreMaximum (read once when the launch may read it), else the exercise's, else 1."""
        lineitem = str(body["lineitem"])
        if readable and lineitem not in self._maxima:
            headers = {"Authorization": f"Bearer {token}", "Accept": LINEITEM_TYPE}
            with self.client.stream("GET", lineitem, headers=headers, timeout=self.timeout) as response:
                data = read_limited(response, 64 << 10) if response.status_code == 200 else None
            try:
                value = float(json.loads(data)["scoreMaximum"]) if data else math.nan
            except (ValueError, KeyError, TypeError, RecursionError):
                value = math.nan
            if math.isfinite(value) and value > 0:
                self._maxima[lineitem] = value
        hint = body.get("hint")
        fallback = float(hint) if isinstance(hint, (int, float)) and hint > 0 else 1.0
        return self._maxima.get(lineitem, fallback)

    def _post(self, body: dict[str, Any], token: str, maximum: float) -> int:
        score = {
            "userId": body["subject"],
            "scoreGiven": round(float(body["fraction"]) * maximum, 6),
            "scoreMaximum": maximum,
            "activityProgress": "Completed",
            "gradingProgress": "FullyGraded",
            "timestamp": body["timestamp"],
        }
        headers = {"Authorization": f"Bearer {token}", "Content-Type": SCORE_TYPE}
        data = json.dumps(score, allow_nan=False).encode()
        with self.client.stream(
            "POST", scores_url(str(body["lineitem"])), content=data, headers=headers, timeout=self.timeout
        ) as response:
            read_limited(response, 64 << 10)
            return response.status_code

    def _later(self, row: Outgoing, why: str) -> None:
        due = self.ledger.clock() + self.backoff.wait(row.tries, self._rng)
        self.ledger.retry(row.id, due, why)
        if row.tries == 0:
            log.warning("LTI grade not sent yet (%s); trying again with back-off", why)
        self._tell(row.grade, News.ON_ITS_WAY, done=False)

    def _fail(self, row: Outgoing, why: str) -> None:
        self.ledger.failed(row.id, why)
        log.warning("LTI grade refused for good: %s (kept in the store's outbox as failed)", why)
        self._tell(row.grade, News.REFUSED, done=True)

    def _tell(self, grade: str, news: News, done: bool) -> None:
        """``news`` to the listeners of ``grade``: the last news (``done``) to all, *on its way* once to each."""
        with self._wake:
            waiting = self._told.pop(grade, []) if done else self._told.get(grade, [])
            listeners = [entry[0] for entry in waiting if done or not entry[1]]
            for entry in waiting:
                entry[1] = True
        for listener in listeners:
            try:
                listener(news)
            except Exception:  # a tab that closed: its listener's failure is not the sender's
                log.debug("LTI grade listener failed", exc_info=True)
