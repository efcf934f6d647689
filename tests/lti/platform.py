"""An LTI 1.3 platform written for the tests from the IMS specifications (LTI Core 1.3, Deep Linking 2.0, AGS 2.0,
Security Framework 1.0), sharing no code with ``tpm_viz.lti``: its own RSA keys and JWKS, an OIDC authorisation
endpoint that form-posts an ``id_token``, a token endpoint that checks the tool's client assertion against the
tool's ``/lti/jwks``, line items and a score endpoint that records what it accepted (latest wins by timestamp) and
can be switched down, slow or answer-losing, and a deep-linking return endpoint that checks the tool's response.

Everything on 127.0.0.1 (uvicorn in a thread); the tests wait on its records, never on fixed sleeps.
"""

from __future__ import annotations

import base64
import datetime
import html
import json
import re
import secrets
import socket
import threading
import time
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import parse_qs, urlencode, urlsplit

import httpx
import jwt
import uvicorn
from cryptography.hazmat.primitives.asymmetric import rsa
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response
from starlette.routing import Route

LTI = "https://purl.imsglobal.org/spec/lti/claim/"
AGS = "https://purl.imsglobal.org/spec/lti-ags/"
DL = "https://purl.imsglobal.org/spec/lti-dl/claim/"
MEMBERSHIP = "http://purl.imsglobal.org/vocab/lis/v2/membership#"
SCORE = AGS + "scope/score"
READ = AGS + "scope/lineitem.readonly"


