"""The LTI endpoints: a Starlette app (:func:`build_asgi`) served by uvicorn in a thread of ``tpm-viz serve``
(:class:`LtiServer`), on its own port of the app's host (docs/lti.md: which URL a reverse proxy maps where).

- ``GET|POST /lti/login``: the OIDC login (:mod:`.logins`); a 302 to the platform, the state in a cookie;
- ``POST /lti/launch`` (and ``/lti/deeplink``, the LMS's "content selection URL"): the ``id_token`` checked
  (:mod:`.checks`), then a resource link's browser is sent to the app with a one-time ticket (303; from inside a
  frame, a page with a link that opens a window) and a deep-linking request opens the picker;
- ``POST /lti/deeplink/return``: the picker's choice, answered with the form that posts the signed response to
  the platform (:mod:`.deeplinking`);
- ``GET /lti/jwks``: the tool's public key set.

State cookie (docs/lti.md): the login sets ``tpmviz_lti_<hash of the state>`` = state (``Path=/lti``, 5 min,
``HttpOnly``; over https ``SameSite=None; Secure; Partitioned``, so that it survives the LMS's cross-site form post,
also inside a frame; over plain http ``SameSite=Lax``). The launch's state must be one this tool issued, unused, at
most 5 min old, *and* its cookie must come back: always when :attr:`Tool.cookie_required` (the default over
https), and when the browser sent it otherwise (a cookie of another value is refused either way).

Bounds: request bodies (:mod:`.bounds`), requests per client address on login, launch and the picker, waiting
logins, pickers and tickets. Every refusal is a 4xx page of one line (:mod:`.refusals`), logged once.
"""

from __future__ import annotations

import contextlib
import hashlib
import socket
import threading
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import urlsplit

import uvicorn
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, RedirectResponse, Response
from starlette.routing import Route

from tpm_viz.classroom.launches import Tickets
from tpm_viz.classroom.network import Network
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Lang, Phrase, T, preferred
from tpm_viz.lti.bounds import BoundedBodies, Rate, address_of
from tpm_viz.lti.checks import DEEP_LINKING, Claims, check_id_token
from tpm_viz.lti.config import Config
from tpm_viz.lti.deeplinking import Catalogue, Picks, response_jwt
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.launches import app_url, resource_launch
from tpm_viz.lti.ledger import Ledger
from tpm_viz.lti.logins import LOGIN_SECONDS, Login, Logins, begin_login
from tpm_viz.lti.pages import Page, autopost_page, headers, open_app_page, picker_page, refusal_page
from tpm_viz.lti.platform_keys import KeySets
from tpm_viz.lti.refusals import Refused, Why, log, log_refusal

__all__ = ["COOKIE_PREFIX", "LtiServer", "Tool", "Urls", "build_asgi", "state_cookie"]

COOKIE_PREFIX = "tpmviz_lti_"
MAX_FIELDS = 64


@dataclass(frozen=True)
class Urls:
    """The tool's public URLs (``base``: scheme, host, port and any path prefix, no trailing slash)."""

    base: str
    app: str

    @property
    def login(self) -> str:
        return self.base + "/lti/login"

    @property
    def launch(self) -> str:
        return self.base + "/lti/launch"

    @property
    def deeplink(self) -> str:
        return self.base + "/lti/deeplink"

    @property
    def picked(self) -> str:
        return self.base + "/lti/deeplink/return"

    @property
    def jwks(self) -> str:
        return self.base + "/lti/jwks"

    @property
    def secure(self) -> bool:
        return self.base.startswith("https://")

    @property
    def cookie_path(self) -> str:
        """The path of the login's cookie: ``/lti`` under the public base's path (a proxy's prefix included)."""
        return urlsplit(self.base).path.rstrip("/") + "/lti"


@dataclass
class Tool:
    """Everything the endpoints use."""

    config: Config
    key: ToolKey
    ledger: Ledger
    tickets: Tickets
    catalogue: Catalogue
    urls: Urls
    network: Network = field(default_factory=Network)
    keysets: KeySets = field(default_factory=KeySets)
    logins: Logins = field(default_factory=Logins)
    picks: Picks = field(default_factory=Picks)
    rate: Rate = field(default_factory=Rate)
    clock: Callable[[], float] = time.time
    cookie_required: bool | None = None
    """Whether a launch must bring the state cookie back (None: when the tool's URL is https)."""

    @property
    def must_have_cookie(self) -> bool:
        return self.urls.secure if self.cookie_required is None else self.cookie_required


