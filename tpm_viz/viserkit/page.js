// tpm-viz's own script in viser's page: keys, a live region, labels and focus, the way back after a network drop
// (see tpm_viz/viserkit/page.py).
// Its settings come from the JSON element #tpmviz-page-config the server puts before it (page.py's CONFIG): data,
// never code. Checked by `node --check` and tests/viserkit/test_page_script.py.
(() => {
  "use strict";
  if (window.__tpmvizPage) return;
  const settings = document.getElementById("tpmviz-page-config");
  if (!settings) return;
  window.__tpmvizPage = true;
  const CONFIG = JSON.parse(settings.textContent);
  const PATH = CONFIG.path;
  const KEYS = new Set(CONFIG.keys);
  const QUEUED = CONFIG.queued;
  const HIDDEN = "position:absolute;width:1px;height:1px;margin:-1px;padding:0;overflow:hidden;" +
    "clip:rect(0 0 0 0);white-space:nowrap;border:0";
  const SKIP = 'input, textarea, select, [contenteditable=""], [contenteditable="true"], [role="slider"], ' +
    '[role="tablist"], [role="tab"], [role="combobox"], [role="listbox"], [role="menu"], [role="radiogroup"]';
  const FOLD = CONFIG.fold;
  const GAP = CONFIG.gap;
  const NOTICE = CONFIG.notice;
  const TYPING = 'input:not([type="checkbox"]):not([type="radio"]), textarea, select, [contenteditable=""], ' +
    '[contenteditable="true"], [role="combobox"]';

  // -- the way back after a network drop: viser's websocket retries replaced --------------------------------------
  // viser's page posts "retry" to its websocket worker every second while disconnected, and each retry closes the
  // attempt before it. Chromium counts an attempt closed before its handshake as a failed one and delays the next
  // by rand(1-5 s) * 2^min(pending + failed / (succeeded + 1), 16) / 65536 (its per-process WebSocket throttle,
  // remembered 2-4 minutes): after ~30 s of drop each attempt waits longer than a second and is closed before it
  // starts, so the page stays dead long after the network is back. Here viser's "retry" messages are dropped; while
  // disconnected the page asks RECONNECT.path (plain HTTP, not throttled) every RECONNECT.every ms, and at once on
  // `online`, on becoming visible and on the button, and tells the worker to connect once the server answers: no
  // websocket attempt fails while the network is down. A hidden page does not ask (it asks when shown again); one
  // without focus does (viser's own retries stop without focus). Nothing is reloaded.
  const RECONNECT = CONFIG.reconnect || null;
  let link = null;  // viser's websocket worker: { worker, post } (post: its postMessage, unfiltered)
  let down = false;  // disconnected: the worker said "closed" and not "connected" since
  let tried = 0;  // performance.now() of the connect asked and not answered yet (0: none)
  let probing = false;
  let timer = 0;
  let showing = 0;
  let button = null;

  function retry() {  // the worker closes any pending attempt and opens a new one
    if (!link || !down) return;
    tried = performance.now();
    link.post({ type: "retry" });
  }
  function probe() {  // ask the server; connect if it answers (any HTTP answer: it is reachable)
    clearTimeout(timer);
    timer = 0;
    if (!down || !link) return;
    timer = setTimeout(probe, RECONNECT.every);
    if (probing || (tried && performance.now() - tried < RECONNECT.stale)) return;
    if (document.visibilityState === "hidden") return;  // a hidden tab waits until it is shown (as viser's #367)
    probing = true;
    const stop = typeof AbortController === "function" ? new AbortController() : null;
    const limit = stop ? setTimeout(() => stop.abort(), RECONNECT.wait) : 0;
    fetch(RECONNECT.path, { cache: "no-store", credentials: "same-origin", signal: stop ? stop.signal : undefined })
      .then((answer) => { if (answer.body) answer.body.cancel().catch(() => {}); retry(); }, () => {})
      .finally(() => { clearTimeout(limit); probing = false; });
  }
  function language() {  // the browser's first language among the button's (as the server picks a new tab's)
    for (const tag of navigator.languages || [navigator.language || ""]) {
      const primary = String(tag).toLowerCase().split("-")[0];
      if (Object.prototype.hasOwnProperty.call(RECONNECT.words, primary)) return primary;
    }
    return "en";
  }
  function show(on) {
    if (!button) return;
    if (on) button.textContent = words("reconnect", RECONNECT.words[language()] || RECONNECT.words.en);
    if (button.hidden === !on) return;
    button.hidden = !on;
    document.body.toggleAttribute("data-tpmviz-offline", on);
  }
  function connected() {
    down = false;
    tried = 0;
    clearTimeout(timer);
    clearTimeout(showing);
    timer = showing = 0;
    show(false);
  }
  function closed() {
    down = true;
    tried = 0;
    if (!timer) probe();
    if (!showing && !(button && !button.hidden)) {
      showing = setTimeout(() => { showing = 0; if (down) show(true); }, RECONNECT.after);
    }
  }
  function now() {  // the network is back, or the page is looked at again: ask at once
    if (down) probe();
  }
  function watch(worker) {  // every worker viser makes; the websocket one is the one told "set_server"
    const post = worker.postMessage.bind(worker);
    worker.postMessage = (data, transfer) => {
      const type = data && data.type;
      if (type === "set_server") link = { worker, post };
      else if (type === "retry" && link && link.worker === worker) return undefined;  // viser's: ours instead
      else if (type === "close" && link && link.worker === worker) { link = null; connected(); }
      return transfer === undefined ? post(data) : post(data, transfer);
    };
    worker.addEventListener("message", (ev) => {
      if (!link || link.worker !== worker || !ev.data) return;
      if (ev.data.type === "connected") connected();
      else if (ev.data.type === "closed") closed();
    });
  }
  if (RECONNECT && typeof window.Worker === "function") {  // before viser's bundle runs (after DOMContentLoaded)
    const Base = window.Worker;
    window.Worker = class extends Base {
      constructor(url, options) {
        super(url, options);
        watch(this);
      }
    };
    window.addEventListener("online", now);
    document.addEventListener("visibilitychange", () => { if (document.visibilityState === "visible") now(); });
  }
  function reconnectButton(parent) {
    if (!RECONNECT) return;
    button = document.createElement("button");
    button.type = "button";
    button.id = "tpmviz-reconnect";
    button.hidden = true;
    button.addEventListener("click", () => { if (down) { retry(); probe(); } });
    parent.appendChild(button);
  }

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
  const heard = new Set();
  function announce() {
    for (const el of document.querySelectorAll("[data-say]")) {  // a result just in (an exercise's): said once
      const stamp = el.getAttribute("data-say");
      if (heard.has(stamp)) continue;
      heard.add(stamp);
      region().textContent = el.textContent.replace(/\s+/g, " ").trim();
    }
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
      "@media (max-width: 36em), (pointer: coarse) { " + NOTICE + " }\n" +
      "#tpmviz-reconnect { position: fixed; z-index: 10000; top: 48px; left: 50%; transform: translateX(-50%); " +
      "min-height: 44px; min-width: 44px; padding: 8px 20px; border: 0; border-radius: 22px; cursor: pointer; " +
      "font: 600 16px/1.25 system-ui, sans-serif; color: #fff; background: #0f766e; " +
      "box-shadow: 0 2px 10px rgba(0, 0, 0, 0.35); }\n" +
      "#tpmviz-reconnect:hover { background: #115e59; }\n#tpmviz-reconnect[hidden] { display: none; }";
    document.head.appendChild(css);
    const title = document.createElement("h1");
    title.textContent = "tpm-viz";
    title.style.cssText = HIDDEN;
    const banner = document.createElement("header");  // a landmark: all of the page is in one (axe's "region")
    banner.appendChild(title);
    reconnectButton(banner);
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
