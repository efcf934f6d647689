"""Who a connection really comes from, and which ``Host`` names this server answers to.

- **Trusted proxies** (``tpm-viz serve --trusted-proxy ADDR``, an address or a network such as ``10.0.0.0/24``):
  only a connection whose peer is one of them may say who the client is, in ``X-Forwarded-For`` (read first) or
  else ``Forwarded: for=...``. The client is the rightmost address of that list that is not itself a trusted
  proxy (a client can prepend anything; the proxy appends what it saw). A trusted peer that names no valid
  address gives :data:`UNKNOWN` (never the proxy's own, loopback, address). Without the flag the headers are
  ignored, and a connection from this machine that carries them is :data:`PROXIED` ``<peer>``: not loopback, so
  a reverse proxy on the laptop does not make every student "local" (the server warns once).
- **Host allow-list** (DNS rebinding: a page of ``rebind.example`` that resolves to 127.0.0.1 sends
  ``Host: rebind.example``): the machine's own names and addresses, every loopback address, ``localhost`` and
  the ``--allowed-host`` names; anything else is refused (403).
- **Header sanity**: ``Host``, ``Origin`` and the other headers the app reads once must be present at most once
  and well formed (an ``Origin`` of another site or scheme is well formed: the same-origin check refuses it, 403);
  otherwise 400 (never a 500).

Pure functions and a small class; no viser (``ui/classroom.py`` applies them to every handshake).
"""

from __future__ import annotations

import ipaddress
import re
import socket
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from urllib.parse import urlsplit

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = [
    "PROXIED",
    "SINGLE_HEADERS",
    "UNKNOWN",
    "HostRules",
    "Network",
    "client_address",
    "header_problem",
    "host_name",
    "is_loopback",
    "parse_allowed_host",
    "parse_trusted_proxy",
]

