"""A browser tab through a network drop, measured (``tests/e2e/test_browser_reconnect.py`` and
``benchmarks/bench_drop.py`` use the same code).

The tab talks to the app through a :class:`~tests.support.proxy.TcpProxy`; :func:`through_a_drop` drops the network
for a while (refused or black-holed, :meth:`~tests.support.proxy.TcpProxy.drop`), lets it back and measures the time
from the network's return to the tab being live again: the app has built the tab's view again, which it does once
the page's websocket is open and the page sent its camera (viser's ``on_client_connect``): from then on its inputs
reach the app. Also counted: the websocket attempts the page made while the network was down (``retry`` messages
that reached viser's websocket worker, logged by :data:`RETRY_LOG_JS`), the connection attempts at the proxy, and
the page's *Reconnect now* button while it waited.

:func:`serve_settings` serves the page with other settings of the page script (``CONFIG`` of
:mod:`tpm_viz.viserkit.page`), edited in the page the server sent: ``{"reconnect": None}`` is viser's own retrying
(the code before the page script took it over), a long ``every`` leaves only the button and the browser's events.
The page carries the settings in ``window.__tpmvizSettings`` once :data:`SETTINGS_JS` has put them in.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from typing import Any

from tpm_viz.viserkit.page import CONFIG, config_json

__all__ = ["RETRY_LOG_JS", "SETTINGS_JS", "Comeback", "new_view", "retries", "serve_settings", "through_a_drop"]

RETRY_LOG_JS = """
(() => {
  // Every message to a Web Worker other than "send" (viser's worker: set_server, retry, close) with its
  // performance.now() time [ms], in window.__workerPosts. Wrapped before the page script wraps Worker again, so a
  // "retry" the page script holds back never shows here.
  const Orig = window.Worker;
  const log = (window.__workerPosts = []);
  function Logged(url, options) {
    const w = new Orig(url, options);
    const post = w.postMessage.bind(w);
    w.postMessage = (data, transfer) => {
      if (data && data.type && data.type !== "send") log.push([data.type, performance.now()]);
      return transfer === undefined ? post(data) : post(data, transfer);
    };
    return w;
  }
  Logged.prototype = Orig.prototype;
  window.Worker = Logged;
})();
"""
"""Init script of a page: the messages to viser's websocket worker other than ``send``, timed."""

BUTTON = "#tpmviz-reconnect"
"""The page script's *Reconnect now* button."""


@dataclass(frozen=True)
class Comeback:
    """One tab through one drop."""

    live_after: float | None
    """Seconds from the network's return to the tab live again (None: not within the bound given)."""
    retries: int
    """Websocket attempts the page made while the network was down."""
    arrivals: tuple[float, ...]
    """Connection attempts at the proxy during the drop and until the tab was live, seconds after the drop began."""
    button: str | None
    """The *Reconnect now* button's text while the tab waited (None: not shown)."""


SETTINGS_JS = """
(() => {
  // The page script's settings element, rewritten as the parser inserts it (a mutation observer's callback runs
  // before the parser runs the next inline script: the page script reads the new settings).
  const wanted = %s;
  new MutationObserver((records, observer) => {
    const el = document.getElementById("tpmviz-page-config");
    if (!el) return;
    try { JSON.parse(el.textContent); } catch (e) { return; }  // not all of it parsed yet
    el.textContent = wanted;
    window.__tpmvizSettings = JSON.parse(wanted);
    observer.disconnect();
  }).observe(document, { childList: true, subtree: true, characterData: true });
})();
"""


def serve_settings(page: Any, settings: dict[str, Any]) -> None:
    """Give ``page`` the app's page with the page script's settings updated by ``settings`` (e.g.
    ``{"reconnect": None}``): an init script rewrites the settings element the server sent before the script reads
    it. (A page fulfilled by a Playwright route instead could not open its websocket at all.)"""
    page.add_init_script(SETTINGS_JS % json.dumps(config_json({**CONFIG, **settings})))


def retries(page: Any) -> int:
    """The ``retry`` messages that reached viser's websocket worker so far (the page needs :data:`RETRY_LOG_JS`)."""
    return int(page.evaluate("(window.__workerPosts || []).filter(([type]) => type === 'retry').length"))


def new_view(app: Any, old: Any) -> Any:
    """The app's view of a tab other than ``old`` (None: none yet)."""
    return next((v for v in list(app.views.values()) if v is not old), None)


def _until(predicate: Any, bound: float, step: float = 0.02) -> float | None:
    """``time.monotonic()`` when ``predicate()`` first held, polled every ``step`` s for at most ``bound`` s (None:
    it never did)."""
    deadline = time.monotonic() + bound
    while True:
        if predicate():
            return time.monotonic()
        if time.monotonic() > deadline:
            return None
        time.sleep(step)


def through_a_drop(app: Any, page: Any, proxy: Any, seconds: float, black_hole: bool, bound: float) -> Comeback:
    """Drop the network under ``page``'s tab (its view in ``app`` live, the page served through ``proxy``) for
    ``seconds``, refused or black-holed, and wait at most ``bound`` seconds after its return for the tab to be live
    again. The page's *Reconnect now* button is read once it shows (if it does before the network returns)."""
    view = new_view(app, None)
    assert view is not None and len(app.views) == 1, "one live tab first"
    before = retries(page)
    first = len(proxy.arrivals)
    began = time.monotonic()
    proxy.drop(seconds, black_hole=black_hole)
    back = began + seconds
    button = None
    wait_ms = (back - time.monotonic() - 0.5) * 1000.0
    if wait_ms > 0:
        shown = page.locator(BUTTON)
        try:
            shown.wait_for(state="visible", timeout=wait_ms)
            button = shown.text_content()
        except Exception as exc:  # playwright's TimeoutError: not shown before the network returns
            if type(exc).__name__ != "TimeoutError":
                raise
    time.sleep(max(0.0, back - time.monotonic() - 0.05))
    tried = retries(page) - before  # read just before the network returns
    time.sleep(max(0.0, back - time.monotonic()))
    live = _until(lambda: new_view(app, view) is not None, bound)
    arrivals = tuple(round(t - began, 2) for t in proxy.arrivals[first:])
    return Comeback(None if live is None else live - back, tried, arrivals, button)
