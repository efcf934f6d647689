"""The OIDC third-party login (LTI Core 1.3 §5.1.1, IMS Security Framework §5.1.1): ``/lti/login`` to the platform.

The platform calls the login URL with ``iss``, ``login_hint``, ``target_link_uri`` and optionally
``lti_message_hint``, ``client_id``, ``lti_deployment_id``; :func:`begin_login` checks them against the
configuration and answers the URL of the platform's authorisation endpoint with ``scope=openid``,
``response_type=id_token``, ``response_mode=form_post``, ``prompt=none``, ``client_id``, ``redirect_uri``,
``login_hint``, ``lti_message_hint``, a fresh ``state`` and ``nonce`` (the service sends it as a 302).

:class:`Logins` keeps each login server-side for :data:`LOGIN_SECONDS`: its state, nonce, platform, target and the
address it came from. A launch spends its state once (:meth:`Logins.finish`); a spent one is remembered as
*replayed*, an unknown or expired one is refused with *state*. Bounded: :data:`MAX_LOGINS` waiting logins and
:data:`MAX_LOGINS_PER_ADDRESS` per address (that address's oldest goes first, never another's).
"""

from __future__ import annotations

import secrets
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from urllib.parse import urlencode

from tpm_viz.core.words import Phrase, T
from tpm_viz.lti.config import Config, Platform
from tpm_viz.lti.refusals import Refused, Why

__all__ = ["LOGIN_SECONDS", "MAX_LOGINS", "MAX_LOGINS_PER_ADDRESS", "Login", "Logins", "begin_login"]

LOGIN_SECONDS = 300.0
"""How long a login waits for its launch [s] (the platform answers within seconds)."""
MAX_LOGINS = 5000
MAX_LOGINS_PER_ADDRESS = 50
MAX_PARAMETER = 2048


@dataclass(frozen=True)
class Login:
    """One login waiting for its launch."""

    state: str
    nonce: str
    platform: Platform
    target: str
    redirect_uri: str
    address: str
    expires: float


class Logins:
    """Logins waiting for their launch, and the states and nonces spent (thread-safe; ``clock``: seconds)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self.clock = clock
        self._lock = threading.Lock()
        self._waiting: OrderedDict[str, Login] = OrderedDict()
        self._spent: OrderedDict[str, float] = OrderedDict()  # state or "n:" + nonce -> forget after

    def __len__(self) -> int:
        with self._lock:
            self._expire(self.clock())
            return len(self._waiting)

    def _expire(self, now: float) -> None:
        while self._waiting and next(iter(self._waiting.values())).expires <= now:
            self._waiting.popitem(last=False)
        while self._spent and next(iter(self._spent.values())) <= now:
            self._spent.popitem(last=False)

    def begin(self, platform: Platform, target: str, redirect_uri: str, address: str) -> Login:
        """A new login (fresh state and nonce) from ``address``."""
        with self._lock:
            now = self.clock()
            self._expire(now)
            login = Login(
                secrets.token_urlsafe(32), secrets.token_urlsafe(32), platform, target, redirect_uri, address,
                now + LOGIN_SECONDS,
            )  # fmt: skip
            mine = [s for s, w in self._waiting.items() if w.address == address]
            for old in mine[: max(0, len(mine) - MAX_LOGINS_PER_ADDRESS + 1)]:
                del self._waiting[old]
            while len(self._waiting) >= MAX_LOGINS:
                self._waiting.popitem(last=False)
            self._waiting[login.state] = login
        return login

    def finish(self, state: object) -> Login:
        """The login of ``state``, spent (refused: *replayed* if spent before, *state* if unknown or expired)."""
        if not isinstance(state, str) or not state or len(state) > MAX_PARAMETER:
            raise Refused(Why.STATE, T("the launch carries no state of a login of this tool (state): launch again"))
        with self._lock:
            now = self.clock()
            self._expire(now)
            login = self._waiting.pop(state, None)
            if login is None:
                if state in self._spent:
                    raise Refused(
                        Why.REPLAYED, T("this launch was used already (replayed): launch again from the course")
                    )
                raise Refused(
                    Why.STATE,
                    T("the launch's state is unknown or expired (state): launch again from the course within 5 min"),
                )
            self._remember(state, now)
        return login

    def spend_nonce(self, nonce: str) -> bool:
        """Mark ``nonce`` used; False if it was used before (a replay)."""
        with self._lock:
            key = "n:" + nonce
            if key in self._spent:
                return False
            self._remember(key, self.clock())
            return True

    def _remember(self, key: str, now: float) -> None:
        self._spent[key] = now + 2 * LOGIN_SECONDS
        while len(self._spent) > 4 * MAX_LOGINS:
            self._spent.popitem(last=False)


def _parameter(params: Mapping[str, str], name: str, required: bool = True) -> str | None:
    value = params.get(name)
    if value is None or value == "":
        if required:
            raise Refused(Why.REQUEST, Phrase("the login request has no {name}: start it from the LMS", name=name))
        return None
    if len(value) > MAX_PARAMETER:
        raise Refused(Why.REQUEST, Phrase("the login request's {name} is too long", name=name))
    return value


def begin_login(
    config: Config, logins: Logins, params: Mapping[str, str], launch_urls: tuple[str, ...], address: str
) -> tuple[str, Login]:
    """The platform's authorisation URL for a login request (``params``: its query or form) and the login kept;
    ``launch_urls``: the tool's launch URLs (the first is the default ``redirect_uri``)."""
    issuer = _parameter(params, "iss") or ""
    login_hint = _parameter(params, "login_hint") or ""
    target = _parameter(params, "target_link_uri") or ""
    client_id = _parameter(params, "client_id", required=False)
    deployment = _parameter(params, "lti_deployment_id", required=False)
    hint = _parameter(params, "lti_message_hint", required=False)
    if not any(p.issuer == issuer for p in config.platforms):
        raise Refused(
            Why.ISSUER,
            Phrase("the login comes from a platform this tool does not know (issuer {iss}): add it as a [[platform]]",
                   iss=issuer[:120]),
        )  # fmt: skip
    platform = config.platform(issuer, client_id)
    if platform is None:
        raise Refused(
            Why.AUDIENCE,
            Phrase(
                "the login names a client this tool does not know (audience/client {client}): check client_id",
                client=str(client_id)[:120],
            ),
        )
    if deployment is not None and deployment not in platform.deployment_ids:
        raise Refused(
            Why.DEPLOYMENT,
            Phrase("unknown deployment {id} (deployment): add it to deployment_ids", id=deployment[:120]),
        )
    base = target.split("?", 1)[0].split("#", 1)[0].rstrip("/")
    matches = [url for url in launch_urls if url.rstrip("/") == base]
    if not matches:
        raise Refused(
            Why.LINK, Phrase("the link's target {url} is not this tool's launch URL (link)", url=target[:120])
        )
    login = logins.begin(platform, target, matches[0], address)
    query = {
        "scope": "openid",
        "response_type": "id_token",
        "response_mode": "form_post",
        "prompt": "none",
        "client_id": platform.client_id,
        "redirect_uri": login.redirect_uri,
        "login_hint": login_hint,
        "state": login.state,
        "nonce": login.nonce,
    }
    if hint is not None:
        query["lti_message_hint"] = hint
    joiner = "&" if "?" in platform.auth_login_url else "?"
    return f"{platform.auth_login_url}{joiner}{urlencode(query)}", login
