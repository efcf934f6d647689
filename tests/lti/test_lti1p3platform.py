"""The tool against ``lti1p3platform`` (a Python LTI 1.3 platform no one here wrote): its OIDC login initiation,
its resource-link and deep-linking launch messages (signed by its key, ``kid`` its own thumbprint), its check of the
tool's deep-linking response against the tool's /lti/jwks, and its token endpoint checking the tool's client
assertion. Its key set is served by the test platform's /jwks (lti1p3platform has no HTTP server of its own)."""

from __future__ import annotations

from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

import httpx
import pytest
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric import rsa

from tests.lti.conftest import EXERCISES, ref_of, start_tool
from tests.lti.platform import form_fields
from tpm_viz.classroom.launches import Role
from tpm_viz.lti.tokens import SCORE_SCOPE, Tokens

lti1p3 = pytest.importorskip("lti1p3platform")
from lti1p3platform.ltiplatform import LTI1P3PlatformConfAbstract  # noqa: E402
from lti1p3platform.message_launch import LTIAdvantageMessageLaunchAbstract  # noqa: E402
from lti1p3platform.oidc_login import OIDCLoginAbstract  # noqa: E402
from lti1p3platform.registration import Registration  # noqa: E402

ISSUER = "https://lti1p3platform.test"
CLIENT = "lib-client"
DEPLOYMENT = "lib-dep"
ROLE = "http://purl.imsglobal.org/vocab/lis/v2/membership#"


class Conf(LTI1P3PlatformConfAbstract):
    def init_platform_config(self, **kwargs: Any) -> None:
        self.registration = kwargs["registration"]

    def get_registration_by_params(self, **kwargs: Any) -> Registration:
        return self.registration


class Login(OIDCLoginAbstract):
    def set_lti_message_hint(self, **kwargs: Any) -> None:
        self._lti_message_hint = kwargs["hint"]

    def get_redirect(self, url: str) -> str:
        return url


class Launch(LTIAdvantageMessageLaunchAbstract):
    def __init__(self, preflight: dict[str, str], conf: Conf) -> None:
        super().__init__(None, conf)
        self.preflight = preflight

    def get_preflight_response(self) -> dict[str, Any]:
        return self.preflight

    def render_launch_form(self, launch_data: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        return launch_data


class Jwk:
    def __init__(self, jwk: dict[str, Any]) -> None:
        self.jwk = jwk


@pytest.fixture
def library(tmp_path: Path, platform):
    private = rsa.generate_private_key(public_exponent=65537, key_size=2048)
    pem = private.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
    ).decode()
    public = (
        private.public_key()
        .public_bytes(serialization.Encoding.PEM, serialization.PublicFormat.SubjectPublicKeyInfo)
        .decode()
    )
    platform.keys.append(Jwk(Registration.get_jwk(public)))  # served at the test platform's /jwks
    table = (
        f'[[platform]]\nissuer = "{ISSUER}"\nclient_id = "{CLIENT}"\ndeployment_ids = ["{DEPLOYMENT}"]\n'
        f'auth_login_url = "{ISSUER}/auth"\nauth_token_url = "{ISSUER}/token"\nkey_set_url = "{platform.url}/jwks"\n'
    )
    running = start_tool(tmp_path, platform, extra_platforms=table)
    registration = (
        Registration()
        .set_iss(ISSUER)
        .set_client_id(CLIENT)
        .set_deployment_id(DEPLOYMENT)
        .set_oidc_login_url(running.urls.login)
        .set_launch_url(running.urls.launch)
        .set_platform_public_key(public)
        .set_platform_private_key(pem)
        .set_tool_key_set_url(running.urls.jwks)
    )
    yield running, registration
    running.server.stop()
    running.ledger.close()


def _launch(running, registration: Registration, roles: list[str], deep: bool = False, **claims: Any):
    conf = Conf(registration=registration)
    login = Login(None, conf)
    login.set_lti_message_hint(hint="msg-1")
    if deep:
        registration.set_deeplink_launch_url(running.urls.deeplink)
        login.set_deeplinking_launch_url()
    browser = httpx.Client(timeout=10, follow_redirects=False)
    answer = browser.get(login.initiate_login("lib-user-1"))  # the library's login initiation URL
    assert answer.status_code == 302, answer.text
    preflight = {k: v[0] for k, v in parse_qs(urlsplit(answer.headers["location"]).query).items()}
    message = Launch(preflight, conf)
    message.set_user_data("lib-user-1", roles)
    message.set_launch_context_claim("lib-course", context_title="Robotics 300")
    message.set_resource_link_claim("rl-1", title="A link")
    if claims.get("custom"):
        message.set_custom_parameters_claim(claims["custom"])
    if deep:
        message.set_dl(f"{ISSUER}/return", accept_types={"ltiResourceLink"}, extra_data={"k": "v"})
    data = message.lti_launch()  # checks the tool's authorisation request, then signs the id_token
    return browser, browser.post(data["launch_url"], data={"id_token": data["id_token"], "state": data["state"]})


def test_the_library_s_launch_is_accepted_as_a_student_and_opens_its_lesson(library):
    running, registration = library
    browser, answer = _launch(running, registration, [ROLE + "Learner"], custom={"lesson": "2"})
    found = ref_of(answer, running.tickets)
    assert (found.role, found.course, found.lesson) == (Role.STUDENT, "Robotics 300", 2)
    browser.close()


def test_the_library_checks_the_tools_deep_linking_response(library):
    running, registration = library
    browser, picker = _launch(running, registration, [ROLE + "Instructor"], deep=True)
    assert picker.status_code == 200, picker.text
    _, fields = form_fields(picker.text)
    answer = browser.post(running.urls.picked, data={"pick": fields["pick"], "item": ["lesson:1", "exercise:ex1"]})
    _, posted = form_fields(answer.text)
    conf = Conf(registration=registration)
    conf.get_registration()
    items = conf.validate_deeplinking_resp({"JWT": posted["JWT"]})  # fetches /lti/jwks, checks the signature
    assert [i["custom"] for i in items] == [{"lesson": "1"}, {"exercise": "ex1"}]
    assert items[1]["lineItem"]["scoreMaximum"] == EXERCISES[0].score_maximum
    browser.close()


def test_the_library_s_token_endpoint_accepts_the_tools_client_assertion(library):
    running, registration = library
    conf = Conf(registration=registration)
    conf.get_registration()
    platform = running.tool.config.platform(ISSUER, CLIENT)
    assertion = Tokens(running.tool.key, httpx.Client()).assertion(platform)
    answer = conf.get_access_token(
        {
            "grant_type": "client_credentials",
            "client_assertion_type": "urn:ietf:params:oauth:client-assertion-type:jwt-bearer",
            "client_assertion": assertion,
            "scope": SCORE_SCOPE,
        }
    )
    assert answer["scope"] == SCORE_SCOPE and conf.validate_token(answer["access_token"], [SCORE_SCOPE])
    decoded = conf.tool_validate_and_decode(assertion)  # the library's own check against /lti/jwks
    assert decoded["iss"] == decoded["sub"] == CLIENT and decoded["aud"] == f"{ISSUER}/token" and decoded["jti"]
