"""The LTI configuration file of ``tpm-viz serve --lti CONFIG.toml`` (format in docs/lti.md).

.. code-block:: toml

    [tool]
    private_key = "tool-key.pem"          # the tool's RSA key (tpm-viz lti keygen), relative to this file
    url = "https://tpm.example.edu"       # optional: where the LMS reaches the LTI endpoints (default http://HOST:PORT)
    app_url = "https://tpm.example.edu/"  # optional: where a browser opens the app (default: the app's own URL)
    port = 8081                           # optional: the LTI service's port on the app's host (0: any free one)
    state_cookie = "required"             # optional: "required" (default over https) or "when-sent" (over http)

    [[platform]]                          # one per LMS registration
    issuer = "https://moodle.example.edu"
    client_id = "aBcD1234"
    deployment_ids = ["1"]
    auth_login_url = "https://moodle.example.edu/mod/lti/auth.php"
    auth_token_url = "https://moodle.example.edu/mod/lti/token.php"
    key_set_url = "https://moodle.example.edu/mod/lti/certs.php"

Read with the bounded reader (:func:`tpm_viz.core.files.read_toml`); every problem is one
:class:`~tpm_viz.core.errors.InputError` naming the file, the key and what to change (the CLI exits 2 with it).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from tpm_viz.core.errors import InputError
from tpm_viz.core.files import read_toml

__all__ = ["DEFAULT_PORT", "MAX_CONFIG_BYTES", "MAX_PLATFORMS", "Config", "Platform", "StateCookie", "read_config"]

MAX_CONFIG_BYTES = 256 << 10
MAX_PLATFORMS = 64
MAX_TEXT = 1000
DEFAULT_PORT = 8081
"""The LTI service's port when the file names none (the app's default is 8080)."""
_TOOL_KEYS = {"private_key", "url", "app_url", "port", "state_cookie"}
_PLATFORM_KEYS = ("issuer", "client_id", "deployment_ids", "auth_login_url", "auth_token_url", "key_set_url")


class StateCookie(enum.Enum):
    """Whether a launch must bring back the login's state cookie (``required``) or only when the browser sent it
    (``when-sent``: plain http, where a cross-site ``Secure`` cookie cannot exist; docs/lti.md)."""

    REQUIRED = "required"
    WHEN_SENT = "when-sent"


@dataclass(frozen=True)
class Platform:
    """One LMS registration (the ``[[platform]]`` table)."""

    issuer: str
    client_id: str
    deployment_ids: tuple[str, ...]
    auth_login_url: str
    auth_token_url: str
    key_set_url: str


@dataclass(frozen=True)
class Config:
    """The whole file. ``url``: the public base of the LTI endpoints ('' = ``http://HOST:PORT``); ``app_url``: the
    app's public URL ('' = the app's own); ``state_cookie``: None = by the scheme of ``url``."""

    private_key: Path
    platforms: tuple[Platform, ...]
    url: str = ""
    app_url: str = ""
    port: int = DEFAULT_PORT
    state_cookie: StateCookie | None = None

    def platform(self, issuer: str, client_id: str | None) -> Platform | None:
        """The registration of ``issuer`` (and ``client_id``; None: the issuer's only one), or None."""
        found = [p for p in self.platforms if p.issuer == issuer and client_id in (None, p.client_id)]
        return found[0] if len(found) == 1 else None


def _bad(path: Path, where: str, what: str) -> InputError:
    return InputError(f"{path}: {where}: {what}")


def _text(path: Path, table: dict[str, Any], key: str, where: str) -> str:
    value = table.get(key)
    if not isinstance(value, str) or not value.strip() or len(value) > MAX_TEXT:
        raise _bad(path, f"{where} {key}", f"give a non-empty string of at most {MAX_TEXT} characters")
    return value.strip()


def _url(path: Path, table: dict[str, Any], key: str, where: str, optional: bool = False) -> str:
    if optional and key not in table:
        return ""
    value = _text(path, table, key, where)
    try:
        parts = urlsplit(value)
        host = parts.hostname
    except ValueError:
        parts, host = urlsplit(""), None
    if parts.scheme not in ("http", "https") or not host or parts.fragment:
        raise _bad(
            path, f"{where} {key}", f"{value[:80]!r} is not an http(s) URL; write it like https://lms.example.edu/path"
        )
    return value


def _unknown(path: Path, table: dict[str, Any], known: set[str] | tuple[str, ...], where: str) -> None:
    extra = sorted(set(table) - set(known))
    if extra:
        raise _bad(path, where, f"unknown key {extra[0][:60]!r}; the keys are {', '.join(sorted(known))}")


def _platform(path: Path, table: Any, n: int) -> Platform:
    where = f"[[platform]] {n}"
    if not isinstance(table, dict):
        raise _bad(path, where, "must be a table with " + ", ".join(_PLATFORM_KEYS))
    _unknown(path, table, _PLATFORM_KEYS, where)
    ids = table.get("deployment_ids")
    if (
        not isinstance(ids, list)
        or not ids
        or len(ids) > 100
        or not all(isinstance(i, str) and i.strip() and len(i) <= 255 for i in ids)
    ):
        raise _bad(path, f"{where} deployment_ids", 'give a list of the LMS\'s deployment ids, e.g. ["1"]')
    return Platform(
        issuer=_text(path, table, "issuer", where),
        client_id=_text(path, table, "client_id", where),
        deployment_ids=tuple(i.strip() for i in ids),
        auth_login_url=_url(path, table, "auth_login_url", where),
        auth_token_url=_url(path, table, "auth_token_url", where),
        key_set_url=_url(path, table, "key_set_url", where),
    )


def read_config(path: str | Path) -> Config:
    """The checked configuration at ``path`` (one-line :class:`InputError` naming the key otherwise)."""
    path = Path(path)
    raw = read_toml(path, MAX_CONFIG_BYTES)
    _unknown(path, raw, {"tool", "platform"}, "top level")
    tool = raw.get("tool")
    if not isinstance(tool, dict):
        raise _bad(path, "[tool]", 'missing: add [tool] with private_key = "tool-key.pem" (tpm-viz lti keygen)')
    _unknown(path, tool, _TOOL_KEYS, "[tool]")
    key = Path(_text(path, tool, "private_key", "[tool]"))
    port = tool.get("port", DEFAULT_PORT)
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise _bad(path, "[tool] port", "give a whole number 0-65535 (0: any free port)")
    cookie = tool.get("state_cookie")
    if cookie is not None and cookie not in {c.value for c in StateCookie}:
        raise _bad(path, "[tool] state_cookie", 'write "required" or "when-sent"')
    platforms = raw.get("platform")
    if not isinstance(platforms, list) or not platforms:
        raise _bad(path, "[[platform]]", "missing: add one [[platform]] table per LMS registration")
    if len(platforms) > MAX_PLATFORMS:
        raise _bad(path, "[[platform]]", f"at most {MAX_PLATFORMS} platforms; remove some")
    found = tuple(_platform(path, table, n) for n, table in enumerate(platforms, start=1))
    pairs = [(p.issuer, p.client_id) for p in found]
    if len(set(pairs)) != len(pairs):
        raise _bad(path, "[[platform]]", "the same issuer and client_id twice; keep one table for each")
    return Config(
        private_key=key if key.is_absolute() else path.parent / key,
        platforms=found,
        url=_url(path, tool, "url", "[tool]", optional=True).rstrip("/"),
        app_url=_url(path, tool, "app_url", "[tool]", optional=True),
        port=port,
        state_cookie=None if cookie is None else StateCookie(cookie),
    )