UNKNOWN = "unknown"
"""The client address when a trusted proxy named none that could be read."""
PROXIED = "proxied"
"""Prefix of the address of a connection from this machine that carries forwarding headers without
``--trusted-proxy`` (``proxied 127.0.0.1``: not an address, so never loopback, never the presenter's)."""
SINGLE_HEADERS = (
    "Host",
    "Origin",
    "Cookie",
    "Upgrade",
    "User-Agent",
    "Accept-Language",
    "Accept-Encoding",
    "Sec-WebSocket-Key",
)
"""Headers the server reads as one value: sent twice, the request is malformed (400)."""
REFRESH_SECONDS = 10.0
"""How often at most [s] the machine's own addresses are looked up again (on a Host not in the list)."""
_NAME = re.compile(r"^(?=.{1,253}$)[a-z0-9_](?:[a-z0-9_-]{0,62})(?:\.[a-z0-9_](?:[a-z0-9_-]{0,62}))*\.?$")
_HOST = re.compile(r"^(\[[0-9a-f:.]+\]|[a-z0-9_.-]+)(?::([0-9]{1,5}))?$")
_FOR = re.compile(r'(?:^|;)\s*for\s*=\s*("[^"]*"|[^;,\s]*)', re.I)
_MAX_HOPS = 32


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an address, ``[::1]`` or ``localhost``) is this machine only (IPv4-mapped IPv6 included)."""
    if host.strip("[]").lower() == "localhost":
        return True
    try:
        address = ipaddress.ip_address(host.strip("[]"))
    except ValueError:  # "proxied 127.0.0.1", "unknown": not a plain address
        return False
    mapped = getattr(address, "ipv4_mapped", None)
    return address.is_loopback or (mapped is not None and mapped.is_loopback)


def _address(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    """An IP address from ``1.2.3.4``, ``1.2.3.4:80``, ``[::1]``, ``[::1]:80`` or ``::1`` (IPv4-mapped IPv6 as
    IPv4); None if it is none of these."""
    text = text.strip().strip('"').strip()
    if text.startswith("["):
        text = text[1:].partition("]")[0]
    elif text.count(":") == 1:
        text = text.partition(":")[0]
    try:
        address = ipaddress.ip_address(text)
    except ValueError:
        return None
    mapped = getattr(address, "ipv4_mapped", None)
    return mapped if mapped is not None else address


def parse_trusted_proxy(text: str) -> ipaddress.IPv4Network | ipaddress.IPv6Network:
    """``--trusted-proxy`` value: an address (``127.0.0.1``, ``::1``) or a network (``10.0.0.0/24``)."""
    try:
        return ipaddress.ip_network(str(text).strip().strip("[]"), strict=False)
    except ValueError:
        raise InputError(
            Phrase(
                "--trusted-proxy {value}: not an IP address or network; give the proxy's address, such as 127.0.0.1",
                value=repr(str(text)[:60]),
            )
        ) from None


def parse_allowed_host(text: str) -> str:
    """``--allowed-host`` value: a host name or an address, as a browser sends it in ``Host`` (no port)."""
    name = str(text).strip().lower().rstrip(".")
    if _NAME.match(name) or _address(name) is not None:
        return name.strip("[]")
    raise InputError(
        Phrase(
            "--allowed-host {value}: not a host name; give the name students type, such as tpm.example.edu",
            value=repr(str(text)[:60]),
        )
    )


@dataclass(frozen=True)
class Network:
    """The network settings of one server: ``trusted_proxies`` (see :func:`parse_trusted_proxy`) and the extra
    ``allowed_hosts`` (see :func:`parse_allowed_host`)."""

    trusted_proxies: tuple[ipaddress.IPv4Network | ipaddress.IPv6Network, ...] = ()
    allowed_hosts: tuple[str, ...] = ()

    @classmethod
    def of(cls, trusted_proxies: Iterable[str] = (), allowed_hosts: Iterable[str] = ()) -> Network:
        """Settings from command-line texts (one-line :class:`~tpm_viz.InputError` for a bad one)."""
        return cls(
            tuple(parse_trusted_proxy(t) for t in trusted_proxies), tuple(parse_allowed_host(h) for h in allowed_hosts)
        )

    def trusts(self, address: object) -> bool:
        """Whether ``address`` (text or an address) is a trusted proxy."""
        found = _address(str(address))
        return found is not None and any(found in net for net in self.trusted_proxies)


def client_address(peer: object, forwarded_for: Sequence[str], forwarded: Sequence[str], network: Network) -> str:
    """The client's address of a request from ``peer`` (the socket's address) carrying the values of the
    ``X-Forwarded-For`` and ``Forwarded`` headers (rules in the module docstring)."""
    peer_text = str(peer)
    if not network.trusts(peer_text):
        found = _address(peer_text)
        if (forwarded_for or forwarded) and found is not None and found.is_loopback:
            return f"{PROXIED} {found}"
        return str(found) if found is not None else peer_text
    hops: list[str] = []
    if forwarded_for:
        hops = [h for value in forwarded_for for h in value.split(",")]
    elif forwarded:
        hops = [m.group(1) for value in forwarded for element in value.split(",") for m in _FOR.finditer(element)]
    for hop in reversed(hops[-_MAX_HOPS:]):
        address = _address(hop)
        if address is None:
            return UNKNOWN  # "unknown", an obfuscated node or garbage: nobody to trust past it
        if not network.trusts(address):
            return str(address)
    return str(_address(hops[0])) if hops and _address(hops[0]) is not None else UNKNOWN


def host_name(host_header: str) -> str | None:
    """The name or address of a ``Host`` header value without its port (lower case, IPv6 without brackets), or
    None if it is malformed."""
    found = _HOST.match(host_header.strip().lower())
    if found is None or (found.group(2) is not None and int(found.group(2)) > 65535):
        return None
    name = found.group(1)
    if name.startswith("["):
        return name[1:-1] if _address(name) is not None else None
    return name.rstrip(".") if _NAME.match(name) or _address(name) is not None else None


def header_problem(get_all: Callable[[str], list[str]]) -> str | None:
    """Why a request's headers are malformed (400), or None: a header of :data:`SINGLE_HEADERS` sent twice, no or
    a malformed ``Host``, a malformed ``Origin`` (``null`` is well formed: a page without an origin)."""
    for name in SINGLE_HEADERS:
        if len(get_all(name)) > 1:
            return f"{name} header sent twice"
    hosts = get_all("Host")
    if not hosts or host_name(hosts[0]) is None:
        return "missing or malformed Host header"
    origins = get_all("Origin")
    if origins and origins[0].strip() != "null":
        try:
            parts = urlsplit(origins[0].strip())
            parts.port  # noqa: B018 - raises ValueError for a port out of range
        except ValueError:
            return "malformed Origin header"
        if not parts.scheme or any(ord(c) < 33 or ord(c) > 126 for c in origins[0].strip()):
            return "malformed Origin header"  # another site's well-formed origin is the same-origin check's (403)
    return None


def _own_names() -> set[str]:
    names = {"localhost", "localhost.localdomain"}
    try:
        hostname = socket.gethostname().lower()
    except OSError:
        return names
    if hostname:
        names |= {hostname, hostname.split(".")[0] + ".local", hostname + ".local"}
    return names


@dataclass
class HostRules:
    """Which ``Host`` names this server answers to: loopback addresses, ``localhost``, the machine's own name
    (and ``<name>.local``), ``bound`` (the address it listens on), the addresses ``addresses()`` returns (looked
    up again at most every :data:`REFRESH_SECONDS` when a Host is not found: a laptop changes networks) and the
    ``network``'s allowed hosts. Thread-safe."""

    network: Network = field(default_factory=Network)
    addresses: Callable[[], Iterable[str]] = lambda: ()
    bound: str = "127.0.0.1"
    clock: Callable[[], float] = time.monotonic
    _known: set[str] = field(default_factory=set, init=False)
    _looked: float = field(default=-1e18, init=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, init=False)

    def __post_init__(self) -> None:
        self._fixed = _own_names() | set(self.network.allowed_hosts)
        bound = _address(self.bound)
        if bound is not None and not bound.is_unspecified:
            self._fixed.add(str(bound))
        elif bound is None and self.bound:
            self._fixed.add(self.bound.lower())

    def allows(self, name: str) -> bool:
        """Whether the ``Host`` name (from :func:`host_name`) is one of this server's."""
        address = _address(name)
        if address is not None and address.is_loopback:
            return True
        key = str(address) if address is not None else name
        if key in self._fixed:
            return True
        with self._lock:
            if key not in self._known and self.clock() - self._looked >= REFRESH_SECONDS:
                self._looked = self.clock()
                try:
                    found = {str(a).lower() for a in self.addresses()}
                except Exception:
                    found = set()
                self._known |= {str(_address(a) or a) for a in found}
            return key in self._known