def _b64(n: int) -> str:
    return base64.urlsafe_b64encode(n.to_bytes((n.bit_length() + 7) // 8, "big")).decode().rstrip("=")


class Key:
    """An RSA key of the platform and its JWK (``kid`` chosen by the platform: any opaque string)."""

    def __init__(self, kid: str) -> None:
        self.private = rsa.generate_private_key(public_exponent=65537, key_size=2048)
        self.kid = kid
        numbers = self.private.public_key().public_numbers()
        self.jwk = {"kty": "RSA", "kid": kid, "alg": "RS256", "use": "sig", "n": _b64(numbers.n), "e": _b64(numbers.e)}

    def sign(self, claims: dict[str, Any], kid: str | None = None) -> str:
        """The claims as a JWS (RS256), whatever their values (a forger's too: no claim is checked here)."""
        payload = json.dumps(claims, separators=(",", ":")).encode()
        return jwt.api_jws.encode(payload, self.private, algorithm="RS256", headers={"kid": kid or self.kid})


@dataclass
class Person:
    """A user of the LMS: ``sub`` and roles (URIs)."""

    sub: str
    roles: list[str]
    locale: str = "en-US"


@dataclass
class Link:
    """What a launch is about (the ``lti_message_hint``): a resource link or a deep-linking request."""

    message_type: str = "LtiResourceLinkRequest"
    resource_link: str = "link-1"
    custom: dict[str, str] = field(default_factory=dict)
    lineitem: str | None = None  # a line item id of this platform
    scopes: list[str] = field(default_factory=lambda: [SCORE, READ])
    context: dict[str, str] = field(default_factory=lambda: {"id": "course-7", "title": "Mechanisms 101"})
    data: str = "opaque-data-42"
    presentation: str = "window"


@dataclass
class Item:
    """A line item and the result the platform keeps per user (the latest score by timestamp)."""

    score_maximum: float
    label: str
    results: dict[str, dict[str, Any]] = field(default_factory=dict)


class TestPlatform:
    """The platform. ``tool_jwks``: the tool's key set URL (set once the tool serves)."""

    __test__ = False

    def __init__(self, client_id: str = "tpm-client", deployment: str = "dep-1") -> None:
        self.key = Key("platform-key-1")
        self.keys = [self.key]  # what /jwks serves
        self.client_id, self.deployment = client_id, deployment
        self.people: dict[str, Person] = {}
        self.links: dict[str, Link] = {}
        self.items: dict[str, Item] = {}
        self.tool_jwks = ""
        self.tool_login = self.tool_launch = ""  # the tool's login and launch URLs (the course page links them)
        self.redirect_uris: list[str] = []
        self.mode = "up"  # "down": 503; "lose": apply, then answer 500 (``lose`` times); "slow": answer late
        self.lose = 0
        self.strict = True  # a score not newer than the one kept: 409 (else 200 and nothing changes)
        self.released = threading.Event()  # a slow answer waits for it
        self.posts: list[dict[str, Any]] = []  # every score body POSTed (whatever the answer)
        self.applied: list[dict[str, Any]] = []  # scores that changed a result
        self.tokens: dict[str, tuple[float, set[str]]] = {}
        self.token_requests: list[dict[str, Any]] = []
        self.assertions: set[str] = set()  # jti seen
        self.deep_link_answers: list[dict[str, Any]] = []
        self.issued: list[dict[str, Any]] = []  # claims of every id_token issued
        self._lock = threading.Lock()
        self.socket = socket.create_server(("127.0.0.1", 0))
        self.port = self.socket.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self.issuer = f"https://lms.test/{secrets.token_hex(3)}"
        routes = [
            Route("/jwks", self._jwks),
            Route("/auth", self._auth, methods=["GET", "POST"]),
            Route("/token", self._token, methods=["POST"]),
            Route("/lineitems/{item}", self._lineitem),
            Route("/lineitems/{item}/scores", self._scores, methods=["POST"]),
            Route("/return", self._return, methods=["POST"]),
            Route("/course/{hint}/{link}", self._course),
        ]
        self.app = Starlette(routes=routes)
        self.server = uvicorn.Server(uvicorn.Config(self.app, log_level="warning", lifespan="off"))
        self.thread = threading.Thread(target=self.server.run, kwargs={"sockets": [self.socket]}, daemon=True)

    # -- life ---------------------------------------------------------------------------------------------------------
    def start(self) -> TestPlatform:
        self.thread.start()
        deadline = time.monotonic() + 10
        while not self.server.started and time.monotonic() < deadline:
            time.sleep(0.01)
        assert self.server.started
        return self

    def stop(self) -> None:
        self.released.set()
        self.server.should_exit = True
        self.thread.join(5)
        self.socket.close()

    def config(self) -> str:
        """The ``[[platform]]`` table of the tool's configuration."""
        return (
            f'[[platform]]\nissuer = "{self.issuer}"\nclient_id = "{self.client_id}"\n'
            f'deployment_ids = ["{self.deployment}"]\nauth_login_url = "{self.url}/auth"\n'
            f'auth_token_url = "{self.url}/token"\nkey_set_url = "{self.url}/jwks"\n'
        )

    # -- what the tests ask ------------------------------------------------------------------------------------------
    def login_query(self, target: str, hint: str, message: str) -> dict[str, str]:
        """The third-party login initiation (LTI Core §5.1.1.1) the platform sends to the tool."""
        return {
            "iss": self.issuer,
            "login_hint": hint,
            "target_link_uri": target,
            "lti_message_hint": message,
            "client_id": self.client_id,
            "lti_deployment_id": self.deployment,
        }

    def claims(self, auth: dict[str, str], now: float | None = None) -> dict[str, Any]:
        """The id_token claims the platform sends for an authorisation request ``auth`` (LTI Core §5.3)."""
        now = time.time() if now is None else now
        person, link = self.people[auth["login_hint"]], self.links[auth["lti_message_hint"]]
        claims: dict[str, Any] = {
            "iss": self.issuer,
            "aud": self.client_id,
            "azp": self.client_id,
            "sub": person.sub,
            "exp": int(now) + 300,
            "iat": int(now),
            "nonce": auth["nonce"],
            "locale": person.locale,
            LTI + "message_type": link.message_type,
            LTI + "version": "1.3.0",
            LTI + "deployment_id": self.deployment,
            LTI + "target_link_uri": auth["redirect_uri"],
            LTI + "roles": person.roles,
            LTI + "context": link.context,
            LTI + "custom": link.custom,
            LTI + "launch_presentation": {"document_target": link.presentation},
        }
        if link.message_type == "LtiResourceLinkRequest":
            claims[LTI + "resource_link"] = {"id": link.resource_link, "title": "A link"}
        else:
            claims[DL + "deep_linking_settings"] = {
                "deep_link_return_url": f"{self.url}/return",
                "accept_types": ["ltiResourceLink", "link"],
                "accept_presentation_document_targets": ["window", "iframe"],
                "accept_multiple": True,
                "accept_lineitem": True,
                "data": link.data,
            }
        if link.lineitem is not None:
            claims[AGS + "claim/endpoint"] = {
                "scope": link.scopes,
                "lineitems": f"{self.url}/lineitems",
                "lineitem": f"{self.url}/lineitems/{link.lineitem}?type=x",
            }
        return claims

    def id_token(self, claims: dict[str, Any], key: Key | None = None, kid: str | None = None) -> str:
        with self._lock:
            self.issued.append(claims)
        return (key or self.key).sign(claims, kid)

    def result(self, item: str, sub: str) -> dict[str, Any] | None:
        with self._lock:
            return self.items[item].results.get(sub)

    # -- endpoints ---------------------------------------------------------------------------------------------------
    async def _jwks(self, request: Request) -> Response:
        return JSONResponse({"keys": [k.jwk for k in self.keys]})

    async def _auth(self, request: Request) -> Response:
        """OIDC authorisation (Security Framework §5.1.1.2-3): checks the request, form-posts the id_token."""
        params = dict(request.query_params) if request.method == "GET" else dict(await request.form())
        expected = {"scope": "openid", "response_type": "id_token", "response_mode": "form_post", "prompt": "none"}
        for name, value in expected.items():
            if params.get(name) != value:
                return Response(f"bad {name}", status_code=400)
        if params.get("client_id") != self.client_id or not params.get("nonce") or not params.get("state"):
            return Response("bad client_id, nonce or state", status_code=400)
        if self.redirect_uris and params.get("redirect_uri") not in self.redirect_uris:
            return Response("unregistered redirect_uri", status_code=400)
        token = self.id_token(self.claims(params))
        fields = {"id_token": token, "state": params["state"]}
        inputs = "".join(f'<input type="hidden" name="{k}" value="{html.escape(v)}">' for k, v in fields.items())
        page = (
            f'<html><body><form id="f" method="post" action="{html.escape(params["redirect_uri"])}">{inputs}</form>'
            '<script>document.getElementById("f").submit()</script></body></html>'
        )
        return HTMLResponse(page)

    def _tool_key(self, token: str) -> Any:
        kid = jwt.get_unverified_header(token)["kid"]
        keys = httpx.get(self.tool_jwks, timeout=5).json()["keys"]
        jwk = next(k for k in keys if k["kid"] == kid)
        return jwt.PyJWK(jwk, algorithm="RS256").key

    async def _token(self, request: Request) -> Response:
        """Client credentials with a JWT assertion (Security Framework §4.1, RFC 7523 §3)."""
        form = dict(await request.form())
        with self._lock:
            self.token_requests.append(form)
        if self.mode == "down":
            return Response("down", status_code=503)
        if form.get("grant_type") != "client_credentials" or form.get("client_assertion_type") != (
            "urn:ietf:params:oauth:client-assertion-type:jwt-bearer"
        ):
            return JSONResponse({"error": "unsupported_grant_type"}, status_code=400)
        try:
            key = await run_in_threadpool(self._tool_key, form["client_assertion"])
            claims = jwt.decode(
                form["client_assertion"],
                key,
                algorithms=["RS256"],
                audience=f"{self.url}/token",
                issuer=self.client_id,
                options={"require": ["iss", "sub", "aud", "exp", "iat", "jti"]},
            )
        except (jwt.PyJWTError, KeyError, StopIteration) as exc:
            return JSONResponse({"error": "invalid_client", "why": type(exc).__name__}, status_code=401)
        with self._lock:
            if claims["sub"] != self.client_id or claims["jti"] in self.assertions:
                return JSONResponse({"error": "invalid_client", "why": "sub or jti"}, status_code=401)
            self.assertions.add(claims["jti"])
            token = secrets.token_urlsafe(16)
            scopes = set(str(form.get("scope", "")).split())
            self.tokens[token] = (time.time() + 3600, scopes)
        return JSONResponse(
            {"access_token": token, "token_type": "Bearer", "expires_in": 3600, "scope": " ".join(scopes)}
        )

    def _scopes(self, request: Request) -> set[str] | None:
        auth = request.headers.get("authorization", "")
        found = self.tokens.get(auth[7:]) if auth.startswith("Bearer ") else None
        return None if found is None or found[0] < time.time() else found[1]

    async def _lineitem(self, request: Request) -> Response:
        scopes = self._scopes(request)
        if scopes is None or not scopes & {READ, AGS + "scope/lineitem"}:
            return Response(status_code=401)
        item = self.items[request.path_params["item"]]
        body = {"id": str(request.url), "scoreMaximum": item.score_maximum, "label": item.label}
        return JSONResponse(body, media_type="application/vnd.ims.lis.v2.lineitem+json")

    async def _scores(self, request: Request) -> Response:
        """The score publish service (AGS 2.0 §3.4)."""
        if self.mode == "down":
            return Response("down", status_code=503)
        scopes = self._scopes(request)
        if scopes is None or SCORE not in scopes:
            return Response(status_code=401)
        if request.headers.get("content-type") != "application/vnd.ims.lis.v1.score+json":
            return Response("wrong media type", status_code=415)
        if request.url.query != "type=x":
            return Response("the line item's query was lost", status_code=404)
        score = json.loads(await request.body())
        with self._lock:
            self.posts.append(score)
        stamp = datetime.datetime.fromisoformat(score["timestamp"].replace("Z", "+00:00"))
        assert stamp.tzinfo is not None, "a timestamp without its zone"
        if self.mode == "slow":
            await run_in_threadpool(self.released.wait, 30.0)
        item = self.items.get(request.path_params["item"])
        if item is None:
            return Response("no such line item", status_code=404)
        with self._lock:
            kept = item.results.get(score["userId"])
            newer = kept is None or stamp > kept["_stamp"]
            if newer:
                item.results[score["userId"]] = {**score, "_stamp": stamp}
                self.applied.append(score)
            losing = self.mode == "lose" and self.lose > 0
            if losing:
                self.lose -= 1
        if losing:
            return Response("answer lost", status_code=500)
        if not newer:
            return Response("not newer", status_code=409 if self.strict else 200)
        return Response(status_code=200)

    async def _course(self, request: Request) -> Response:
        """The course page a student or a lecturer opens in the LMS: a link that starts the tool's login."""
        hint, link = request.path_params["hint"], request.path_params["link"]
        target = query(self.tool_login, **self.login_query(self.tool_launch, hint, link))
        return HTMLResponse(f'<html><body><h1>Mechanisms 101</h1><a id="open" href="{html.escape(target)}">tpm-viz</a>')

    async def _return(self, request: Request) -> Response:
        """The deep-linking return URL (Deep Linking 2.0 §4.2): the tool's signed response, checked."""
        form = dict(await request.form())
        key = await run_in_threadpool(self._tool_key, form["JWT"])
        claims = jwt.decode(form["JWT"], key, algorithms=["RS256"], audience=self.issuer, issuer=self.client_id)
        with self._lock:
            self.deep_link_answers.append(claims)
        return HTMLResponse("<p>Content added.</p>")


def auth_params(location: str) -> dict[str, str]:
    """The query of the tool's redirect to the platform's authorisation endpoint."""
    return {k: v[0] for k, v in parse_qs(urlsplit(location).query).items()}


def form_fields(page: str) -> tuple[str, dict[str, str]]:
    """``(action, fields)`` of the first form of an HTML page (a tiny reader: the pages are the tools' own)."""
    action = html.unescape(re.search(r'<form[^>]*action="([^"]*)"', page).group(1))
    fields = {html.unescape(n): html.unescape(v) for n, v in re.findall(r'name="([^"]*)" value="([^"]*)"', page)}
    return action, fields


def query(url: str, **params: str) -> str:
    return f"{url}?{urlencode(params)}"
