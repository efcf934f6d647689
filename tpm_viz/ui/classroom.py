"""A real classroom: the addresses students type, who a tab is, and which websocket handshakes are refused.

- :func:`local_addresses` finds this machine's network addresses (the lookup is a parameter of :class:`Classroom`,
  so that tests inject theirs); :func:`student_urls` turns the bound host into the URLs to hand out (never a
  loopback address: on a student's phone 127.0.0.1 is the phone itself); :func:`qr_text` / :func:`qr_data_uri`
  draw one of them as a QR code (``segno``) for the terminal and the lecturer's panel.
- :class:`Handshakes` sees every HTTP request and websocket handshake (:func:`~._viser.hook_handshakes`): a
  websocket whose ``Origin`` is not the host the page was served under is refused with 403 (the same-origin check
  Jupyter's server makes: any page open in the lecturer's browser could otherwise drive the mechanism on
  127.0.0.1); a client without ``Origin`` (not a browser) may connect. The page's response sets a random
  ``tpmviz_id`` cookie, which the browser sends back with every websocket handshake, reconnections included: it is
  how a tab that comes back after a wifi blip or a restart is recognised (:func:`identity`).
"""

from __future__ import annotations

import http
import io
import ipaddress
import logging
import re
import secrets
import socket
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from http.cookies import SimpleCookie
from typing import Any
from urllib.parse import urlsplit

import segno

__all__ = [
    "COOKIE",
    "Classroom",
    "Handshakes",
    "identity",
    "is_loopback_address",
    "local_addresses",
    "qr_data_uri",
    "qr_text",
    "same_origin",
    "student_urls",
]

log = logging.getLogger("tpm_viz.ui")

COOKIE = "tpmviz_id"
COOKIE_MAX_AGE = 7 * 24 * 3600
_COOKIE_VALUE = re.compile(r"^[0-9a-f]{32}$")
_PAGES = ("/", "/index.html")


def is_loopback_address(host: str) -> bool:
    """Whether ``host`` (an address or ``localhost``) is this machine only."""
    if host.strip("[]").lower() == "localhost":
        return True
    try:
        address = ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return False
    mapped = getattr(address, "ipv4_mapped", None)
    return address.is_loopback or (mapped is not None and mapped.is_loopback)


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
    return list(dict.fromkeys(a for a in found if not is_loopback_address(a) and a != "0.0.0.0"))


def student_urls(host: str, port: int, addresses: Iterable[str]) -> list[str]:
    """The URLs students type: every given address of this machine when bound to all of them, else the host."""
    if host in ("0.0.0.0", "::", ""):
        hosts = [a for a in addresses if not is_loopback_address(a)]
    else:
        hosts = [] if is_loopback_address(host) else [host]
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
    ``presenter_address`` says which connecting address makes a tab the presenter (default: loopback)."""

    addresses: Callable[[], list[str]] = local_addresses
    presenter_address: Callable[[str], bool] = is_loopback_address
    token: str = field(default_factory=lambda: secrets.token_urlsafe(9))


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


def _cookie(headers: Any) -> str | None:
    raw = headers.get("Cookie")
    if not raw:
        return None
    try:
        jar: SimpleCookie = SimpleCookie()
        jar.load(raw)
    except Exception:  # a malformed Cookie header: no identity
        return None
    morsel = jar.get(COOKIE)
    return morsel.value if morsel is not None and _COOKIE_VALUE.match(morsel.value) else None


def identity(remote: Any, headers: Any) -> str | None:
    """Who a tab is across reconnections: ``c:<cookie>`` (a browser with the page's cookie), else ``a:<address and
    user agent>`` for a browser that blocks cookies (weaker: its copy is only offered back, never restored by
    itself), else None (not a browser: no ``Origin``, no cookie; nothing is kept for it)."""
    cookie = None if headers is None else _cookie(headers)
    if cookie is not None:
        return f"c:{cookie}"
    if headers is None or headers.get("Origin") is None:
        return None
    host = remote[0] if isinstance(remote, (tuple, list)) and remote else str(remote)
    agent = "" if headers is None else str(headers.get("User-Agent", ""))[:200]
    return f"a:{host}|{agent}"


class Handshakes:
    """The hook of :func:`~._viser.hook_handshakes`: refuse cross-origin websockets, give pages an identity."""

    def __init__(self) -> None:
        self.refused = 0

    def __call__(self, connection: Any, request: Any, viser_response: Callable[[], Any]) -> Any:
        headers = request.headers
        if headers.get("Upgrade", "").lower() == "websocket":
            if same_origin(headers):
                return None
            self.refused += 1
            log.warning("refused a websocket from another site (Origin %.80s)", headers.get("Origin"))
            return connection.respond(http.HTTPStatus.FORBIDDEN, "cross-origin websocket refused\n")
        response = viser_response()
        path = request.path.partition("?")[0]
        if response is not None and response.status_code == 200 and path in _PAGES and _cookie(headers) is None:
            response.headers["Set-Cookie"] = (
                f"{COOKIE}={secrets.token_hex(16)}; Path=/; Max-Age={COOKIE_MAX_AGE}; HttpOnly; SameSite=Strict"
            )
        return response
