"""Every refusal of a login or a launch: a 4xx page of one line with the word a lecturer looks for, logged once, no
traceback, and nothing created (no user, no launch, no course binding, no ticket). Tampered claims are made by the
test platform and signed by its key (or by another), as an attacker or a misconfigured LMS would send them."""

from __future__ import annotations

import logging
import re
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.lti.conftest import launch, login, start_tool
from tests.lti.platform import LTI, Key
from tests.support.hypo import examples
from tpm_viz.lti.bounds import Rate

WORD = re.compile(r'data-why="([^"]+)"')


def _refused(answer, word: str, caplog, status: int = 400) -> None:
    assert answer.status_code == status, answer.text
    assert WORD.search(answer.text).group(1) == word
    line = re.search(r'<p class="why"[^>]*>([^<]*)</p>', answer.text).group(1)
    assert f"({word}" in line or f"{word})" in line or f" {word} " in line, line  # the word is in the line
    assert "Traceback" not in answer.text and "\n" not in line
    records = [r for r in caplog.records if r.name == "tpm_viz.lti" and r.levelno == logging.WARNING]
    assert len(records) == 1 and f"({word})" in records[0].getMessage(), [r.getMessage() for r in records]
    assert records[0].exc_info is None


def _nothing_created(running) -> None:
    assert running.ledger.counts() == {
        "lti_users": 0, "lti_class": 0, "lti_launches": 0, "lti_outbox": 0, "lti_grades": 0,
    }  # fmt: skip
    assert len(running.tickets) == 0


def _set(name: str, value):
    def tamper(claims: dict) -> None:
        claims[name] = value

    return tamper


def _drop(name: str):
    def tamper(claims: dict) -> None:
        claims.pop(name, None)

    return tamper


LAUNCH_REFUSALS = {
    "wrong aud": (_set("aud", "someone-else"), "audience"),
    "aud list without azp": (lambda c: (c.update(aud=[c["aud"], "other"]), c.pop("azp")), "audience"),
    "wrong azp": (_set("azp", "someone-else"), "audience"),
    "wrong iss": (_set("iss", "https://evil.example"), "issuer"),
    "expired": (lambda c: c.update(exp=int(time.time()) - 120, iat=int(time.time()) - 600), "expired"),
    "issued in the future": (lambda c: c.update(iat=int(time.time()) + 600, exp=int(time.time()) + 900), "expired"),
    "no exp": (_drop("exp"), "expired"),
    "another nonce": (_set("nonce", "made-up-nonce"), "nonce"),
    "unknown deployment": (_set(LTI + "deployment_id", "dep-999"), "deployment"),
    "missing roles": (_drop(LTI + "roles"), "role"),
    "empty roles": (_set(LTI + "roles", []), "role"),
    "wrong version": (_set(LTI + "version", "1.1.0"), "version"),
    "wrong message type": (_set(LTI + "message_type", "LtiSubmissionReviewRequest"), "message type"),
    "no user": (_drop("sub"), "user"),
    "another target": (_set(LTI + "target_link_uri", "https://evil.example/x"), "link"),
}


@pytest.mark.parametrize("case", sorted(LAUNCH_REFUSALS))
def test_a_tampered_launch_is_refused_with_its_word_and_creates_nothing(running, platform, caplog, case):
    tamper, word = LAUNCH_REFUSALS[case]
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        answer = launch(browser, running, platform, "student", "plain", tamper=tamper)
    _refused(answer, word, caplog)
    _nothing_created(running)