def state_cookie(state: str) -> str:
    """The name of the cookie that binds a login's ``state`` to its browser."""
    return COOKIE_PREFIX + hashlib.sha256(state.encode()).hexdigest()[:16]


def _page(page: Page, status: int = 200) -> HTMLResponse:
    return HTMLResponse(page.text, status_code=status, headers=headers(page))


def _lang(request: Request, claims: Claims | None = None) -> Lang:
    asked = preferred(request.headers.get("accept-language"))
    return Lang.parse(claims.locale, default=asked) if claims is not None and claims.locale else asked


def _answered(
    endpoint: Callable[[Request, Tool], Awaitable[Response]], limited: bool = True
) -> Callable[[Request], Awaitable[Response]]:
    """An endpoint whose refusals are one-line pages (logged once) and whose bugs are a 500 page, never a
    traceback in the browser; ``limited``: counted against its address's rate."""

    async def run(request: Request) -> Response:
        tool: Tool = request.app.state.tool
        address = address_of(request, tool.network)
        try:
            if limited and not tool.rate.allow(address):
                raise Refused(Why.TOO_MANY, T("too many requests from this address (too many): wait a minute"))
            return await endpoint(request, tool)
        except Refused as exc:
            log_refusal(exc, address, request.url.path)
            return _page(refusal_page(exc, _lang(request)), exc.status)
        except Exception:
            log.exception("LTI %s failed", request.url.path)
            internal = Refused(Why.REQUEST, T("internal error of the LTI tool, logged on the server"))
            return _page(refusal_page(internal, _lang(request)), 500)

    return run


async def _form(request: Request) -> dict[str, Any]:
    try:
        form = await request.form(max_files=0, max_fields=MAX_FIELDS)
    except Exception:  # malformed or too many fields: not a form this tool takes
        raise Refused(Why.REQUEST, T("the request is not a form this tool takes")) from None
    return {"_items": form.getlist("item"), **{k: v for k, v in form.items() if isinstance(v, str)}}


async def login(request: Request, tool: Tool) -> Response:
    params = dict(request.query_params) if request.method == "GET" else await _form(request)
    urls = tool.urls
    target, found = begin_login(
        tool.config, tool.logins, params, (urls.launch, urls.deeplink), address_of(request, tool.network)
    )
    response = RedirectResponse(target, status_code=302)
    secure = urls.secure
    # written by hand: Starlette's set_cookie takes Partitioned only on Python 3.14+ (the state is URL-safe text)
    site = "SameSite=None; Secure; Partitioned" if secure else "SameSite=Lax"
    response.headers.append(
        "set-cookie",
        f"{state_cookie(found.state)}={found.state}; Path={urls.cookie_path}; Max-Age={int(LOGIN_SECONDS)}; "
        f"HttpOnly; {site}",
    )
    response.headers["Cache-Control"] = "no-store"
    return response


def _check_cookie(request: Request, tool: Tool, login: Login) -> None:
    sent = request.cookies.get(state_cookie(login.state))
    if sent is None and not tool.must_have_cookie:
        return
    if sent != login.state:
        why = "did not come back" if sent is None else "is another browser's"
        raise Refused(
            Why.STATE,
            T("this browser did not start the login (state): launch again; the browser must keep the tool's cookie"),
            detail=f"the state cookie {why}",
        )


