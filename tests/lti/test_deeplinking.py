"""Deep linking: an instructor's request opens the picker (English or Korean), the choice comes back to the platform
as a signed LtiDeepLinkingResponse that the test platform checks against the tool's /lti/jwks, and a later launch of
a placed link opens what it names."""

from __future__ import annotations

import base64
import json

from jwcrypto.jwk import JWK

from tests.lti.conftest import launch, ref_of
from tests.lti.platform import DL, LTI, MEMBERSHIP, Link, Person, form_fields
from tpm_viz.app.lessons import DEMOS
from tpm_viz.core.words import Lang, say


def _picker(running, platform, hint: str = "teacher"):
    with running.client() as browser:
        answer = launch(browser, running, platform, hint, "dl")
    assert answer.status_code == 200, answer.text
    return answer


def _choose(running, picker, items: list[str], do: str = "add"):
    _, fields = form_fields(picker.text)
    with running.client() as browser:
        return browser.post(running.urls.picked, data={"pick": fields["pick"], "item": items, "do": do})


def _header(token: str) -> dict:
    head = token.split(".")[0]
    return json.loads(base64.urlsafe_b64decode(head + "=" * (-len(head) % 4)))


def test_the_picker_lists_the_lessons_and_the_exercises(running, platform):
    page = _picker(running, platform).text
    for demo in DEMOS:
        assert demo.title in page
    assert 'value="lesson:1"' in page and 'value="exercise:ex1"' in page
    assert "graded, out of 5 points" in page and 'lang="en"' in page


def test_the_picker_speaks_korean_to_a_korean_lms(running, platform):
    platform.people["kteacher"] = Person("k-sub", [MEMBERSHIP + "Instructor"], locale="ko-KR")
    page = _picker(running, platform, "kteacher").text
    assert 'lang="ko"' in page and say(Lang.KO, DEMOS[0].title) in page
    assert say(Lang.KO, "Choose what to add to the course") in page and "연습 1" in page
    assert "Choose what to add" not in page


def test_the_response_is_signed_by_the_tool_and_checked_by_the_platform(running, platform):
    answer = _choose(running, _picker(running, platform), ["lesson:3", "exercise:ex1"])
    assert answer.status_code == 200
    action, fields = form_fields(answer.text)
    assert action == f"{platform.url}/return" and set(fields) == {"JWT"}
    csp = answer.headers["content-security-policy"]
    assert f"form-action 'self' {platform.url}" in csp and "script-src 'nonce-" in csp
    kid = _header(fields["JWT"])["kid"]
    public = running.tool.key.private.public_key()
    assert kid == JWK.from_pyca(public).thumbprint()  # RFC 7638, computed by jwcrypto
    with running.client() as browser:
        assert browser.post(action, data=fields).status_code == 200  # the platform checked the signature
    (claims,) = platform.deep_link_answers
    assert claims["iss"] == platform.client_id and claims["aud"] == platform.issuer and claims["nonce"]
    assert claims[LTI + "message_type"] == "LtiDeepLinkingResponse" and claims[LTI + "version"] == "1.3.0"
    assert claims[LTI + "deployment_id"] == platform.deployment
    assert claims[DL + "data"] == "opaque-data-42"
    assert 0 < claims["exp"] - claims["iat"] <= 600
    lesson, exercise = claims[DL + "content_items"]
    assert lesson == {
        "type": "ltiResourceLink",
        "title": DEMOS[2].title,
        "url": running.urls.launch,
        "custom": {"lesson": "3"},
        "window": {"targetName": "tpm-viz"},
    }
    assert exercise["custom"] == {"exercise": "ex1"} and exercise["url"] == running.urls.launch
    assert exercise["lineItem"]["scoreMaximum"] == 5.0 and exercise["lineItem"]["label"] == exercise["title"]


def test_a_placed_link_opens_what_it_names(running, platform):
    answer = _choose(running, _picker(running, platform), ["lesson:3", "exercise:ex1"])
    action, fields = form_fields(answer.text)
    with running.client() as browser:
        browser.post(action, data=fields)
    items = platform.deep_link_answers[0][DL + "content_items"]
    for n, item in enumerate(items):
        platform.links[f"placed{n}"] = Link(custom=item["custom"])
    with running.client() as browser:
        lesson = ref_of(launch(browser, running, platform, "student", "placed0"), running.tickets)
        exercise = ref_of(launch(browser, running, platform, "student", "placed1"), running.tickets)
    assert (lesson.lesson, lesson.exercise) == (3, None)
    assert (exercise.lesson, exercise.exercise) == (None, "ex1")


def test_a_pick_is_good_once_and_cancel_sends_nothing(running, platform):
    picker = _picker(running, platform)
    cancelled = _choose(running, picker, ["lesson:1"], do="cancel")
    _, fields = form_fields(cancelled.text)
    payload = fields["JWT"].split(".")[1]
    claims = json.loads(base64.urlsafe_b64decode(payload + "=" * (-len(payload) % 4)))
    assert claims[DL + "content_items"] == [] and DL + "msg" not in claims
    again = _choose(running, picker, ["lesson:1"])
    assert again.status_code == 400 and 'data-why="state"' in again.text


def test_an_unknown_item_is_refused(running, platform):
    answer = _choose(running, _picker(running, platform), ["exercise:nope"])
    assert answer.status_code == 400 and "unknown item" in answer.text
