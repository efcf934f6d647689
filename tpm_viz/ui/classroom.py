"""A real classroom: the addresses students type, who a tab is, and which websocket handshakes are refused.

- :func:`local_addresses` finds this machine's network addresses (the lookup is a parameter of :class:`Classroom`,
  so that tests inject theirs); :func:`student_urls` turns the bound host into the URLs to hand out (never a
  loopback address: on a student's phone 127.0.0.1 is the phone itself); :func:`qr_text` / :func:`qr_data_uri`
  draw one of them as a QR code (``segno``) for the terminal and the lecturer's panel.
- :class:`Handshakes` sees every HTTP request and websocket handshake
  (:func:`~tpm_viz.viserkit.adapter.new_server`): a
  websocket whose ``Origin`` is not the host the page was served under is refused with 403 (the same-origin check
  Jupyter's server makes: any page open in the lecturer's browser could otherwise drive the mechanism on
  127.0.0.1); a client without ``Origin`` (not a browser) may connect. The page's response sets a
  ``tpmviz_id`` cookie the server minted and signed (:mod:`tpm_viz.classroom.identity`; one it did not sign is
  replaced), which the browser sends back with every websocket handshake, reconnections included: it is
  how a tab that comes back after a wifi blip or a restart is recognised (:func:`identity`). A page asked with
  ``?share=TOKEN`` (a share link, :mod:`tpm_viz.classroom.links`) gets a short-lived ``tpmviz_share`` cookie naming
  where its token waits (:data:`PENDING`); that page's websocket brings it back and :func:`shared_token` hands the token
  over once (:mod:`.share` opens it on the tab's own copy). A page asked with ``?lti=TICKET`` (``serve --lti``) spends
  the LTI launch's one-time ticket and carries its launch the same way (``tpmviz_lti``, :mod:`.launched`).
"""

from __future__ import annotations

import contextlib
import http
import io
import logging
import secrets
import socket
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from http.cookies import SimpleCookie
from typing import Any
from urllib.parse import urlsplit

import segno

from tpm_viz.classroom.identity import Keys, hashed
from tpm_viz.classroom.launches import TICKET_SECONDS, Tickets, ticket_of_query
from tpm_viz.classroom.links import PENDING_SECONDS, PendingLinks, token_of_query
from tpm_viz.classroom.network import PROXIED, HostRules, client_address, header_problem, host_name, is_loopback
from tpm_viz.ui.keyboard import Keyboard
from tpm_viz.ui.seen import Sightings
from tpm_viz.viserkit.page import ALIVE_PATH, with_script

__all__ = [
    "COOKIE",
    "LAUNCH_COOKIE",
    "PENDING",
    "SHARE_COOKIE",
    "Classroom",
    "Handshakes",
    "identity",
    "launch_nonce",
    "local_addresses",
    "qr_data_uri",
    "qr_text",
    "same_origin",
    "shared_token",
    "student_urls",
]

log = logging.getLogger("tpm_viz.ui")

COOKIE = "tpmviz_id"
COOKIE_MAX_AGE = 7 * 24 * 3600
DEFAULT_KEYS = Keys()
"""The cookie keys of a server built without its own (a secret of this process: in-process servers and tests)."""
_PAGES = ("/", "/index.html")
SHARE_COOKIE = "tpmviz_share"
"""The short-lived cookie that carries a share link's nonce from the page to its websocket (:mod:`.share`)."""
LAUNCH_COOKIE = "tpmviz_lti"
"""The short-lived cookie that carries an LTI launch's nonce from the page to its websocket (:mod:`.launched`)."""
PENDING = PendingLinks()
"""The share tokens of pages whose tab has not connected yet (this process's; :class:`Handshakes` fills it)."""


def local_addresses() -> list[str]:
    """This machine's non-loopback IPv4 addresses (the one of the default route first); no packet is sent."""
    found: list[str] = []
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.connect(("192.0.2.1", 9))  # TEST-NET-1: UDP connect only picks the outgoing interface
            found.append(probe.getsockname()[0])
    except OSError:
        pass
    try:
        for info in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET):
            found.append(str(info[4][0]))
    except OSError:
        pass
    return list(dict.fromkeys(a for a in found if not is_loopback(a) and a != "0.0.0.0"))


def student_urls(host: str, port: int, addresses: Iterable[str]) -> list[str]:
    """The URLs students type: every given address of this machine when bound to all of them, else the host."""
    if host in ("0.0.0.0", "::", ""):
        hosts = [a for a in addresses if not is_loopback(a)]
    else:
        hosts = [] if is_loopback(host) else [host]
    return [f"http://{f'[{h}]' if ':' in h else h}:{port}/" for h in hosts]


def qr_text(url: str) -> str:
    """A QR code of ``url`` for the terminal (half-block characters, quiet zone included)."""
    out = io.StringIO()
    segno.make(url, error="m").terminal(out=out, compact=True)
    return out.getvalue()


def qr_data_uri(url: str) -> str:
    """A QR code of ``url`` as an SVG ``data:`` URI (for an ``<img>`` in the lecturer's panel)."""
    return segno.make(url, error="m").svg_data_uri(scale=5, dark="#0f172a")


