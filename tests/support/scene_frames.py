"""A browser tab on the app that keeps every websocket frame it is sent, and the 3D scene read back from them.

For the typed-number tests (``test_browser_typed_actuators.py``, ``test_browser_burst_typing.py``): the scene is
checked from an independent route, the binary frames the page received (decoded with
:func:`tests.support.protocol.decode_batch`), not the server's own state.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from tests.support.protocol import decode_batch, wait_for

__all__ = ["RecordedPage", "node_positions", "open_recorded"]


class RecordedPage(NamedTuple):
    """The page, the binary frames it received (in order), its uncaught errors and the server's view of the tab."""

    page: Any
    frames: list[bytes]
    errors: list[str]
    view: Any


def open_recorded(app: Any, browser: Any) -> RecordedPage:
    """A new page on ``app``, recording frames and page errors from the start, once its panel is up."""
    page = browser.new_page()
    frames: list[bytes] = []
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.on("websocket", lambda ws: ws.on("framereceived", lambda p: frames.append(p) if isinstance(p, bytes) else 0))
    page.goto(f"http://127.0.0.1:{app.port}/")
    page.wait_for_selector("[data-q=p1]", timeout=20_000)
    view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
    return RecordedPage(page, frames, errors, view)


def node_positions(page: Any, frames: list[bytes], name: str = "/tpm/slider1") -> list[tuple[float, ...]]:
    """Every position [m] of the broadcast scene node ``name`` in the frames the page received, in order.

    Playwright's sync API delivers the page's events only while one of its calls runs: a short wait lets the frames
    in first."""
    page.wait_for_timeout(20)
    out = []
    for raw in list(frames):
        for m in decode_batch(raw):
            if m.get("name") == name and m.get("owner") == "":
                position = m.get("position") or (m.get("props") or {}).get("position")
                if position is not None:
                    out.append(tuple(float(x) for x in position))
    return out
