"""Deep Linking 2.0: an instructor picks lessons and exercises; the tool answers a signed ``LtiDeepLinkingResponse``.

An Instructor's ``LtiDeepLinkingRequest`` (checked by :mod:`.checks`) opens the picker (:func:`tpm_viz.lti.pages
.picker_page`) of the :data:`Catalogue`'s items; the choice comes back to ``/lti/deeplink/return`` with a one-time
pick token (:class:`Picks`, the request's settings kept server-side) and :func:`response_jwt` builds the answer: a
JWT signed with the tool's key (``kid`` in its header) with ``iss`` = the client_id, ``aud`` = the platform's
issuer, a fresh ``nonce``, the deployment, the request's ``data`` echoed and one ``ltiResourceLink`` per item:
its title, the launch URL, ``custom`` ``{"lesson": "N"}`` or ``{"exercise": "ID"}``, and for a graded exercise a
``lineItem`` with ``scoreMaximum`` and ``label`` (when the platform accepts line items). It is form-posted as
``JWT`` to the request's ``deep_link_return_url``.
"""

from __future__ import annotations

import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from tpm_viz.app.demos import Demo
from tpm_viz.classroom.launches import Role
from tpm_viz.core.words import Lang, Phrase, T
from tpm_viz.lti.checks import CLAIM, Claims
from tpm_viz.lti.config import Platform
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.refusals import Refused, Why

__all__ = ["DL", "PICK_SECONDS", "Catalogue", "Item", "Pick", "Picks", "lessons_catalogue", "response_jwt"]

DL = "https://purl.imsglobal.org/spec/lti-dl/claim/"
PICK_SECONDS = 900.0
"""How long a picker stays good [s]."""
MAX_PICKS = 500
RESPONSE_SECONDS = 600
"""Lifetime of a deep-linking response [s] (the browser posts it at once)."""


@dataclass(frozen=True)
class Item:
    """One thing the picker offers: a lesson (``id``: its 1-based number) or an exercise (``id``: its id), its
    title in English and Korean, whether it is graded and its maximum score (points)."""

    kind: str
    id: str
    title_en: str
    title_ko: str
    graded: bool = False
    score_maximum: float | None = None

    def title(self, lang: Lang) -> str:
        return self.title_ko if lang is Lang.KO and self.title_ko else self.title_en

    @property
    def value(self) -> str:
        """The picker's form value of the item (``lesson:3``, ``exercise:ID``)."""
        return f"{self.kind}:{self.id}"


Catalogue = Callable[[], list[Item]]
"""What the picker lists (the lessons now; the exercise engine adds its exercises)."""


def lessons_catalogue(lessons: Sequence[Demo], exercises: Catalogue | None = None) -> Catalogue:
    """The app's lessons (``custom`` ``lesson`` = their 1-based number) followed by ``exercises()``."""
    items = [Item("lesson", str(n), d.title, T(d.title).render(Lang.KO)) for n, d in enumerate(lessons, start=1)]
    return lambda: items + (exercises() if exercises is not None else [])


@dataclass(frozen=True)
class Pick:
    """A deep-linking request waiting for the instructor's choice."""

    token: str
    platform: Platform
    deployment: str
    return_url: str
    data: Any
    multiple: bool
    line_items: bool
    lang: Lang
    expires: float


class Picks:
    """Pickers waiting for a choice, each good once within :data:`PICK_SECONDS` (thread-safe, bounded)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self.clock = clock
        self._lock = threading.Lock()
        self._picks: OrderedDict[str, Pick] = OrderedDict()

    def open(self, claims: Claims, platform: Platform, lang: Lang) -> Pick:
        """The picker of a checked deep-linking request (refused with *role* for a student, with *deep linking*
        when the platform does not take ``ltiResourceLink`` items)."""
        if claims.role is not Role.PRESENTER:
            raise Refused(Why.ROLE, T("only an instructor can add tpm-viz content to the course (role)"))
        settings = claims.deep_linking or {}
        accepted = settings.get("accept_types")
        if isinstance(accepted, list) and "ltiResourceLink" not in accepted:
            raise Refused(Why.DEEP_LINKING, T("the course does not accept LTI links here (deep linking)"))
        pick = Pick(
            token=secrets.token_urlsafe(24),
            platform=platform,
            deployment=claims.deployment,
            return_url=str(settings["deep_link_return_url"]),
            data=settings.get("data"),
            multiple=settings.get("accept_multiple", True) is not False,
            line_items=settings.get("accept_lineitem", True) is not False,
            lang=lang,
            expires=self.clock() + PICK_SECONDS,
        )
        with self._lock:
            now = self.clock()
            while self._picks and (len(self._picks) >= MAX_PICKS or next(iter(self._picks.values())).expires <= now):
                self._picks.popitem(last=False)
            self._picks[pick.token] = pick
        return pick

    def take(self, token: object) -> Pick:
        """The picker of ``token``, once (refused with *state* when unknown, used or expired)."""
        with self._lock:
            pick = self._picks.pop(token, None) if isinstance(token, str) else None
        if pick is None or pick.expires <= self.clock():
            raise Refused(Why.STATE, T("this choice was sent already or has expired (state): open the picker again"))
        return pick


def content_item(item: Item, launch_url: str, line_items: bool) -> dict[str, Any]:
    """The ``ltiResourceLink`` of ``item``."""
    found: dict[str, Any] = {
        "type": "ltiResourceLink",
        "title": item.title_en,
        "url": launch_url,
        "custom": {item.kind: item.id},
        "window": {"targetName": "tpm-viz"},
    }
    if item.graded and line_items and item.score_maximum:
        found["lineItem"] = {
            "scoreMaximum": item.score_maximum,
            "label": item.title_en,
            "resourceId": item.value,
            "tag": "tpm-viz",
        }
    return found


def response_jwt(
    pick: Pick, chosen: Sequence[str], catalogue: Sequence[Item], key: ToolKey, launch_url: str, now: float
) -> str:
    """The signed ``LtiDeepLinkingResponse`` of the items ``chosen`` (form values; unknown ones refused)."""
    known = {item.value: item for item in catalogue}
    unknown = [c for c in chosen if c not in known]
    if unknown:
        raise Refused(Why.REQUEST, Phrase("unknown item {item}: open the picker again", item=unknown[0][:80]))
    if len(chosen) > 1 and not pick.multiple:
        raise Refused(Why.DEEP_LINKING, T("the course takes one item here (deep linking): choose one"))
    items = [content_item(known[c], launch_url, pick.line_items) for c in dict.fromkeys(chosen)]
    claims: dict[str, Any] = {
        "iss": pick.platform.client_id,
        "aud": pick.platform.issuer,
        "iat": int(now),
        "exp": int(now) + RESPONSE_SECONDS,
        "nonce": secrets.token_urlsafe(24),
        CLAIM + "message_type": "LtiDeepLinkingResponse",
        CLAIM + "version": "1.3.0",
        CLAIM + "deployment_id": pick.deployment,
        DL + "content_items": items,
    }
    if pick.data is not None:
        claims[DL + "data"] = pick.data
    if items:
        claims[DL + "msg"] = f"tpm-viz: {len(items)} item(s) added"
    return key.sign(claims)
