// What the page sees and viser does not tell the server (tpm_viz/viserkit/seen.py): a coarse pointer and the open
// tabs, told with the tab's key nonce. Its settings come from the page script's JSON element (`seen`).
(() => {
  "use strict";
  if (window.__tpmvizSeen) return;
  window.__tpmvizSeen = true;
  const SEEN = JSON.parse(document.getElementById("tpmviz-page-config").textContent).seen;
  const PATH = SEEN.path;
  let told = null;  // the nonce the pointer and the open tabs were told for (a reconnected tab has a new one)
  let open = null;
  let count = 0;
  function nonce() {
    const el = document.querySelector("[data-tpmviz-keys]");
    return el ? el.getAttribute("data-tpmviz-keys") : null;
  }
  function tell(n, what) {
    count = (count + 1) % 1e9;
    fetch(PATH + "?n=" + encodeURIComponent(n) + "&w=" + encodeURIComponent(what) + "&c=" + count,
          { cache: "no-store", credentials: "same-origin" }).catch(() => {});
  }
  function check() {
    const n = nonce();
    if (!n) return;
    if (n !== told) {
      told = n;
      open = null;
      if (matchMedia("(pointer: coarse)").matches) tell(n, "touch");
    }
    const now = [...new Set([...document.querySelectorAll("[data-tpmviz-tab]")]
      .filter((el) => el.getClientRects().length).map((el) => el.getAttribute("data-tpmviz-tab")))].sort().join(",");
    if (now !== open) { open = now; tell(n, "tabs:" + now); }
  }
  // A tab the server asks the page to show (a hidden [data-tpmviz-show] element: a stamp, and the labels of the tabs
  // to open, outermost first): one Enter on a tab per look, each tab once it is drawn, for at most SHOW_LOOKS looks.
  const shown = new Map();
  function reveal() {
    const el = document.querySelector("[data-tpmviz-show]");
    if (!el) return;
    const stamp = el.getAttribute("data-tpmviz-show");
    const looks = shown.get(stamp) || 0;
    if (looks < 0 || looks >= SHOW_LOOKS) return;
    shown.set(stamp, looks + 1);
    let path = [];
    try { path = JSON.parse(el.getAttribute("data-path") || "[]"); } catch (e) { path = []; }
    for (const name of Array.isArray(path) ? path : []) {
      const tab = [...document.querySelectorAll('[role="tab"]')].find((t) => t.getAttribute("title") === name);
      if (!tab) return;  // not drawn yet: the next look
      if (tab.getAttribute("aria-selected") !== "true") {  // viser's dock tabs open on a press, or on Enter
        tab.dispatchEvent(new KeyboardEvent("keydown", { key: "Enter", code: "Enter", bubbles: true, cancelable: true }));
        return;
      }
    }
    shown.set(stamp, -1);  // every tab of the path open: done
  }
  const SHOW_LOOKS = 120;
  setInterval(reveal, 250);
  document.addEventListener("click", (ev) => {
    const t = ev.target;
    if (t && t.closest && t.closest('[role="tab"]')) { setTimeout(check, 50); setTimeout(check, 300); }
  }, true);
  setInterval(check, SEEN.every);
})();
