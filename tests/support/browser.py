"""Headless Chromium for the browser tests and benchmarks: Debian's binary, the flags this machine needs, and
an init script that logs viser's websocket messages in the page."""

import contextlib
import os
from collections.abc import Iterator
from typing import Any

import pytest

from tpm_viz.viserkit.probe import widget_uuid

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@contextlib.contextmanager
def launched_chromium() -> Iterator[Any]:
    """A headless Chromium (each ``new_context()`` a fresh browser with no cookies); the test is skipped when Chromium
    or playwright is not installed."""
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            yield browser
        finally:
            browser.close()


WORKER_LOG_JS = """
(() => {
  // Wrap the websocket Web Worker: log every decoded incoming message and every outgoing one, with
  // performance.now() timestamps (ms), in window.__viserLog.
  const Orig = window.Worker;
  const log = (window.__viserLog = []);
  function Wrapped(url, opts) {
    const w = new Orig(url, opts);
    const post = w.postMessage.bind(w);
    w.postMessage = (data, transfer) => {
      if (data && data.type === "send" && data.message) {
        log.push({ dir: "out", t: performance.now(), type: data.message.type, uuid: data.message.uuid,
                   name: data.message.name });
      }
      return post(data, transfer);
    };
    w.addEventListener("message", (ev) => {
      const d = ev.data;
      if (d && d.type === "message_batch") {
        const t = performance.now();
        for (const m of d.messages) log.push({ dir: "in", t, type: m.type, uuid: m.uuid, name: m.name });
      }
    });
    return w;
  }
  Wrapped.prototype = Orig.prototype;
  window.Worker = Wrapped;
})();
"""
"""Init script for a page: a timestamped log of viser's websocket messages in ``window.__viserLog``."""


def text_input(page, handle):
    """The ``<input>`` of a viser text field (``add_text``; the ``<textarea>`` of a multi-line one, e.g. a typed number
    of ``tpm_viz.ui.fields``): it has no id of its own, so it is found by its label's ``for`` (the handle's uuid)."""
    return page.locator(f'div:has(> div > p > label[for="{widget_uuid(handle)}"]) :is(input, textarea)')
