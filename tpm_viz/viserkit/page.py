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
  and draws a visible focus outline; a ``MutationObserver`` keeps this up as viser rebuilds the panel;
- shows viser's own English names (``aria-label``, ``title``, tooltip texts: *Collapse panel area*, *Expand
  column*, ...; the software-WebGL notice) in the tab's language: the hidden element carries each as
  ``<span data-en="English">shown</span>``;
- puts a field's hint (viser's Mantine tooltip, drawn above the field it explains, over the field above) beside the
  panel over the 3D view, or above the phone's sheet (CSS variables kept by a ``ResizeObserver``), and shows it on
  keyboard focus too (a ``mouseenter`` on the field's wrappers, which is what viser's tooltip listens to);
- folds and unfolds the panel with :data:`FOLD_KEY` in presentation mode (viser's own rail and collapse buttons,
  clicked), from anywhere but a text field;
- keeps viser's software-WebGL notice to a one-line strip on a phone (:data:`NOTICE_CSS`).

A second, separate script goes in with it: :data:`~tpm_viz.viserkit.seen.SEEN_SCRIPT` (a coarse pointer, the tab
of the panel that is open).

The wire format of a key (:func:`key_request`) is in :mod:`.keys` (re-exported here).
"""

from __future__ import annotations

import gzip
import json
import threading
from typing import Any

from tpm_viz.viserkit.keys import KEY_PATH, KEYS, QUEUED, KeyRequest, key_request
from tpm_viz.viserkit.seen import SEEN_SCRIPT

__all__ = [
    "FOLD_KEY",
    "KEYS",
    "KEY_PATH",
    "NOTICE_CSS",
    "QUEUED",
    "SCRIPT",
    "KeyRequest",
    "key_request",
    "with_script",
]

FOLD_KEY = "KeyP"
"""The key that folds and unfolds the panel in presentation mode (the page's own: never sent to the server)."""
TIP_GAP = 8
"""Gap between a hint's box and the panel (or the phone's sheet) [CSS px]."""

NOTICE_CSS = (
    "#webgl-software-rendering { max-width: calc(100vw - 16px) !important; min-height: 0 !important; "
    "padding: 0 2px 0 12px !important; }\n"
    "#webgl-software-rendering .mantine-Notification-description { display: none !important; }\n"
    "#webgl-software-rendering .mantine-Notification-title { font-size: 11px !important; margin: 0 !important; "
    "white-space: nowrap; overflow: hidden; text-overflow: ellipsis; }\n"
    "#webgl-software-rendering .mantine-Notification-closeButton { min-width: 24px; min-height: 24px; }\n"
    ".mantine-Notifications-root:has(#webgl-software-rendering) { top: 4px !important; left: 4px !important; }"
)
"""viser's "Software WebGL rendering detected" notice (a computer without a GPU) as a one-line strip, 24 px high, at
the canvas's top-left corner: on a phone (a window at most 36em wide, or a coarse pointer) and in a touch tab."""

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
  const FOLD = "__FOLD__";
  const GAP = __GAP__;
  const NOTICE = __NOTICE__;
  const TYPING = 'input:not([type="checkbox"]):not([type="radio"]), textarea, select, [contenteditable=""], ' +
    '[contenteditable="true"], [role="combobox"]';

  // -- presentation mode: the panel folds to its rail and back (viser's own buttons) ----------------------------
  function fold() {
    const rail = document.querySelector("[data-dock-rail-root] [data-dock-minimize-all]");
    const open = document.querySelector('[data-dock-region-collapse="right"]') ||
      document.querySelector("[data-dock-region-collapse]");
    const button = rail || open;
    if (!button) return false;
    button.click();
    return true;
  }

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
    if (ev.code === FOLD && !ev.ctrlKey && !ev.altKey && !ev.metaKey && !ev.isComposing && !ev.repeat &&
        !(ev.target && ev.target.closest && ev.target.closest(TYPING)) && document.querySelector("[data-live]")) {
      if (fold()) { ev.preventDefault(); ev.stopImmediatePropagation(); }
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

  // -- viser's own English names in the tab's language ------------------------------------------------------------
  function lexicon() {
    const m = new Map();
    for (const el of document.querySelectorAll("[data-tpmviz-keys] [data-en]")) {
      m.set(el.getAttribute("data-en"), el.textContent.trim());
    }
    return m;
  }
  function render(m, en) {
    if (m.has(en)) return m.get(en);
    for (const [key, shown] of m) {
      const at = key.indexOf("{name}");
      if (at < 0) continue;
      const head = key.slice(0, at), tail = key.slice(at + 6);
      if (en.length > head.length + tail.length && en.startsWith(head) && en.endsWith(tail)) {
        return shown.replace("{name}", en.slice(head.length, en.length - tail.length));
      }
    }
    return null;
  }
  function reword(m, el, key, now, write) {  // el's text `now`: shown in the tab's language (key: its dataset slot)
    const en = render(m, now) !== null ? now : (el.dataset[key + "Shown"] === now ? el.dataset[key] : null);
    if (en === null || en === undefined) return;
    const shown = render(m, en);
    if (shown === null) return;
    el.dataset[key] = en;
    el.dataset[key + "Shown"] = shown;
    if (now !== shown) write(shown);
  }
  function translate() {
    const m = lexicon();
    if (!m.size) return;
    for (const el of document.querySelectorAll("[aria-label], [title]")) {
      if (el.closest("[data-tpmviz-keys]")) continue;
      for (const [attr, key] of [["aria-label", "tpmvizLabel"], ["title", "tpmvizTitle"]]) {
        const now = el.getAttribute(attr);
        if (now) reword(m, el, key, now, (shown) => el.setAttribute(attr, shown));
      }
    }
    const texts = ".mantine-Tooltip-tooltip, #webgl-software-rendering :is(.mantine-Notification-title, " +
      ".mantine-Notification-description)";
    for (const tip of document.querySelectorAll(texts)) {
      const node = [...tip.childNodes].find((n) => n.nodeType === 3 && n.nodeValue.trim());
      if (node) reword(m, tip, "tpmvizTip", node.nodeValue.trim(), (shown) => { node.nodeValue = shown; });
    }
  }

  // -- a field's hint beside the panel (over the 3D view), above the sheet on a phone; on keyboard focus too ---------
  let observed = null;
  const sizes = typeof ResizeObserver === "function" ? new ResizeObserver(() => place()) : null;
  function panel() {
    const marker = document.querySelector("[data-tpmviz-keys]");
    const phone = matchMedia("(max-width: 36em)").matches;
    if (phone) return document.querySelector('.mantine-Paper-root[style*="position: fixed"]');
    return marker ? marker.closest("[data-dock-region]") : null;
  }
  function place() {
    const box = panel();
    if (sizes && box !== observed) {
      if (observed) sizes.unobserve(observed);
      if (box) sizes.observe(box);
      observed = box;
    }
    const root = document.documentElement, body = document.body;
    const r = box ? box.getBoundingClientRect() : null;
    let mode = "";
    if (r && r.width > 0 && matchMedia("(max-width: 36em)").matches) {
      mode = "above";
      root.style.setProperty("--tpmviz-tip-bottom", Math.max(GAP, root.clientHeight - r.top + GAP) + "px");
    } else if (r && r.width > 0 && r.left + r.width / 2 > root.clientWidth / 2) {
      mode = "left";
      root.style.setProperty("--tpmviz-tip-right", Math.max(0, root.clientWidth - r.left + GAP) + "px");
      root.style.setProperty("--tpmviz-tip-room", Math.max(96, r.left - 2 * GAP) + "px");
    } else if (r && r.width > 0) {
      mode = "right";
      root.style.setProperty("--tpmviz-tip-left", r.right + GAP + "px");
      root.style.setProperty("--tpmviz-tip-room", Math.max(96, root.clientWidth - r.right - 2 * GAP) + "px");
    }
    if ((body.getAttribute("data-tpmviz-tips") || "") !== mode) {
      if (mode) body.setAttribute("data-tpmviz-tips", mode); else body.removeAttribute("data-tpmviz-tips");
    }
  }
  function hover(ev, type) {  // viser's tooltip opens on mouseenter of the field's wrapper: a focused field's too
    const t = ev.target;
    if (!(t instanceof Element) || !t.matches('input, textarea, button, [role="slider"], [role="button"]')) return;
    let el = t;
    for (let i = 0; i < 8 && el && !el.matches("[data-dock-region], body"); i++, el = el.parentElement) {
      el.dispatchEvent(new MouseEvent(type, { bubbles: false, cancelable: false }));
    }
  }
  document.addEventListener("focusin", (ev) => { if (!window.__tpmvizPointer) hover(ev, "mouseenter"); }, true);
  document.addEventListener("focusout", (ev) => hover(ev, "mouseleave"), true);
  window.addEventListener("pointerdown", () => { window.__tpmvizPointer = true; }, true);
  window.addEventListener("keydown", () => { window.__tpmvizPointer = false; }, true);
  window.addEventListener("resize", () => place());
  function style() {
    const css = document.createElement("style");
    css.textContent = ":focus-visible { outline: 3px solid #0f766e !important; outline-offset: 2px !important; }\n" +
      ":root { --mantine-color-dimmed: #5c636a !important; --mantine-color-gray-filled: #5c636a !important; " +
      "--mantine-color-gray-filled-hover: #495057 !important; --mantine-color-custom-outline: #0f766e !important; }\n" +
      "body[data-tpmviz-tips] .mantine-Tooltip-arrow { display: none !important; }\n" +
      "body[data-tpmviz-tips=left] .mantine-Tooltip-tooltip { position: fixed !important; left: auto !important; " +
      "right: var(--tpmviz-tip-right) !important; max-width: var(--tpmviz-tip-room) !important; }\n" +
      "body[data-tpmviz-tips=right] .mantine-Tooltip-tooltip { position: fixed !important; " +
      "left: var(--tpmviz-tip-left) !important; max-width: var(--tpmviz-tip-room) !important; }\n" +
      "body[data-tpmviz-tips=above] .mantine-Tooltip-tooltip { position: fixed !important; top: auto !important; " +
      "bottom: var(--tpmviz-tip-bottom) !important; left: " + GAP + "px !important; right: " + GAP + "px !important; " +
      "width: auto !important; max-width: none !important; }\n" +
      "@media (max-width: 36em), (pointer: coarse) { " + NOTICE + " }";
    document.head.appendChild(css);
    const title = document.createElement("h1");
    title.textContent = "tpm-viz";
    title.style.cssText = HIDDEN;
    const banner = document.createElement("header");  // a landmark: all of the page is in one (axe's "region")
    banner.appendChild(title);
    document.body.prepend(banner);
  }

  let pending = false;
  function tick() {
    pending = false;
    announce();
    label();
    translate();
    place();
  }
  function start() {
    style();
    region();
    tick();
    new MutationObserver(() => {
      if (!pending) { pending = true; requestAnimationFrame(tick); setTimeout(tick, 250); }
    }).observe(document.body, { subtree: true, childList: true, characterData: true, attributes: true,
                                attributeFilter: ["data-level", "for", "aria-label", "title"] });
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start); else start();
})();
""".replace("__PATH__", KEY_PATH)
    .replace("__KEYS__", json.dumps(KEYS))
    .replace("__QUEUED__", str(QUEUED))
    .replace("__FOLD__", FOLD_KEY)
    .replace("__GAP__", str(TIP_GAP))
    .replace("__NOTICE__", json.dumps(NOTICE_CSS))
)
"""The page script (see the module docstring)."""

_TAG = f"<script>{SCRIPT}</script><script>{SEEN_SCRIPT}</script>".encode()  # what the page sees: viserkit/seen.py
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