async def launch(request: Request, tool: Tool) -> Response:
    form = await _form(request)
    if "error" in form:
        with contextlib.suppress(Refused):
            tool.logins.finish(form.get("state"))  # spent: the platform will not launch this login
        raise Refused(
            Why.REQUEST,
            Phrase("the platform answered the login with an error ({error}): launch again", error=form["error"][:80]),
        )
    found = tool.logins.finish(form.get("state"))
    _check_cookie(request, tool, found)
    claims = await run_in_threadpool(check_id_token, form.get("id_token"), found, tool.keysets, tool.logins, tool.clock)
    lang = _lang(request, claims)
    if claims.message_type == DEEP_LINKING:
        pick = tool.picks.open(claims, found.platform, lang)
        response: Response = _page(picker_page(pick, tool.catalogue(), tool.urls.picked))
    else:
        opened, ticket = await run_in_threadpool(resource_launch, claims, found.platform, tool.ledger, tool.tickets)
        log.info("LTI launch: a %s of %r", opened.role.value, opened.course)
        target = app_url(tool.urls.app, ticket)
        presentation = claims.raw.get("https://purl.imsglobal.org/spec/lti/claim/launch_presentation")
        framed = request.headers.get("sec-fetch-dest") == "iframe" or (
            isinstance(presentation, dict) and presentation.get("document_target") == "iframe"
        )
        response = _page(open_app_page(target, lang)) if framed else RedirectResponse(target, status_code=303)
        response.headers["Referrer-Policy"] = "no-referrer"
    response.delete_cookie(state_cookie(found.state), path=tool.urls.cookie_path)
    return response


async def picked(request: Request, tool: Tool) -> Response:
    form = await _form(request)
    pick = tool.picks.take(form.get("pick"))
    chosen = [] if form.get("do") == "cancel" else [str(c) for c in form["_items"]][:100]
    token = response_jwt(pick, chosen, tool.catalogue(), tool.key, tool.urls.launch, tool.clock())
    return _page(autopost_page(pick.return_url, {"JWT": token}, pick.lang))


async def jwks(request: Request, tool: Tool) -> Response:
    return JSONResponse(tool.key.jwks(), headers={"Cache-Control": "max-age=300"})


def _too_large(scope: Any) -> Any:
    refused = Refused(Why.TOO_LARGE, T("the request is too large (too large)"))
    log_refusal(refused, str((scope.get("client") or ("?",))[0]), str(scope.get("path", "")))
    return _page(refusal_page(refused, Lang.EN), refused.status)


def build_asgi(tool: Tool) -> Any:
    """The ASGI app of the LTI endpoints."""
    app = Starlette(
        routes=[
            Route("/lti/login", _answered(login), methods=["GET", "POST"]),
            Route("/lti/launch", _answered(launch), methods=["POST"]),
            Route("/lti/deeplink", _answered(launch), methods=["POST"]),
            Route("/lti/deeplink/return", _answered(picked), methods=["POST"]),
            Route("/lti/jwks", _answered(jwks, limited=False), methods=["GET"]),
        ]
    )
    app.state.tool = tool
    return BoundedBodies(app, _too_large)


class LtiServer:
    """uvicorn in a thread on a socket bound at construction (a busy port fails at once, before the app starts)."""

    def __init__(self, host: str, port: int) -> None:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self.socket = socket.socket(family, socket.SOCK_STREAM)
        self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self.socket.bind((host, port))
        except OSError as exc:
            self.socket.close()
            raise InputError(
                f"the LTI port {port} on {host} is not free ({exc.strerror or exc}); set another [tool] port"
            ) from None
        self.socket.listen(128)
        self.port = int(self.socket.getsockname()[1])
        self.server: uvicorn.Server | None = None
        self._thread: threading.Thread | None = None

    def start(self, asgi: Any, wait: float = 10.0) -> None:
        """Serve ``asgi`` in a thread; returns once uvicorn listens (at most ``wait`` seconds)."""
        config = uvicorn.Config(
            asgi, log_level="warning", access_log=False, proxy_headers=False, server_header=False,
            timeout_keep_alive=5, limit_concurrency=256, h11_max_incomplete_event_size=16 << 10, lifespan="off",
        )  # fmt: skip
        server = self.server = uvicorn.Server(config)
        self._thread = threading.Thread(
            target=server.run, kwargs={"sockets": [self.socket]}, name="tpm-viz-lti", daemon=True
        )
        self._thread.start()
        deadline = time.monotonic() + wait
        while not server.started and self._thread.is_alive() and time.monotonic() < deadline:
            time.sleep(0.01)
        if not server.started:
            raise InputError(f"the LTI service did not start within {wait:g} s")

    def stop(self) -> None:
        if self.server is not None:
            self.server.should_exit = True
        if self._thread is not None:
            self._thread.join(5.0)
        self.socket.close()
