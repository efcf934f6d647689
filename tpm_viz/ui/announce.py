"""What ``tpm-viz serve`` prints when it starts: the URL, the LTI tool's URLs (``--lti``) and, in classroom mode,
the students' URLs, a QR code and the presenter token (terminal only)."""

from __future__ import annotations

from typing import Any

from tpm_viz.classroom.network import is_loopback
from tpm_viz.ui.classroom import Classroom, qr_text, student_urls

__all__ = ["announce", "nobody", "serving"]


def serving(app: Any, host: str, room: Classroom | None) -> None:
    """The one line with the URL (and in classroom mode the students' URLs, QR code and token)."""
    shown = "127.0.0.1" if host in ("0.0.0.0", "::") else host
    print(f"tpm-viz serving at http://{shown}:{app.port}", flush=True)
    if getattr(app, "lti", None) is not None:
        store = app.room.store.store
        app.lti.start(f"http://{shown}:{app.port}/", None if store is None else store.path)
    if room is not None:
        announce(app, room, bound=host)


def nobody(host: str) -> bool:
    """No address presents by itself (``--lti``)."""
    return False


def announce(app: Any, room: Classroom, bound: str) -> None:
    """Classroom mode: the URLs students type, a QR code of the first, and the presenter token (terminal only)."""
    urls = student_urls("0.0.0.0", app.port, room.addresses())
    if not urls:
        print("No network address found: connect this computer to the room's network and restart.", flush=True)
    for url in urls:
        print(f"Students open: {url}", flush=True)
    if is_loopback(bound):
        print(f"(bound to {bound} only: students cannot connect; serve with --host 0.0.0.0)", flush=True)
    if urls:
        print(qr_text(urls[0]), end="", flush=True)
    if getattr(app, "lti", None) is not None:
        print(
            "Only an instructor's launch from the course (or --presenter-token) makes a tab the presenter.", flush=True
        )
        return
    print(
        "A tab opened on this computer is the presenter. To present from another device, log in there with", flush=True
    )
    print(f"the presenter token {room.token} (shown here only: keep it off the projector).", flush=True)
