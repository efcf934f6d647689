"""tpm-viz's own script in viser's page: keys, a live region, labels and focus (viser's public API has none).

viser's page is one HTML file (its client bundle inlined). :func:`with_script` adds :data:`SCRIPT` before its
``</body>`` (the gzipped variant is unpacked, edited and packed once per page body, then cached). The script:

- sends the keys of :data:`KEYS` (when focus is not in a text field, a slider, a list or a tab strip; no Ctrl, Alt or
  Meta) to :data:`KEY_PATH` with the tab's nonce, one request at a time (at most :data:`QUEUED` keys waiting, more are
  dropped): the nonce is the ``data-tpmviz-keys`` attribute of a hidden element the server put in this tab's panel
  (:mod:`tpm_viz.ui.keyboard`), so a key moves this tab's mechanism only, and a page that does not know it can do
  nothing;
- keeps one ``aria-live="polite"`` region (``#tpmviz-live``) with the text of the pose banner (``[data-q=banner]``),
  written only when the banner's words change (its numbers masked: a warning whose cos θ moves by 0.001 is not
  announced again; a new warning, or back to a regular pose, is);
- gives every input whose ``<label for>`` names no element an ``aria-label`` (viser's text fields, sliders' number
  boxes), names unnamed buttons by their ``title`` or icon, gives the 3D canvas a name and a place in the Tab order,
  and draws a visible focus outline; a ``MutationObserver`` keeps this up as viser rebuilds the panel.

Parsing a key request (:func:`key_request`) is here too: the wire format is the script's.
"""

from __future__ import annotations

import gzip
import json
import threading
from dataclasses import dataclass
from typing import Any
from urllib.parse import parse_qs, urlsplit

__all__ = ["KEYS", "KEY_PATH", "QUEUED", "SCRIPT", "KeyRequest", "key_request", "with_script"]

KEY_PATH = "/tpm-viz/key"
"""The path the page script sends a key to (``GET``: websockets' HTTP server reads nothing else)."""

KEYS = (
    "ArrowLeft",
    "ArrowRight",
    "ArrowUp",
    "ArrowDown",
    "KeyQ",
    "KeyA",
    "KeyW",
    "KeyS",
)
"""The physical keys (``KeyboardEvent.code``: the same on every layout, Korean included) the script sends."""

QUEUED = 8
"""Keys the script keeps while one is on its way; more are dropped (a held key repeats ~30 times a second)."""

NONCE_CHARS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_")


@dataclass(frozen=True)
class KeyRequest:
    """One key the page sent: the tab's ``nonce``, the key's ``code`` (one of :data:`KEYS`), Shift held."""

    nonce: str
    code: str
    shift: bool


def key_request(path: str) -> KeyRequest | None:
    """The key of a request for ``path`` (its query ``n``, ``k``, ``s``), or None when the path is not
    :data:`KEY_PATH`. Raises ``ValueError`` (one line) for a malformed one."""
    try:
        parts = urlsplit(path)
    except ValueError as exc:
        raise ValueError("malformed key request") from exc
    if parts.path != KEY_PATH:
        return None
    query = parse_qs(parts.query, max_num_fields=4)
    nonce, code, shift = (query.get(name, [""])[0] for name in ("n", "k", "s"))
    if not 16 <= len(nonce) <= 64 or not set(nonce) <= NONCE_CHARS:
        raise ValueError("malformed key request: nonce")
    if code not in KEYS:
        raise ValueError("malformed key request: key")
    return KeyRequest(nonce, code, shift == "1")


