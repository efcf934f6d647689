"""The checks of a launch's ``id_token`` (LTI Core 1.3 §5.1.3, IMS Security Framework §5.1.3), in this order:

1. a JWT signed RS256 (*signature*), its header naming a ``kid`` (*key*);
2. ``iss`` is the issuer of the login's platform (*issuer*);
3. the ``kid`` is in the platform's key set (:class:`~tpm_viz.lti.platform_keys.KeySets`: *key*) and the signature
   holds (*signature*);
4. ``exp`` not past and ``iat`` not ahead, each within :data:`LEEWAY` s (*expired*);
5. ``aud`` is (or lists) the client_id, and ``azp`` is the client_id when there are several audiences or when it is
   given (*audience*);
6. ``nonce`` is the login's and unused (*nonce*);
7. version ``1.3.0`` (*version*), message type ``LtiResourceLinkRequest`` or ``LtiDeepLinkingRequest`` (*message
   type*), a deployment of the platform's configuration (*deployment*), a user ``sub`` (*user*), a non-empty list of
   roles (*role*), the login's ``target_link_uri`` (*link*), a resource link id or the deep-linking settings.

What passes is :class:`Claims`: the parts the tool uses, already read (role, course, custom, AGS, deep linking).
The login's state is checked (and spent) before, by :meth:`tpm_viz.lti.logins.Logins.finish`.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import jwt

from tpm_viz.classroom.launches import Role
from tpm_viz.core.words import Phrase, T
from tpm_viz.lti.logins import Login, Logins
from tpm_viz.lti.platform_keys import KeySets
from tpm_viz.lti.refusals import Refused, Why

__all__ = ["CLAIM", "DEEP_LINKING", "LEEWAY", "RESOURCE_LINK", "Claims", "check_id_token", "role_of"]

LEEWAY = 60.0
"""Clock difference accepted on ``exp`` and ``iat`` [s]."""
CLAIM = "https://purl.imsglobal.org/spec/lti/claim/"
AGS_CLAIM = "https://purl.imsglobal.org/spec/lti-ags/claim/endpoint"
DL_CLAIM = "https://purl.imsglobal.org/spec/lti-dl/claim/deep_linking_settings"
RESOURCE_LINK = "LtiResourceLinkRequest"
DEEP_LINKING = "LtiDeepLinkingRequest"
_MEMBERSHIP = "http://purl.imsglobal.org/vocab/lis/v2/membership"
_INSTITUTION = "http://purl.imsglobal.org/vocab/lis/v2/institution/person#"
_PRESENTING = {"Instructor", "Administrator", "TeachingAssistant"}
_EXERCISE = re.compile(r"^[A-Za-z0-9_.-]{1,64}$")
_LESSON = re.compile(r"^[1-9][0-9]{0,2}$")


def role_of(roles: list[str]) -> Role:
    """Presenter for Instructor, Administrator or TeachingAssistant of the context (``membership#...`` or the
    sub-role ``membership/Instructor#TeachingAssistant``, or LTI 1.1's short names); the institution roles
    (``institution/person#...``) count only when the launch names no context role; any other role is a student."""
    context = [r.rsplit("#", 1)[-1] for r in roles if r.startswith(_MEMBERSHIP) or "/" not in r]
    institution = [r.rsplit("#", 1)[-1] for r in roles if r.startswith(_INSTITUTION)]
    names = context if context else institution
    return Role.PRESENTER if any(n in _PRESENTING for n in names) else Role.STUDENT


@dataclass(frozen=True)
class Claims:
    """A checked ``id_token``: what the tool uses of it (``raw``: every claim, for the tests and the logs)."""

    raw: dict[str, Any]
    message_type: str
    deployment: str
    subject: str
    role: Role
    course_id: str
    course: str
    custom: dict[str, str]
    ags: dict[str, Any] | None
    deep_linking: dict[str, Any] | None
    locale: str

    @property
    def lesson(self) -> int | None:
        """The lesson the link opens (``custom`` ``lesson`` = "N", 1-based), if it names one."""
        value = self.custom.get("lesson", "")
        return int(value) if _LESSON.match(value) else None

    @property
    def exercise(self) -> str | None:
        """The exercise the link opens (``custom`` ``exercise`` = "ID"), if it names one."""
        value = self.custom.get("exercise", "")
        return value if _EXERCISE.match(value) else None


def _verify(token: str, login: Login, keys: KeySets) -> dict[str, Any]:
    """Steps 1-3: the claims of a token whose signature holds."""
    try:
        header = jwt.get_unverified_header(token)
        unverified = jwt.decode(token, options={"verify_signature": False})
    except jwt.PyJWTError:
        raise Refused(Why.SIGNATURE, Phrase("the launch token is not a signed JWT (signature): launch again")) from None
    if header.get("alg") != "RS256":
        raise Refused(
            Why.SIGNATURE,
            Phrase("the launch token is not signed RS256 (signature {alg})", alg=str(header.get("alg"))[:20]),
        )
    kid = header.get("kid")
    if not isinstance(kid, str) or not kid:
        raise Refused(Why.KEY, Phrase("the launch token names no key (key): the platform must send a kid"))
    if unverified.get("iss") != login.platform.issuer:
        raise Refused(
            Why.ISSUER,
            Phrase(
                "the launch comes from another platform than its login (issuer {iss}): check issuer",
                iss=str(unverified.get("iss"))[:120],
            ),
        )
    key = keys.key(login.platform.key_set_url, kid)
    try:
        return dict(
            jwt.decode(
                token,
                key,
                algorithms=["RS256"],
                options={
                    "verify_aud": False,
                    "verify_exp": False,
                    "verify_iat": False,
                    "verify_nbf": False,
                    "verify_iss": False,
                    "verify_sub": False,
                    "verify_jti": False,
                },
            )
        )
    except jwt.InvalidSignatureError:
        raise Refused(
            Why.SIGNATURE,
            Phrase("the launch's signature does not match the platform's key (signature): check key_set_url"),
        ) from None
    except jwt.PyJWTError:
        raise Refused(Why.SIGNATURE, Phrase("the launch token is not a signed JWT (signature): launch again")) from None


def _times(claims: dict[str, Any], now: float) -> None:
    exp, iat = claims.get("exp"), claims.get("iat")
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (exp, iat)):
        raise Refused(Why.EXPIRED, Phrase("the launch token has no valid exp and iat times (expired): launch again"))
    if now > float(exp) + LEEWAY:  # type: ignore[arg-type]
        raise Refused(Why.EXPIRED, Phrase("the launch token has expired (expired): launch again from the course"))
    if float(iat) > now + LEEWAY:  # type: ignore[arg-type]
        raise Refused(Why.EXPIRED, Phrase("the launch token is issued in the future (expired): check both clocks"))


def _audience(claims: dict[str, Any], client_id: str) -> None:
    aud, azp = claims.get("aud"), claims.get("azp")
    audiences = [aud] if isinstance(aud, str) else aud if isinstance(aud, list) else []
    wrong = client_id not in audiences or (len(audiences) > 1 and azp is None) or azp not in (None, client_id)
    if wrong:
        raise Refused(
            Why.AUDIENCE,
            Phrase("the launch is meant for another tool (audience/client {aud}): check client_id", aud=str(aud)[:120]),
        )


def _text(claims: dict[str, Any], name: str) -> str:
    value = claims.get(name)
    return value if isinstance(value, str) else ""


def check_id_token(
    token: object, login: Login, keys: KeySets, logins: Logins, clock: Callable[[], float] = time.time
) -> Claims:
    """The checked claims of a launch's ``id_token`` for ``login`` (a :class:`Refused` at the first check that
    fails; order in the module docstring)."""
    if not isinstance(token, str) or not token or len(token) > 65536:
        raise Refused(Why.REQUEST, Phrase("the launch carries no id_token: launch again from the course"))
    claims = _verify(token, login, keys)
    platform = login.platform
    _times(claims, clock())
    _audience(claims, platform.client_id)
    nonce = claims.get("nonce")
    if not isinstance(nonce, str) or nonce != login.nonce or not logins.spend_nonce(nonce):
        raise Refused(
            Why.NONCE, Phrase("the launch's nonce is not its login's, or was used already (nonce): launch again")
        )
    version = claims.get(CLAIM + "version")
    if version != "1.3.0":
        raise Refused(Why.VERSION, Phrase("the launch is LTI version {v}, not 1.3.0 (version)", v=str(version)[:20]))
    kind = claims.get(CLAIM + "message_type")
    if kind not in (RESOURCE_LINK, DEEP_LINKING):
        raise Refused(
            Why.MESSAGE_TYPE, Phrase("this tool does not take the message type {t} (message type)", t=str(kind)[:60])
        )
    deployment = _text(claims, CLAIM + "deployment_id")
    if deployment not in platform.deployment_ids:
        raise Refused(
            Why.DEPLOYMENT,
            Phrase("unknown deployment {id} (deployment): add it to deployment_ids", id=deployment[:120]),
        )
    subject = _text(claims, "sub")
    if not subject or len(subject) > 255:
        raise Refused(Why.USER, T("the launch names no user (user): the LMS must send the user's id (sub)"))
    roles = claims.get(CLAIM + "roles")
    if not isinstance(roles, list) or not roles or not all(isinstance(r, str) for r in roles):
        raise Refused(Why.ROLE, T("the launch carries no role (role): the LMS must send the user's roles"), status=400)
    target = _text(claims, CLAIM + "target_link_uri")
    if target.rstrip("/") != login.target.rstrip("/"):
        raise Refused(Why.LINK, Phrase("the launch's target {url} is not its login's (link)", url=target[:120]))
    return _claims(claims, kind, deployment, subject, roles)


def _claims(claims: dict[str, Any], kind: str, deployment: str, subject: str, roles: list[str]) -> Claims:
    """The parts the tool uses (resource link id or deep-linking settings required by the message type)."""
    link = claims.get(CLAIM + "resource_link")
    if kind == RESOURCE_LINK and not (isinstance(link, dict) and isinstance(link.get("id"), str) and link["id"]):
        raise Refused(Why.REQUEST, T("the launch names no resource link: launch again from the course"))
    settings = claims.get(DL_CLAIM)
    if kind == DEEP_LINKING:
        url = settings.get("deep_link_return_url") if isinstance(settings, dict) else None
        if not isinstance(url, str) or not url.startswith(("https://", "http://")):
            raise Refused(Why.DEEP_LINKING, T("the deep-linking request has no return URL (deep linking)"))
    context = claims.get(CLAIM + "context")
    context = context if isinstance(context, dict) else {}
    course_id = str(context.get("id") or f"deployment {deployment}")[:255]
    course = next((str(context[k]) for k in ("title", "label", "id") if context.get(k)), "(no course)")[:200]
    custom = claims.get(CLAIM + "custom")
    custom = {str(k)[:64]: str(v)[:256] for k, v in custom.items()} if isinstance(custom, dict) else {}
    ags = claims.get(AGS_CLAIM)
    presentation = claims.get(CLAIM + "launch_presentation")
    locale = _text(claims, "locale") or (str(presentation.get("locale", "")) if isinstance(presentation, dict) else "")
    return Claims(
        raw=claims,
        message_type=kind,
        deployment=deployment,
        subject=subject,
        role=role_of(roles),
        course_id=course_id,
        course=course,
        custom=dict(list(custom.items())[:50]),
        ags=ags if isinstance(ags, dict) else None,
        deep_linking=settings if kind == DEEP_LINKING and isinstance(settings, dict) else None,
        locale=locale[:35],
    )
