"""Fixtures of the LTI tests: the test platform (:mod:`tests.lti.platform`), the tool's files (its key and
configuration, made by the tool's own commands) and the LTI service on loopback, without the app
(:class:`Running`)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

import httpx
import pytest

from tests.lti.platform import MEMBERSHIP, READ, SCORE, Item, Link, Person, TestPlatform, auth_params
from tpm_viz.app.lessons import DEMOS
from tpm_viz.classroom.launches import Tickets
from tpm_viz.lti import refusals
from tpm_viz.lti.config import read_config
from tpm_viz.lti.deeplinking import Item as Offered
from tpm_viz.lti.deeplinking import lessons_catalogue
from tpm_viz.lti.keys import ToolKey, keygen
from tpm_viz.lti.ledger import Ledger
from tpm_viz.lti.service import LtiServer, Tool, Urls, build_asgi

EXERCISES = [Offered("exercise", "ex1", "Exercise 1: the direct singularity", "연습 1", graded=True, score_maximum=5.0)]
"""The exercises the tests' catalogue offers (the exercise engine's stand-in)."""


@pytest.fixture
def platform() -> Iterator[TestPlatform]:
    lms = TestPlatform().start()
    lms.people["teacher"] = Person("teacher-sub", [MEMBERSHIP + "Instructor"], locale="en-US")
    lms.people["student"] = Person("student-sub", [MEMBERSHIP + "Learner"], locale="ko-KR")
    lms.people["student2"] = Person("student2-sub", [MEMBERSHIP + "Learner"])
    lms.links["plain"] = Link()
    lms.links["lesson3"] = Link(custom={"lesson": "3"})
    lms.links["graded"] = Link(custom={"exercise": "ex1"}, lineitem="li-1", scopes=[SCORE, READ])
    lms.links["graded-noread"] = Link(custom={"exercise": "ex1"}, lineitem="li-2", scopes=[SCORE])
    lms.links["dl"] = Link(message_type="LtiDeepLinkingRequest")
    lms.items["li-1"] = Item(score_maximum=10.0, label="Exercise 1")
    lms.items["li-2"] = Item(score_maximum=20.0, label="Exercise 1 again")
    yield lms
    lms.stop()


def write_config(folder: Path, platform: TestPlatform, extra: str = "", extra_platforms: str = "") -> Path:
    """The tool's key (``keygen``) and a configuration naming ``platform`` (and ``extra_platforms``), in
    ``folder``."""
    keygen(folder / "keys")
    path = folder / "lti.toml"
    text = f'[tool]\nprivate_key = "keys/tool-key.pem"\nport = 0\n{extra}\n{platform.config()}\n{extra_platforms}'
    path.write_text(text)
    return path


@dataclass
class Running:
    """The LTI service on loopback, without the app."""

    tool: Tool
    server: LtiServer
    ledger: Ledger
    tickets: Tickets

    @property
    def urls(self) -> Urls:
        return self.tool.urls

    def client(self) -> httpx.Client:
        """A browser of its own (a cookie jar), following no redirect."""
        return httpx.Client(timeout=10, follow_redirects=False)


def start_tool(
    folder: Path, platform: TestPlatform, store: Path | None = None, extra_platforms: str = "", **options: Any
) -> Running:
    config = read_config(write_config(folder, platform, extra_platforms=extra_platforms))
    key = ToolKey.read(config.private_key)
    ledger = Ledger(store or folder / "store.sqlite3")
    tickets = Tickets()
    server = LtiServer("127.0.0.1", 0)
    urls = Urls(f"http://127.0.0.1:{server.port}", "http://127.0.0.1:9/")
    tool = Tool(config, key, ledger, tickets, lessons_catalogue(DEMOS, lambda: list(EXERCISES)), urls, **options)
    server.start(build_asgi(tool))
    platform.tool_jwks = urls.jwks
    platform.redirect_uris = [urls.launch, urls.deeplink]
    return Running(tool, server, ledger, tickets)


@pytest.fixture
def running(tmp_path: Path, platform: TestPlatform) -> Iterator[Running]:
    found = start_tool(tmp_path, platform)
    yield found
    found.server.stop()
    found.ledger.close()


def login(client: httpx.Client, running: Running, platform: TestPlatform, hint: str, message: str) -> dict[str, str]:
    """The platform starts a login at the tool; the tool's redirect's query (state, nonce, ...)."""
    query = platform.login_query(running.urls.launch, hint, message)
    answer = client.get(running.urls.login, params=query)
    assert answer.status_code == 302, answer.text
    return auth_params(answer.headers["location"])


def launch(
    client: httpx.Client,
    running: Running,
    platform: TestPlatform,
    hint: str = "student",
    message: str = "plain",
    tamper: Callable[[dict[str, Any]], None] | None = None,
    **sign: Any,
) -> httpx.Response:
    """Login, then the launch POST of a (tampered) id_token signed by the platform."""
    auth = login(client, running, platform, hint, message)
    claims = platform.claims(auth)
    if tamper is not None:
        tamper(claims)
    return client.post(
        running.urls.launch, data={"id_token": platform.id_token(claims, **sign), "state": auth["state"]}
    )


def until(predicate: Callable[[], Any], what: str, timeout: float = 30.0) -> Any:
    """Poll ``predicate`` until it is truthy (returned) or fail after ``timeout`` s (a bound, not a speed)."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.01)


def ref_of(answer: httpx.Response, tickets: Tickets) -> Any:
    """The launch a successful launch's redirect carries (its ticket spent as the app would)."""
    assert answer.status_code == 303, answer.text
    ticket = parse_qs(urlsplit(answer.headers["location"]).query)["lti"][0]
    return tickets.take(tickets.arrive(ticket))[1]


@pytest.fixture(autouse=True)
def fresh_refusal_log() -> None:
    """Each test starts with a fresh second of the refusal log (a flood in the test before must not silence it)."""
    refusals._window[:] = [0.0, 0, 0]
