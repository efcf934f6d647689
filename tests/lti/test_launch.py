"""Login and launch against the test platform (its authorisation endpoint form-posts the id_token): every parameter
of the redirect, a Learner and an Instructor, the same user from two browsers, roles, and the one-time ticket."""

from __future__ import annotations

from urllib.parse import parse_qs, urlsplit

import pytest

from tests.lti.conftest import launch, login
from tests.lti.platform import MEMBERSHIP, Person, auth_params, form_fields
from tpm_viz.classroom.launches import Role
from tpm_viz.lti.checks import role_of
from tpm_viz.lti.service import Urls, state_cookie


def _through_platform(client, running, platform, hint: str, message: str):
    """The whole flow as a browser makes it: tool login -> platform authorisation -> form post -> tool launch."""
    answer = client.get(running.urls.login, params=platform.login_query(running.urls.launch, hint, message))
    assert answer.status_code == 302
    page = client.get(answer.headers["location"])
    assert page.status_code == 200, page.text
    action, fields = form_fields(page.text)
    assert action == running.urls.launch and set(fields) == {"id_token", "state"}
    return client.post(action, data=fields)


def _arrive(running, answer) -> object:
    """The app's side of the ticket: the page spends it, the websocket takes its launch."""
    assert answer.status_code == 303, answer.text
    target = urlsplit(answer.headers["location"])
    ticket = parse_qs(target.query)["lti"][0]
    came, found = running.tickets.take(running.tickets.arrive(ticket))
    assert came
    return found


def test_the_login_redirects_to_the_platform_with_every_parameter(running, platform):
    with running.client() as client:
        query = platform.login_query(running.urls.launch, "student", "plain")
        answer = client.get(running.urls.login, params=query)
        assert answer.status_code == 302
        location = answer.headers["location"]
        assert location.startswith(f"{platform.url}/auth?")
        params = {k: v for k, (v,) in parse_qs(urlsplit(location).query).items()}
        assert params.pop("state") and params.pop("nonce")
        assert params == {
            "scope": "openid",
            "response_type": "id_token",
            "response_mode": "form_post",
            "prompt": "none",
            "client_id": platform.client_id,
            "redirect_uri": running.urls.launch,
            "login_hint": "student",
            "lti_message_hint": "plain",
        }
        state = parse_qs(urlsplit(location).query)["state"][0]
        cookie = answer.headers["set-cookie"]
        assert f"{state_cookie(state)}={state}" in cookie and "HttpOnly" in cookie and "Path=/lti" in cookie
        assert "samesite=lax" in cookie.lower()  # plain http here: no Secure cookie can exist (docs/lti.md)
        again = client.post(running.urls.login, data=query)  # the platform may POST the login as well
        assert again.status_code == 302 and again.headers["location"] != location  # a fresh state and nonce


def test_a_learner_arrives_as_a_student_and_an_instructor_as_the_presenter(running, platform):
    with running.client() as student, running.client() as teacher:
        learner = _arrive(running, _through_platform(student, running, platform, "student", "plain"))
        instructor = _arrive(running, _through_platform(teacher, running, platform, "teacher", "plain"))
    assert learner.role is Role.STUDENT and instructor.role is Role.PRESENTER
    assert learner.course == instructor.course == "Mechanisms 101"
    assert learner.user != instructor.user and learner.lang == "ko-KR"
    counts = running.ledger.counts()
    assert counts["lti_users"] == 2 and counts["lti_launches"] == 2 and counts["lti_class"] == 1
    assert running.ledger.course() == {"issuer": platform.issuer, "id": "course-7", "title": "Mechanisms 101"}


def test_the_same_lms_user_is_the_same_identity_from_every_launch_and_browser(running, platform):
    users = []
    for _ in range(3):
        with running.client() as browser:  # a new device each time: no cookie shared
            users.append(_arrive(running, _through_platform(browser, running, platform, "student", "plain")))
    assert len({u.user for u in users}) == 1 and len({u.ref for u in users}) == 3
    assert running.ledger.counts()["lti_users"] == 1


def test_the_ticket_works_once_and_in_one_browser_only(running, platform):
    with running.client() as browser:
        answer = _through_platform(browser, running, platform, "student", "plain")
    ticket = parse_qs(urlsplit(answer.headers["location"]).query)["lti"][0]
    first = running.tickets.arrive(ticket)
    second = running.tickets.arrive(ticket)  # the same URL opened again, here or in another browser
    assert running.tickets.take(first)[1] is not None
    assert running.tickets.take(second) == (True, None)  # it came with a ticket, which gave nothing
    assert running.tickets.take(first) == (False, None)  # the page's nonce is taken once too


def test_a_link_to_a_lesson_opens_it(running, platform):
    with running.client() as browser:
        found = _arrive(running, _through_platform(browser, running, platform, "student", "lesson3"))
    assert found.lesson == 3 and found.exercise is None


def test_a_replayed_launch_post_gets_nothing_the_second_time(running, platform):
    with running.client() as browser:
        auth = login(browser, running, platform, "student", "plain")
        form = {"id_token": platform.id_token(platform.claims(auth)), "state": auth["state"]}
        assert browser.post(running.urls.launch, data=form).status_code == 303
        again = browser.post(running.urls.launch, data=form)
    assert again.status_code == 400 and "replayed" in again.text
    assert running.ledger.counts()["lti_launches"] == 1


@pytest.mark.parametrize(
    ("roles", "role"),
    [
        ([MEMBERSHIP + "Instructor"], Role.PRESENTER),
        (["http://purl.imsglobal.org/vocab/lis/v2/membership/Instructor#TeachingAssistant"], Role.PRESENTER),
        ([MEMBERSHIP + "Administrator"], Role.PRESENTER),
        (["http://purl.imsglobal.org/vocab/lis/v2/institution/person#Instructor"], Role.PRESENTER),
        (["Instructor"], Role.PRESENTER),  # LTI 1.1's short name
        ([MEMBERSHIP + "Learner"], Role.STUDENT),
        ([MEMBERSHIP + "Mentor"], Role.STUDENT),
        # an institution's instructor who is a learner in this course learns here
        (
            [MEMBERSHIP + "Learner", "http://purl.imsglobal.org/vocab/lis/v2/institution/person#Instructor"],
            Role.STUDENT,
        ),
    ],
)
def test_roles(roles, role):
    assert role_of(roles) is role


def test_a_teaching_assistant_launch_presents(running, platform):
    platform.people["ta"] = Person(
        "ta-sub", ["http://purl.imsglobal.org/vocab/lis/v2/membership/Instructor#TeachingAssistant"]
    )
    with running.client() as browser:
        assert _arrive(running, launch(browser, running, platform, "ta")).role is Role.PRESENTER


def test_over_https_the_state_cookie_survives_a_cross_site_post_and_is_required(running, platform):
    """Behind a TLS proxy with a path prefix (the tool's public URL is https://tpm.example/tpm)."""
    public = Urls("https://tpm.example/tpm", "https://tpm.example/tpm/")
    running.tool.urls = public
    with running.client() as browser:
        query = platform.login_query(public.launch, "student", "plain")
        answer = browser.get(f"http://127.0.0.1:{running.server.port}/lti/login", params=query)
    assert answer.status_code == 302
    assert auth_params(answer.headers["location"])["redirect_uri"] == "https://tpm.example/tpm/lti/launch"
    cookie = answer.headers["set-cookie"].lower()
    for part in ("samesite=none", "secure", "partitioned", "httponly", "path=/tpm/lti"):
        assert part in cookie, cookie
    assert running.tool.must_have_cookie