def test_a_bad_signature_is_refused(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    forger = Key(platform.key.kid)  # another key claiming the platform's kid
    with running.client() as browser:
        _refused(launch(browser, running, platform, key=forger), "signature", caplog)
    _nothing_created(running)


def test_an_unknown_key_is_refused_after_one_refetch_of_the_key_set(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        assert launch(browser, running, platform, "student", "plain").status_code == 303  # the key set is cached
        fetched = running.tool.keysets.fetches
        caplog.clear()
        running.ledger_before = running.ledger.counts()
        running.tool.keysets.refetch_seconds = 0.0  # an unknown kid may refetch at once
        answer = launch(browser, running, platform, key=Key("stranger"))
    _refused(answer, "key", caplog)
    assert running.tool.keysets.fetches == fetched + 1  # refetched once for the unknown kid, then refused
    assert running.ledger.counts() == running.ledger_before


def test_a_rolled_over_platform_key_is_found_by_one_refetch(running, platform):
    with running.client() as browser:
        assert launch(browser, running, platform).status_code == 303
        new = Key("platform-key-2")
        platform.keys = [platform.key, new]  # the platform publishes its next key
        running.tool.keysets.refetch_seconds = 0.0
        fetched = running.tool.keysets.fetches
        assert launch(browser, running, platform, key=new).status_code == 303
        assert running.tool.keysets.fetches == fetched + 1


def test_a_flood_of_made_up_kids_costs_the_platform_one_fetch_per_interval(running, platform):
    with running.client() as browser:
        assert launch(browser, running, platform).status_code == 303
        fetched = running.tool.keysets.fetches
        for n in range(5):  # within REFETCH_SECONDS of the first fetch: no new fetch
            assert launch(browser, running, platform, key=Key(f"k{n}")).status_code == 400
    assert running.tool.keysets.fetches == fetched


def test_a_replayed_nonce_is_refused(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        first = login(browser, running, platform, "student", "plain")
        used = platform.claims(first)
        assert browser.post(running.urls.launch, data={"id_token": platform.id_token(used), "state": first["state"]})
        before = running.ledger.counts()
        caplog.clear()
        again = launch(browser, running, platform, tamper=_set("nonce", used["nonce"]))  # a fresh state, an old nonce
    _refused(again, "nonce", caplog)
    assert running.ledger.counts() == before


def test_a_wrong_or_missing_state_is_refused(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        auth = login(browser, running, platform, "student", "plain")
        token = platform.id_token(platform.claims(auth))
        _refused(browser.post(running.urls.launch, data={"id_token": token, "state": "made-up"}), "state", caplog)
        caplog.clear()
        _refused(browser.post(running.urls.launch, data={"id_token": token}), "state", caplog)
    _nothing_created(running)


def test_with_the_cookie_required_another_browser_cannot_use_a_login(tmp_path, platform, caplog):
    """Login CSRF: a login started in one browser is finished in another (the state cookie is not there)."""
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    strict = start_tool(tmp_path, platform, cookie_required=True)
    try:
        with strict.client() as attacker, strict.client() as victim:
            auth = login(attacker, strict, platform, "student", "plain")
            form = {"id_token": platform.id_token(platform.claims(auth)), "state": auth["state"]}
            _refused(victim.post(strict.urls.launch, data=form), "state", caplog)
            _nothing_created(strict)
            assert launch(attacker, strict, platform).status_code == 303  # its own browser: fine
    finally:
        strict.server.stop()
        strict.ledger.close()


LOGIN_REFUSALS = {
    "unknown issuer": ({"iss": "https://evil.example"}, "issuer"),
    "unknown client": ({"client_id": "nobody"}, "audience"),
    "unknown deployment": ({"lti_deployment_id": "dep-999"}, "deployment"),
    "another target": ({"target_link_uri": "https://evil.example/lti/launch"}, "link"),
    "no login hint": ({"login_hint": ""}, "request"),
}


@pytest.mark.parametrize("case", sorted(LOGIN_REFUSALS))
def test_a_bad_login_is_refused(running, platform, caplog, case):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    change, word = LOGIN_REFUSALS[case]
    query = {**platform.login_query(running.urls.launch, "student", "plain"), **change}
    with running.client() as browser:
        _refused(browser.get(running.urls.login, params=query), word, caplog)
    assert len(running.tool.logins) == 0


def test_another_course_is_refused_naming_both(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        assert launch(browser, running, platform).status_code == 303
        before = running.ledger.counts()
        caplog.clear()
        answer = launch(browser, running, platform, tamper=_set(LTI + "context", {"id": "c-8", "title": "Fluids 202"}))
    _refused(answer, "course", caplog, status=409)
    assert "Mechanisms 101" in answer.text and "Fluids 202" in answer.text
    assert running.ledger.counts() == before


def test_a_student_cannot_deep_link(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    with running.client() as browser:
        _refused(launch(browser, running, platform, "student", "dl"), "role", caplog, status=403)
    _nothing_created(running)


def test_a_body_too_large_and_too_many_requests(running, platform, caplog):
    caplog.set_level(logging.INFO, logger="tpm_viz.lti")
    running.tool.rate = Rate(clock=lambda: 0.0)  # the clock stands still: no token comes back during the burst
    with running.client() as browser:
        _refused(browser.post(running.urls.launch, data={"id_token": "x" * 70_000}), "too large", caplog, 413)
        caplog.clear()
        answers = [browser.get(running.urls.login, params={"iss": "x"}) for _ in range(40)]
    assert {a.status_code for a in answers} == {400, 429}  # the burst of 30 a minute, then 429
    assert sum(a.status_code == 429 for a in answers) == 10


@pytest.fixture
def roomy(tmp_path, platform):
    found = start_tool(tmp_path, platform, rate=Rate(per_minute=1e9, burst=1e9))
    yield found
    found.server.stop()
    found.ledger.close()


CLAIMS = ["iss", "aud", "azp", "sub", "exp", "iat", "nonce", *(LTI + n for n in ("version", "message_type",
          "deployment_id", "roles", "target_link_uri", "resource_link"))]  # fmt: skip
VALUES = st.one_of(
    st.none(), st.integers(-(2**40), 2**40), st.text(max_size=20), st.lists(st.text(max_size=5), max_size=3)
)


@settings(max_examples=examples(40), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(changes=st.dictionaries(st.sampled_from(CLAIMS), VALUES, min_size=1, max_size=3))
def test_any_tampered_claim_is_refused_or_harmless_and_never_a_500(roomy, platform, changes):
    """Whatever a forger puts in the signed claims: a 4xx with a known word and nothing created, or (when the
    change happens to be valid, e.g. the same value) a normal launch."""
    before = roomy.ledger.counts()
    with roomy.client() as browser:
        answer = launch(browser, roomy, platform, tamper=lambda c: c.update(changes))
    assert answer.status_code in (303, 400, 403, 409), answer.text
    if answer.status_code != 303:
        assert WORD.search(answer.text) and "Traceback" not in answer.text
        assert roomy.ledger.counts() == before
