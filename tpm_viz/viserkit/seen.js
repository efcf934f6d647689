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
  document.addEventListener("click", (ev) => {
    const t = ev.target;
    if (t && t.closest && t.closest('[role="tab"]')) { setTimeout(check, 50); setTimeout(check, 300); }
  }, true);
  setInterval(check, SEEN.every);
})();
