"""A tab builds its *Player*, *Equations* and *Lab* tabs a moment after the rest (ui/teaching/tabs.py: a class that
reconnects at once gets its mechanisms back first). Checked from what the browser receives: once built, the tab is
the one an eager build gives (same tabs in the same order, same labels, values and texts); a returning own copy
arrives with its copy ticked and drawn before them; whoever asks for a deferred view gets it built."""

from __future__ import annotations

import gc
import re
import threading
import weakref

from tests.support.fixtures import open_tab
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.classroom.later import Later
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.ui.teaching.tabs import LATER

_ID = re.compile(r"[0-9a-f]{8}-?[0-9a-f]{4}-?[0-9a-f]{4}-?[0-9a-f]{4}-?[0-9a-f]{12}|data-tpmviz-keys=[^>]*")
_OWN_NUMBERS = re.compile(r"(?s)(data-q=\"exercise-prompt\".*)")
"""An exercise's prompt: each student's own numbers (a tab without a browser's cookie is a student of its own)."""


class GuiClient(ProtocolClient):
    """A tab that keeps the GUI elements it was sent: uuid -> (type, container, props, value)."""

    def __init__(self, port: int) -> None:
        self.gui: dict[str, dict] = {}
        self._lock = threading.Lock()
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        with self._lock:
            if m["type"] == "GuiRemoveMessage":
                self.gui.pop(m["uuid"], None)
            elif m["type"] == "GuiUpdateMessage" and m["uuid"] in self.gui:
                element = self.gui[m["uuid"]]
                for name, value in m["updates"].items():
                    if name == "value":
                        element["value"] = value
                    else:
                        element["props"][name] = value
            elif m["type"].startswith("Gui") and isinstance(m.get("props"), dict) and "container_uuid" in m:
                self.gui[m["uuid"]] = {
                    "type": m["type"],
                    "container": m["container_uuid"],
                    "props": dict(m["props"]),
                    "value": m.get("value"),
                }

    def tree(self) -> list[tuple]:
        """Every element as ``(path of tabs and folders, type, label, value, text)`` in the order the page shows
        them (ids and the keyboard's nonce left out: they are each tab's own)."""
        with self._lock:
            gui = {k: {**v, "props": dict(v["props"])} for k, v in self.gui.items()}
        parents: dict[str, tuple[str, str]] = {}  # container id -> (its parent container, its label)
        for uuid, e in gui.items():
            props = e["props"]
            for tab_id, label in zip(props.get("_tab_container_ids", ()), props.get("_tab_labels", ()), strict=False):
                parents[tab_id] = (e["container"], label)
            parents.setdefault(uuid, (e["container"], f"{e['type']} {props.get('label', '')}"))  # a folder, a form

        def path(container: str) -> tuple[str, ...]:
            out: list[str] = []
            for _ in range(20):
                if container not in parents:
                    break
                container, label = parents[container]
                out.append(label)
            return tuple(reversed(out))

        def text(props: dict) -> str:
            content = _ID.sub("<id>", str(props.get("content", props.get("_markdown", ""))))
            return _OWN_NUMBERS.sub(lambda m: re.sub(r"[-−+]?\d[\d.,]*", "#", m.group(1)), content)

        rows = [
            (
                path(e["container"]),
                float(e["props"].get("order", 0.0)),
                e["type"],
                str(e["props"].get("label", "")),
                repr(e["value"]),
                text(e["props"]),
                tuple(e["props"].get("_tab_labels", ())),
            )
            for e in gui.values()
        ]
        rows.sort(key=lambda r: (r[0], r[1]))
        return [(p, kind, label, value, content, tabs) for p, _order, kind, label, value, content, tabs in rows]


def _open(app, opened: list[GuiClient]):
    before = set(app.views)
    client = GuiClient(app.port)
    opened.append(client)
    new = wait_for(lambda: set(app.views) - before, what="the tab's view")
    view = app.views[next(iter(new))]
    wait_for(lambda: view in app.arrived, what="the tab connected")
    return client, view


def _quiet(app, views) -> None:
    later = app.services.later
    wait_for(
        lambda: (later is None or later.pending() == 0) and not any(v.teaching.waiting for v in views), what="built"
    )
    wait_for(lambda: app.services.worker.idle(), timeout=60, what="the plans of the Planner tabs")