SCRIPT = (
    r"""
(() => {
  "use strict";
  if (window.__tpmvizPage) return;
  window.__tpmvizPage = true;
  const PATH = "__PATH__";
  const KEYS = new Set(__KEYS__);
  const QUEUED = __QUEUED__;
  const HIDDEN = "position:absolute;width:1px;height:1px;margin:-1px;padding:0;overflow:hidden;" +
    "clip:rect(0 0 0 0);white-space:nowrap;border:0";
  const SKIP = 'input, textarea, select, [contenteditable=""], [contenteditable="true"], [role="slider"], ' +
    '[role="tablist"], [role="tab"], [role="combobox"], [role="listbox"], [role="menu"], [role="radiogroup"]';

  // -- keys: this tab's nonce, one request at a time -----------------------------------------------------------
  const queue = [];
  let sending = false;
  function nonce() {
    const el = document.querySelector("[data-tpmviz-keys]");
    return el ? el.getAttribute("data-tpmviz-keys") : null;
  }
  function pump() {
    if (sending || queue.length === 0) return;
    const [code, shift] = queue.shift();
    const n = nonce();
    if (!n) { queue.length = 0; return; }
    sending = true;
    const url = PATH + "?n=" + encodeURIComponent(n) + "&k=" + code + "&s=" + (shift ? "1" : "0");
    fetch(url, { cache: "no-store", credentials: "same-origin" })
      .catch(() => {})
      .finally(() => { sending = false; pump(); });
  }
  window.addEventListener("keydown", (ev) => {
    const tab = ev.target && ev.target.closest ? ev.target.closest('[role="tab"]') : null;
    if (tab && (ev.key === "Enter" || ev.key === " ") && !ev.repeat) {  // viser's tabs answer clicks only
      ev.preventDefault();
      tab.click();
      return;
    }
    if (!KEYS.has(ev.code) || ev.ctrlKey || ev.altKey || ev.metaKey || ev.isComposing) return;
    const t = ev.target;
    if (t && t.closest && t.closest(SKIP)) return;
    if (!nonce()) return;
    ev.preventDefault();
    ev.stopImmediatePropagation();
    if (queue.length < QUEUED) queue.push([ev.code, ev.shiftKey]);
    pump();
  }, true);

  // -- the pose status, announced when its words change ----------------------------------------------------------
  let live = null;
  let said = null;
  function region() {
    if (live && live.isConnected) return live;
    live = document.createElement("div");
    live.id = "tpmviz-live";
    live.setAttribute("role", "status");
    live.setAttribute("aria-live", "polite");
    live.setAttribute("aria-atomic", "true");
    live.style.cssText = HIDDEN;
    document.body.appendChild(live);
    return live;
  }
  function announce() {
    const banner = document.querySelector('[data-q="banner"]');
    if (!banner) return;
    const text = (banner.querySelector("b") || banner).textContent.replace(/\s+/g, " ").trim();
    const key = (banner.getAttribute("data-level") || "") + "|" + text.replace(/[-−+]?\d[\d.,]*/g, "#");
    if (key === said) return;
    said = key;
    region().textContent = text;
  }

  // -- names for assistive technology, the Tab order, a visible focus ---------------------------------------------
  function words(key, fallback) {
    const el = document.querySelector('[data-tpmviz-keys] [data-w="' + key + '"]');
    return el ? el.textContent.trim() : fallback;
  }
  function label() {
    for (const lab of document.querySelectorAll("label[for]")) {
      const target = document.getElementById(lab.getAttribute("for"));
      if (target && target.matches("input, textarea, select")) continue;
      const p = lab.closest("p");
      const box = p && p.parentElement ? p.parentElement.parentElement : lab.parentElement;
      const text = lab.textContent.replace(/\s+/g, " ").trim();
      if (!box || !text) continue;
      for (const input of box.querySelectorAll('input:not([type="hidden"]), textarea, [role="slider"]')) {
        if (input.getAttribute("aria-label") !== text) input.setAttribute("aria-label", text);
      }
    }
    for (const button of document.querySelectorAll("button, [role=button]")) {
      if (button.textContent.trim() || (button.getAttribute("aria-label") || "").trim()) continue;
      const icon = button.querySelector('svg[class*="tabler-icon-"]');
      const kind = icon ? icon.getAttribute("class").replace(/.*tabler-icon-([\w-]+).*/, "$1") : "";
      const name = button.getAttribute("title") ||
        (String(button.className).includes("CloseButton") || kind === "x" ? words("close", "Close") :
         kind === "adjustments" ? words("settings", "Settings") : kind.replace(/-/g, " "));
      if (name) button.setAttribute("aria-label", name);
    }
    for (const canvas of document.querySelectorAll("canvas")) {
      const name = words("view", "3D view of the mechanism");
      if (canvas.getAttribute("aria-label") === name) continue;
      canvas.setAttribute("role", "img");
      canvas.setAttribute("aria-label", name);
      if (canvas.style.pointerEvents !== "none") canvas.tabIndex = 0;
    }
    for (const el of document.querySelectorAll("[tabindex]")) {
      if (el.tabIndex > 0) el.tabIndex = 0;
    }
    const root = document.getElementById("root");
    if (root && !root.getAttribute("role")) root.setAttribute("role", "main");
  }
  function style() {
    const css = document.createElement("style");
    css.textContent = ":focus-visible { outline: 3px solid #0f766e !important; outline-offset: 2px !important; }\n" +
      ":root { --mantine-color-dimmed: #5c636a !important; --mantine-color-gray-filled: #5c636a !important; " +
      "--mantine-color-gray-filled-hover: #495057 !important; --mantine-color-custom-outline: #0f766e !important; }";
    document.head.appendChild(css);
    const title = document.createElement("h1");
    title.textContent = "tpm-viz";
    title.style.cssText = HIDDEN;
    document.body.prepend(title);
  }

  let pending = false;
  function tick() {
    pending = false;
    announce();
    label();
  }
  function start() {
    style();
    region();
    tick();
    new MutationObserver(() => {
      if (!pending) { pending = true; requestAnimationFrame(tick); setTimeout(tick, 250); }
    }).observe(document.body, { subtree: true, childList: true, characterData: true, attributes: true,
                                attributeFilter: ["data-level", "for"] });
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start); else start();
})();
""".replace("__PATH__", KEY_PATH)
    .replace("__KEYS__", json.dumps(KEYS))
    .replace("__QUEUED__", str(QUEUED))
)
"""The page script (see the module docstring)."""

_TAG = f"<script>{SCRIPT}</script>".encode()
_CACHE: dict[bytes, bytes] = {}
_CACHE_LOCK = threading.Lock()
_CACHE_SIZE = 4


def _edited(body: bytes, zipped: bool) -> bytes:
    """``body`` with the script before its last ``</body>`` (at the end if it has none)."""
    html = gzip.decompress(body) if zipped else body
    at = html.rfind(b"</body>")
    html = html + _TAG if at < 0 else html[:at] + _TAG + html[at:]
    return gzip.compress(html, mtime=0) if zipped else html


def with_script(response: Any) -> Any:
    """viser's page ``response`` (a websockets ``Response``, edited in place) with :data:`SCRIPT` in it; any other
    response unchanged. The edited body is cached per body (viser serves the same bytes object every time)."""
    if response is None or response.status_code != 200:
        return response
    headers = response.headers
    if not str(headers.get("Content-Type", "")).startswith("text/html"):
        return response
    body = bytes(response.body)
    zipped = headers.get("Content-Encoding", "identity") == "gzip"
    with _CACHE_LOCK:
        edited = _CACHE.get(body)
    if edited is None:
        edited = _edited(body, zipped)
        with _CACHE_LOCK:
            if len(_CACHE) >= _CACHE_SIZE:
                _CACHE.clear()
            _CACHE[body] = edited
    response.body = edited
    del headers["Content-Length"]
    headers["Content-Length"] = str(len(edited))
    return response