@dataclass
class Classroom:
    """Classroom mode's settings. ``addresses`` is the lookup of this machine's addresses (tests inject one);
    ``presenter_address`` says which connecting address makes a tab the presenter (default: loopback);
    ``lecturer_address`` which one is the lecturer's machine, whose tabs a student's sockets never crowd out
    (default: loopback; :mod:`tpm_viz.viserkit.admission`)."""

    addresses: Callable[[], list[str]] = local_addresses
    presenter_address: Callable[[str], bool] = is_loopback
    token: str = field(default_factory=lambda: secrets.token_urlsafe(9))
    lecturer_address: Callable[[str], bool] = is_loopback


def same_origin(headers: Any) -> bool:
    """Whether a websocket handshake comes from a page served by this server (or from no page at all)."""
    origin = headers.get("Origin")
    if origin is None:
        return True  # not a browser: a browser always sends Origin with a websocket handshake
    host = (headers.get("Host") or "").strip().lower()
    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        return False
    if parts.scheme not in ("http", "https") or not parts.hostname:
        return False
    default = 443 if parts.scheme == "https" else 80
    netloc = parts.hostname.lower()
    netloc = f"[{netloc}]" if ":" in netloc else netloc
    port = parts.port if parts.port is not None else default
    candidates = {f"{netloc}:{port}"} | ({netloc} if port == default else set())
    return host in candidates


def _cookie(headers: Any, keys: Keys) -> str | None:
    """The id of the identity cookie if this server signed it (:meth:`Keys.verify`), else None."""
    raw = headers.get("Cookie")
    if not raw:
        return None
    try:
        jar: SimpleCookie = SimpleCookie()
        jar.load(raw)
    except Exception:  # a malformed Cookie header: no identity
        return None
    morsel = jar.get(COOKIE)
    return None if morsel is None else keys.verify(morsel.value)


def _share_nonce(headers: Any) -> str | None:
    """The value of the share cookie (:data:`SHARE_COOKIE`) a request carries, else None."""
    return _cookie_value(headers, SHARE_COOKIE)


def _cookie_value(headers: Any, name: str) -> str | None:
    """The value of the cookie ``name`` a request carries, else None (a malformed Cookie header: None)."""
    raw = None if headers is None else headers.get("Cookie")
    if not raw or name not in raw:
        return None
    try:
        jar: SimpleCookie = SimpleCookie()
        jar.load(raw)
    except Exception:
        return None
    morsel = jar.get(name)
    return None if morsel is None else morsel.value


def launch_nonce(headers: Any) -> str | None:
    """The value of the launch cookie (:data:`LAUNCH_COOKIE`) a websocket handshake carries, else None."""
    return _cookie_value(headers, LAUNCH_COOKIE)


def shared_token(headers: Any, links: PendingLinks = PENDING) -> str | None:
    """The share token of the page a websocket handshake (``headers``) comes from, once (None: none waiting)."""
    return links.take(_share_nonce(headers))


def identity(remote: Any, headers: Any, keys: Keys = DEFAULT_KEYS) -> str | None:
    """Who a tab is across reconnections, hashed (:func:`~tpm_viz.classroom.identity.hashed`): ``c:...`` for a
    browser with a cookie this server signed, else ``a:...`` of its address and user agent for a browser without
    one (cookies blocked, or a self-made or unknown cookie: a new identity that owns nothing of a cookie's; its copy
    is only offered back, never restored by itself), else None (not a browser: no ``Origin``; nothing is kept)."""
    cookie = None if headers is None else _cookie(headers, keys)
    if cookie is not None:
        return hashed("c", cookie)
    if headers is None or headers.get("Origin") is None:
        return None
    host = remote[0] if isinstance(remote, (tuple, list)) and remote else str(remote)
    agent = "" if headers is None else str(headers.get("User-Agent", ""))[:200]
    return hashed("a", f"{host}|{agent}")