def test_a_deferred_tab_once_opened_is_the_tab_an_eager_build_gives(app):
    opened: list[GuiClient] = []
    later = app.services.later
    try:
        app.services.later = Later(quiet=3600.0)  # nothing is built behind the test's back
        lazy_client, lazy = _open(app, opened)
        assert lazy.teaching.waiting == set(LATER)
        labels = {row[2] for row in lazy_client.tree()}
        assert {"Trajectory", "Controller"}.isdisjoint(labels)  # the Player and Control tabs wait
        app.services.later = None  # the next tab is built whole, as before the deferral
        eager_client, eager = _open(app, opened)
        assert not eager.teaching.waiting
        assert eager.panel.equations is not None
        for group in LATER:
            assert lazy.teaching.open(group)
            assert not lazy.teaching.open(group)  # once
        _quiet(app, (lazy, eager))
        # Both tabs' classroom lines are redrawn by a timer (a tab arrived): the trees are compared as they stand at
        # one moment, until they agree, and what follows reads that moment's tree (a second reading may fall between
        # the timer's writes to the two tabs).
        lazy_tree = wait_for(
            lambda: (tree := lazy_client.tree()) == eager_client.tree() and tree, timeout=30, what="the same tab"
        )
        paths = {p for p, *_ in lazy_tree}
        assert {("Teach", "Player"), ("Teach", "Equations"), ("Lab", "Control"), ("Lab", "Planner")} <= paths
        groups = {tabs for *_, tabs in lazy_tree if tabs}
        assert ("Demos", "Player", "Exercises", "Equations") in groups and ("Control", "Planner", "Design") in groups
    finally:
        app.services.later = later
        for client in opened:
            client.close()


def test_the_deferred_tabs_build_themselves_and_a_view_asked_for_is_built_at_once(app):
    opened: list[GuiClient] = []
    try:
        client, view = _open(app, opened)  # the app's own Later: built once no tab arrived for a moment
        _quiet(app, (view,))
        wait_for(lambda: {"Trajectory", "Controller"} <= {row[2] for row in client.tree()}, what="the Player and Lab")
        later = app.services.later
        app.services.later = Later(quiet=3600.0)
        try:
            _second, other = _open(app, opened)
            assert other.teaching.waiting == set(LATER)
            assert other.panel.equations.content  # asked for: the Teach tabs built now, with the numbers
            assert other.teaching.waiting == {"lab"}
            assert other.teaching.control.charts  # and the Lab tabs
            assert not other.teaching.waiting
        finally:
            app.services.later = later
    finally:
        for client in opened:
            client.close()


def test_a_returning_own_copy_comes_with_its_copy_before_its_deferred_tabs(app, monkeypatch):
    """A returning tab gets its own copy, ticked and drawn (what bench_reconnect.py times), without waiting for the
    deferred tabs; they follow, built for the copy's mechanism (its numbers, not the shared mechanism's)."""
    opened: list[GuiClient] = []
    state = app.hub.shared.state.replace(params=app.hub.shared.state.params.replace(l_a=0.28))
    monkeypatch.setattr(app.room, "build", lambda who, make: make(Saved(state)))  # as Room.build for a known cookie
    later = app.services.later
    try:
        app.services.later = Later(quiet=3600.0)
        client, view = _open(app, opened)
        assert not view.session.shared and view.session.state.params.l_a == 0.28
        ticked = lambda: [row[3] for row in client.tree() if row[2] == "Work on my own copy"] == ["True"]  # noqa: E731
        wait_for(ticked, what="the box ticked (made unticked, ticked in the same batch)")
        tree = client.tree()
        wait_for(lambda: any(name.startswith("/own/platform") for name, _owner in list(client.nodes)), what="the copy")
        assert "Trajectory" not in {row[2] for row in tree}
        app.services.later = later
        for group in LATER:
            view.teaching.open(group)
        _quiet(app, (view,))
        shown = view.panel.equations.content  # the copy's numbers, not the shared mechanism's
        shared = app.hub.frame(app.hub.shared.state).equations_in(view.lang)
        assert shown == app.hub.frame(state).equations_in(view.lang) != shared
    finally:
        app.services.later = later
        for client in opened:
            client.close()


def test_a_closed_tab_is_freed_by_the_app_without_the_collectors_schedule(app):
    client, view = open_tab(app, [])
    gone = weakref.ref(view)
    del view
    later = app.services.later
    wait_for(lambda: later.pending() == 0, what="the tab's deferred tabs")
    gc.disable()
    try:
        count = len(app.views)
        client.close()
        wait_for(lambda: len(app.views) < count, what="the app to drop the closed tab")
        wait_for(lambda: gone() is None, what="the closed tab's view to be collected")
    finally:
        gc.enable()
