"""A checked launch becomes a user, a launch record and a one-time ticket (or, for deep linking, a picker).

:func:`resource_launch` writes the records (:meth:`~tpm_viz.lti.ledger.Ledger.record_launch`: the class's course,
the user's server-issued identity, the launch) and issues the ticket the browser takes to the app
(:class:`~tpm_viz.classroom.launches.Tickets`); :func:`app_url` is where it goes. :func:`connect_browsers` lets
the app find the launch of a browser that reconnects (``Tickets.recall``) through the store.
"""

from __future__ import annotations

from typing import Any
from urllib.parse import urlencode

from tpm_viz.classroom.launches import LTI_PARAMETER, Launch, Role, Tickets
from tpm_viz.lti.checks import Claims
from tpm_viz.lti.config import Platform
from tpm_viz.lti.ledger import Ledger

__all__ = ["app_url", "connect_browsers", "launch_of", "resource_launch"]


def launch_of(record: dict[str, Any]) -> Launch | None:
    """The app's :class:`Launch` of a launch record of the ledger (None if the record is not one)."""
    try:
        return Launch(
            ref=str(record["ref"]),
            user=str(record["user"]),
            role=Role(record["role"]),
            course=str(record["course"]),
            lesson=record.get("lesson") if isinstance(record.get("lesson"), int) else None,
            exercise=record.get("exercise") if isinstance(record.get("exercise"), str) else None,
            lang=str(record.get("locale", "")),
        )
    except (KeyError, ValueError, TypeError):
        return None


def resource_launch(claims: Claims, platform: Platform, ledger: Ledger, tickets: Tickets) -> tuple[Launch, str]:
    """Records of a checked ``LtiResourceLinkRequest`` (refused with *course* if the class is another course's)
    and its ticket: ``(launch, ticket)``."""
    ags = claims.ags or {}
    found = ags.get("scope")
    scopes: list[Any] = found if isinstance(found, list) else []
    body = {
        "issuer": platform.issuer,
        "client_id": platform.client_id,
        "deployment": claims.deployment,
        "subject": claims.subject,
        "role": claims.role.value,
        "course": claims.course,
        "course_id": claims.course_id,
        "lesson": claims.lesson,
        "exercise": claims.exercise,
        "locale": claims.locale,
        "lineitem": ags.get("lineitem") if isinstance(ags.get("lineitem"), str) else None,
        "scopes": [s for s in scopes if isinstance(s, str)][:20],
    }
    course = {"issuer": platform.issuer, "id": claims.course_id, "title": claims.course}
    user, ref = ledger.record_launch(platform.issuer, claims.subject, course, body)
    launch = launch_of({**body, "ref": ref, "user": user})
    assert launch is not None
    return launch, tickets.issue(launch)


def app_url(base: str, ticket: str) -> str:
    """The app's URL that spends ``ticket`` (``base``: the app's public URL)."""
    root = base if base.endswith("/") else base + "/"
    return f"{root}?{urlencode({LTI_PARAMETER: ticket})}"


def connect_browsers(tickets: Tickets, ledger: Ledger) -> None:
    """Keep, in the store, which browser each launch arrived in, and find it again for a tab that reconnects."""

    def remember(browser: str, launch: Launch) -> None:
        ledger.arrived(launch.ref, browser)

    def recall(browser: str) -> Launch | None:
        record = ledger.launch_of_browser(browser)
        return None if record is None else launch_of(record)

    tickets.remember, tickets.recall = remember, recall
    bound = ledger.course()
    if bound is not None:
        tickets.course = str(bound.get("title", ""))