class Handshakes:
    """The hook of :func:`~tpm_viz.viserkit.adapter.new_server`: refuse cross-origin websockets, give pages an
    identity, keep a share link's token for the tab the page opens (:data:`SHARE_COOKIE`), and answer the page
    script's requests (its keys; ``GET /tpm-viz/alive`` of a disconnected page, :mod:`tpm_viz.viserkit.page`)."""

    def __init__(
        self,
        hosts: HostRules | None = None,
        keys: Keys | None = None,
        links: PendingLinks | None = None,
        tickets: Tickets | None = None,
    ) -> None:
        self.refused = 0
        self.tickets = tickets
        """The LTI launches' one-time tickets (``serve --lti``), or None."""
        self.links = links if links is not None else PENDING
        """Where a page's share token waits for its websocket (:func:`shared_token` reads it)."""
        self.keys = keys if keys is not None else DEFAULT_KEYS
        """Mints the page's identity cookie (:mod:`tpm_viz.classroom.identity`)."""
        self.hosts = hosts if hosts is not None else HostRules()
        """The ``Host`` names served and the trusted proxies (:mod:`tpm_viz.classroom.network`)."""
        self._warned_proxy = False
        self._logged = 0.0
        self.keyboard = Keyboard()
        """The tabs' keys (:mod:`.keyboard`): the page script's requests are answered here."""
        self.sightings = Sightings(self.keyboard)
        """What the pages see (a finger, the tab opened: :mod:`.seen`), answered here."""

    def _refusal(self, connection: Any, headers: Any) -> Any:
        """400 for malformed or duplicated headers, 403 for a ``Host`` not of this server (DNS rebinding), else
        None, with the client's address (read through a trusted proxy) kept on ``connection``."""
        problem = header_problem(headers.get_all)
        status, text = http.HTTPStatus.BAD_REQUEST, f"{problem}\n"
        if problem is None:
            name = host_name(headers.get_all("Host")[0]) or ""
            if self.hosts.allows(name):
                self._client(connection, headers)
                return None
            status, text, problem = http.HTTPStatus.FORBIDDEN, "unknown host name\n", f"unknown Host {name[:80]!r}"
        self.refused += 1
        if time.monotonic() - self._logged >= 1.0:  # a flood is one line a second, not one per request
            self._logged = time.monotonic()
            log.warning("refused a request (%s); serve with --allowed-host NAME if it is this server's name", problem)
        return connection.respond(status, text)

    def _client(self, connection: Any, headers: Any) -> None:
        remote = getattr(connection, "remote_address", None)
        peer = remote[0] if isinstance(remote, (tuple, list)) and remote else str(remote)
        client = client_address(
            peer, headers.get_all("X-Forwarded-For"), headers.get_all("Forwarded"), self.hosts.network
        )
        with contextlib.suppress(AttributeError):
            connection.tpm_viz_client = client
        if client.startswith(PROXIED) and not self._warned_proxy:
            self._warned_proxy = True
            log.warning(
                "a connection from this computer carries X-Forwarded-For or Forwarded: a reverse proxy? Its tabs are "
                "not treated as local; serve with --trusted-proxy %s to read the students' own addresses",
                peer,
            )

    def __call__(self, connection: Any, request: Any, viser_response: Callable[[], Any]) -> Any:
        headers = request.headers
        refusal = self._refusal(connection, headers)
        if refusal is not None:
            return refusal
        if (key := self.keyboard.answer(request.path, same_origin(headers))) is not None:
            return connection.respond(*key)  # a key of the page script (viserkit/page.py)
        if request.path.partition("?")[0] == ALIVE_PATH:  # a disconnected page asking whether to reconnect
            return connection.respond(http.HTTPStatus.OK, "ok\n")
        if (seen := self.sightings.answer(request.path, same_origin(headers))) is not None:
            return connection.respond(*seen)  # what the page sees (viserkit/seen.py)
        if headers.get("Upgrade", "").lower() == "websocket":
            if same_origin(headers):
                return None
            self.refused += 1
            log.warning("refused a websocket from another site (Origin %.80s)", headers.get("Origin"))
            return connection.respond(http.HTTPStatus.FORBIDDEN, "cross-origin websocket refused\n")
        response = viser_response()
        path = request.path.partition("?")[0]
        if path in _PAGES:
            response = with_script(response)  # keys, live region, labels (viserkit/page.py)
        if (
            response is not None
            and response.status_code == 200
            and path in _PAGES
            and _cookie(headers, self.keys) is None
        ):
            response.headers["Set-Cookie"] = (
                f"{COOKIE}={self.keys.mint()}; Path=/; Max-Age={COOKIE_MAX_AGE}; HttpOnly; SameSite=Strict"
            )
        if response is not None and response.status_code == 200 and path in _PAGES:
            self._share(connection, request.path, headers, response)
            self._launch(request.path, response)
        return response

    def _launch(self, target: str, response: Any) -> None:
        """A page asked with ``?lti=TICKET`` (``serve --lti``): spend the ticket now, once, and keep its launch for
        this page's tab under a nonce in a short-lived cookie (:class:`~tpm_viz.classroom.launches.Tickets`)."""
        ticket = ticket_of_query(target.partition("?")[2])
        if self.tickets is not None and ticket is not None:
            nonce = self.tickets.arrive(ticket)
            response.headers["Set-Cookie"] = (
                f"{LAUNCH_COOKIE}={nonce}; Path=/; Max-Age={int(TICKET_SECONDS)}; HttpOnly; SameSite=Strict"
            )

    def _share(self, connection: Any, target: str, headers: Any, response: Any) -> None:
        """A page asked with ``?share=TOKEN``: keep the token for this page's tab, its nonce in a cookie; a page
        without one: forget a nonce still in the browser (a plain reload opens no link)."""
        token = token_of_query(target.partition("?")[2])
        if token is not None:
            nonce = self.links.put(token, str(getattr(connection, "tpm_viz_client", "")))
            response.headers["Set-Cookie"] = (
                f"{SHARE_COOKIE}={nonce}; Path=/; Max-Age={int(PENDING_SECONDS)}; HttpOnly; SameSite=Strict"
            )
        elif _share_nonce(headers) is not None:
            self.links.take(_share_nonce(headers))
            response.headers["Set-Cookie"] = f"{SHARE_COOKIE}=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict"
