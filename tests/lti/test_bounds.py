"""The LTI service's bounds, each with an injected clock: waiting logins per address and in all, tickets and their
arrivals in time and number, the per-address rate, a streamed body without a length, and the refusal log in a flood."""

from __future__ import annotations

import logging

import httpx
import pytest

from tpm_viz.classroom import launches as launches_module
from tpm_viz.classroom.launches import TICKET_SECONDS, Launch, Role, Tickets, ticket_of_query
from tpm_viz.core.words import T
from tpm_viz.lti import logins as logins_module
from tpm_viz.lti import refusals
from tpm_viz.lti.bounds import MAX_BODY_BYTES, Rate
from tpm_viz.lti.config import Platform
from tpm_viz.lti.logins import LOGIN_SECONDS, MAX_LOGINS_PER_ADDRESS, Logins
from tpm_viz.lti.refusals import Refused, Why

PLATFORM = Platform("https://lms", "c", ("d",), "https://lms/a", "https://lms/t", "https://lms/k")
LAUNCH = Launch("ref", "0" * 32, Role.STUDENT, "Course")


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_one_address_cannot_push_out_another_s_logins():
    clock = Clock()
    logins = Logins(clock)
    other = logins.begin(PLATFORM, "t", "r", "198.51.100.1")
    mine = [logins.begin(PLATFORM, "t", "r", "192.0.2.9") for _ in range(MAX_LOGINS_PER_ADDRESS + 10)]
    assert len(logins) == MAX_LOGINS_PER_ADDRESS + 1
    assert logins.finish(other.state) == other  # still there
    with pytest.raises(Refused) as caught:
        logins.finish(mine[0].state)  # that address's oldest went
    assert caught.value.why is Why.STATE
    assert logins.finish(mine[-1].state) == mine[-1]


def test_logins_expire_and_a_spent_state_is_a_replay(monkeypatch):
    clock = Clock()
    monkeypatch.setattr(logins_module, "MAX_LOGINS", 3)
    logins = Logins(clock)
    first = logins.begin(PLATFORM, "t", "r", "a1")
    assert logins.finish(first.state) == first
    with pytest.raises(Refused) as caught:
        logins.finish(first.state)
    assert caught.value.why is Why.REPLAYED
    late = logins.begin(PLATFORM, "t", "r", "a2")
    clock.now += LOGIN_SECONDS + 1
    with pytest.raises(Refused) as caught:
        logins.finish(late.state)
    assert caught.value.why is Why.STATE
    for n in range(5):
        logins.begin(PLATFORM, "t", "r", f"b{n}")
    assert len(logins) == 3  # at most MAX_LOGINS, the oldest went


def test_tickets_expire_and_are_bounded(monkeypatch):
    clock = Clock()
    monkeypatch.setattr(launches_module, "MAX_TICKETS", 4)
    tickets = Tickets(clock=clock)
    old = tickets.issue(LAUNCH)
    clock.now += TICKET_SECONDS + 1
    assert tickets.take(tickets.arrive(old)) == (True, None)  # expired: the page came with it, it gave nothing
    issued = [tickets.issue(LAUNCH) for _ in range(6)]
    assert tickets.take(tickets.arrive(issued[0]))[1] is None  # pushed out by the newer ones
    assert tickets.take(tickets.arrive(issued[-1]))[1] == LAUNCH


def test_a_ticket_in_a_query():
    good = "A" * 32
    assert ticket_of_query(f"lti={good}") == good
    assert ticket_of_query("share=x") is None
    assert ticket_of_query("lti=short") == "" and ticket_of_query("lti=" + "<" * 40) == ""


def test_the_rate_refills_with_time():
    clock = Clock()
    rate = Rate(per_minute=60, burst=3, addresses=2, clock=clock)
    assert [rate.allow("a") for _ in range(4)] == [True, True, True, False]
    clock.now += 1.0  # one token a second
    assert rate.allow("a") and not rate.allow("a")
    rate.allow("b")
    rate.allow("c")  # three addresses: the least recently seen ("a") is forgotten, with its empty bucket
    assert [rate.allow("a") for _ in range(4)] == [True, True, True, False]


def test_a_streamed_body_without_a_length_is_cut_at_the_limit(running):
    def chunks():
        for _ in range(MAX_BODY_BYTES // 1024 + 2):
            yield b"x" * 1024

    with httpx.Client(timeout=10) as client:
        answer = client.post(running.urls.launch, content=chunks())
    assert answer.status_code == 413 and 'data-why="too large"' in answer.text


def test_a_flood_of_refusals_is_counted_not_written_line_by_line(caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    refused = Refused(Why.STATE, T("the request is not a form this tool takes"))
    for _ in range(refusals.LINES_PER_SECOND * 3):
        refusals.log_refusal(refused, "192.0.2.1", "/lti/launch")
    lines = [r for r in caplog.records if r.name == "tpm_viz.lti"]
    assert 1 <= len(lines) <= 2 * refusals.LINES_PER_SECOND  # at most two windows of a second
