"""tpm-viz's own script in viser's page: keys, a live region, labels and focus (viser's public API has none).

viser's page is one HTML file (its client bundle inlined). :func:`with_script` adds :data:`SCRIPT` (the file
``page.js`` beside this module, JavaScript checked by ``node --check``) before its ``</body>``, after its settings
:data:`CONFIG` (the key path, the keys, ...: JSON data in an element of its own, :func:`page_tag`, never code written
into the script). The gzipped variant is unpacked, edited and packed once per page body, then cached. The script:

- sends the keys of :data:`KEYS` (when focus is not in a text field, a slider, a list or a tab strip; no Ctrl, Alt or
  Meta) to :data:`KEY_PATH` with the tab's nonce, one request at a time (at most :data:`QUEUED` keys waiting, more are
  dropped): the nonce is the ``data-tpmviz-keys`` attribute of a hidden element the server put in this tab's panel
  (:mod:`tpm_viz.ui.keyboard`), so a key moves this tab's mechanism only, and a page that does not know it can do
  nothing;
- keeps one ``aria-live="polite"`` region (``#tpmviz-live``) with the text of the pose banner (``[data-q=banner]``),
  written only when the banner's words change (its numbers masked: a warning whose cos θ moves by 0.001 is not
  announced again; a new warning, or back to a regular pose, is), and with the text of an element that carries a new
  ``data-say`` stamp (an exercise's result, once per submission);
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
- keeps viser's software-WebGL notice to a one-line strip on a phone (:data:`NOTICE_CSS`);
- brings the tab back promptly after a network drop (:data:`RECONNECT`): it takes over viser's websocket retries
  (viser's page closes its pending attempt and opens a new one every second, and Chromium, which counts each such
  attempt as a failed one and delays the next by up to 1-5 s once there are about 16 failures per success, ends up
  closing every attempt before it starts: after a 30 s drop the page stayed dead for minutes). While the tab is
  disconnected the script asks :data:`ALIVE_PATH` (a plain HTTP request, not throttled) every
  :data:`RECONNECT_EVERY_MS` (a hidden page waits until it is shown; one without focus asks too), at once on the
  browser's ``online`` event and when the page becomes visible again, and tells viser's worker to connect only once
  the server answers; meanwhile it shows a *Reconnect now* button (``#tpmviz-reconnect``, in the tab's language: the
  words the server put in the tab's hidden element, else the browser's first language among :data:`RECONNECT`'s)
  that connects at once. No page reload: nothing typed is lost by it.

A second, separate script goes in with it: :data:`~tpm_viz.viserkit.seen.SEEN_SCRIPT` (a coarse pointer, the tab
of the panel that is open).

The wire format of a key (:func:`key_request`) is in :mod:`.keys` (re-exported here).
"""

from __future__ import annotations

import gzip
import json
import threading
from importlib import resources
from typing import Any

from tpm_viz.core.words import Lang, T, say
from tpm_viz.viserkit.keys import KEY_PATH, KEYS, QUEUED, KeyRequest, key_request
from tpm_viz.viserkit.seen import SEEN_SCRIPT
from tpm_viz.viserkit.seen import SETTINGS as SEEN_SETTINGS

__all__ = [
    "ALIVE_PATH",
    "CONFIG",
    "FOLD_KEY",
    "KEYS",
    "KEY_PATH",
    "NOTICE_CSS",
    "QUEUED",
    "RECONNECT",
    "RECONNECT_NOW",
    "SCRIPT",
    "KeyRequest",
    "config_json",
    "key_request",
    "page_tag",
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

ALIVE_PATH = "/tpm-viz/alive"
"""What a disconnected page asks to learn that the server is reachable again (the handshake hook answers it, 200)."""
RECONNECT_EVERY_MS = 2000
"""How often a disconnected page asks :data:`ALIVE_PATH` [ms] (the issue asked for at most 2-3 s apart)."""
RECONNECT_WAIT_MS = 1800
"""How long one such request may take before it is given up [ms] (a black-holed network never answers)."""
RECONNECT_STALE_MS = 6500
"""How long a websocket attempt may stay unanswered before the page asks again [ms] (viser's worker closes an
attempt that has not opened after 5 s, and says so)."""
RECONNECT_AFTER_MS = 1000
"""How long a tab is disconnected before its *Reconnect now* button shows [ms] (no flash on a brief blip)."""
RECONNECT_NOW = T("Reconnect now")
"""The button's words (the tab's hidden element carries them in the tab's language, :mod:`tpm_viz.ui.keyboard`)."""

RECONNECT: dict[str, Any] = {
    "path": ALIVE_PATH,
    "every": RECONNECT_EVERY_MS,
    "wait": RECONNECT_WAIT_MS,
    "stale": RECONNECT_STALE_MS,
    "after": RECONNECT_AFTER_MS,
    "words": {lang.value: say(lang, RECONNECT_NOW) for lang in Lang},
}
"""The page's way back after a drop (``CONFIG["reconnect"]``; ``None`` there leaves viser's own retries alone). The
button's words in every language: the script uses them when the tab's hidden element is not there (a tab that never
connected), in the browser's first language among them (as the server picks a new tab's language)."""

CONFIG: dict[str, Any] = {
    "path": KEY_PATH,
    "keys": list(KEYS),
    "queued": QUEUED,
    "fold": FOLD_KEY,
    "gap": TIP_GAP,
    "notice": NOTICE_CSS,
    "reconnect": RECONNECT,
    "seen": SEEN_SETTINGS,
}
"""What the script is told (``page.js`` reads it as ``CONFIG``): its one input from Python, sent as JSON data in its
own element, never written into the script's code."""

SCRIPT = resources.files("tpm_viz.viserkit").joinpath("page.js").read_text(encoding="utf-8")
"""The page script (``page.js`` beside this module, read once at import; see the module docstring)."""


def config_json(config: dict[str, Any]) -> str:
    """``config`` as JSON that can stand inside an HTML ``<script>`` element: ``<``, ``>`` and ``&`` escaped as
    ``\\u003c``, ``\\u003e``, ``\\u0026`` (the same string to ``JSON.parse``), so no value can end the element or
    open a comment."""
    text = json.dumps(config, ensure_ascii=True, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def page_tag(config: dict[str, Any] = CONFIG, script: str = SCRIPT) -> bytes:
    """What :func:`with_script` puts before ``</body>``: the settings (``<script type="application/json"
    id="tpmviz-page-config">``), then the script. Raises ValueError if the script could end its own element."""
    if "</script" in script.lower():
        raise ValueError("the page script contains '</script'")
    data = f'<script type="application/json" id="tpmviz-page-config">{config_json(config)}</script>'
    return f"{data}<script>{script}</script><script>{SEEN_SCRIPT}</script>".encode()  # seen.js: viserkit/seen.py


_TAG = page_tag()
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
