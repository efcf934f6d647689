"""A phone's tab through a long network drop (issue 40, item 2): seconds from the network's return to the tab live
again, with the page script's way back (``after``) and with viser's own retrying (``before``: the page script's
``reconnect`` setting off, ``{"reconnect": None}``, everything else the same).

Each run: the app in this process, a TCP proxy in front of it (:class:`tests.support.proxy.TcpProxy`), a fresh
headless Chromium (Chromium's WebSocket throttle remembers a renderer's failed attempts for 2-4 minutes: a browser
per run, so no run inherits another's) as a 390×844 touch phone, one tab; the network drops for ``--seconds`` (every
connection refused, or with ``--black-hole`` accepted and never answered) and comes back; the tab is live again when
the app has built its view again (its inputs reach the app). Printed per run: the time to live (or that it was not
live within ``--bound`` s), the websocket attempts the page made while the network was down, the gaps between
connection attempts at the proxy during the drop, the last attempt before the return, and the *Reconnect now*
button's text. The test (``tests/e2e/test_browser_reconnect.py``) runs the same measurement
(:func:`tests.support.drops.through_a_drop`) for a 30 s refused drop, after only.

Run: ``python benchmarks/bench_drop.py`` (``--seconds 60``, both modes, before and after; ``--seconds 10 20 30 60
--modes refused --variants before`` shows viser's backoff growing with the drop). Bounded: each run waits at most
``--bound`` s after the return; the app and the proxy stop at the end of each run.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from tests.support.browser import launched_chromium
from tests.support.drops import RETRY_LOG_JS, new_view, serve_settings, through_a_drop
from tests.support.protocol import wait_for
from tests.support.proxy import TcpProxy
from tpm_viz.ui.app import TpmApp, build_server

PHONE = {"viewport": {"width": 390, "height": 844}, "has_touch": True, "is_mobile": True, "locale": "en-US"}
VARIANTS = {"before": {"reconnect": None}, "after": None}
"""The page script's settings per variant (None: as the app serves them)."""


def _once(seconds: float, black_hole: bool, variant: str, bound: float) -> str:
    app = TpmApp(build_server("127.0.0.1", 0))
    proxy = TcpProxy(app.port)
    try:
        with launched_chromium() as browser:
            context = browser.new_context(**PHONE)
            page = context.new_page()
            page.add_init_script(RETRY_LOG_JS)
            if VARIANTS[variant] is not None:
                serve_settings(page, VARIANTS[variant])
            page.goto(f"http://127.0.0.1:{proxy.port}/")
            view = wait_for(lambda: new_view(app, None), timeout=60, what="the tab's view")
            wait_for(lambda: view.session.readout is not None, timeout=60, what="the first render")
            time.sleep(1.0)  # the page settled (its first batches applied)
            comeback = through_a_drop(app, page, proxy, seconds, black_hole, bound)
            context.close()
    finally:
        proxy.close()
        app.stop()
    during = [t for t in comeback.arrivals if t < seconds]
    gaps = [b - a for a, b in itertools.pairwise(during)]
    live = "not live" if comeback.live_after is None else f"live {comeback.live_after:5.2f} s"
    gap = f"{min(gaps):.1f}-{max(gaps):.1f} s" if gaps else "-"
    last = f"{during[-1]:.1f} s" if during else "-"
    button = "none" if comeback.button is None else repr(comeback.button)
    mode = "black-holed" if black_hole else "refused"
    return (
        f"{variant:6} {mode:11} {seconds:4.0f} s drop: {live} after the return (bound {bound:.0f} s); "
        f"{comeback.retries} websocket attempts while down; {len(during)} connections at the proxy during the drop, "
        f"{gap} apart, the last {last} into it; button {button}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, nargs="+", default=[60.0], help="drop lengths [s]")
    parser.add_argument("--modes", nargs="+", choices=("refused", "black-holed"), default=["refused", "black-holed"])
    parser.add_argument("--variants", nargs="+", choices=tuple(VARIANTS), default=["before", "after"])
    parser.add_argument("--bound", type=float, default=120.0, help="seconds to wait after the return at most")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each case")
    args = parser.parse_args()
    print("A phone's tab through a network drop: time from the network's return to the tab live again", flush=True)
    for seconds in args.seconds:
        for mode in args.modes:
            for variant in args.variants:
                for _ in range(args.repeat):
                    print(_once(seconds, mode == "black-holed", variant, args.bound), flush=True)


if __name__ == "__main__":
    main()
