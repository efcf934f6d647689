"""Stand-ins for viser's scene and GUI APIs that check every value the app writes (no server, no browser).

:class:`FakeApi` answers any ``add_*`` call with a :class:`Node`; a node accepts any attribute, is a context
manager (folders, tabs) and records callbacks. Every assignment to a node (``handle.position = ...``,
``handle.value = ...``, ``handle.content = ...``) goes through :func:`assert_clean`: numbers must be finite and
text must not show ``nan`` or ``inf``. So :class:`~tpm_viz.ui.scene.MechanismScene` and
:class:`~tpm_viz.ui.panels.Panel` run their real code and any non-finite value they would send to a browser
fails the test at the line that writes it.
"""

from __future__ import annotations

import re

import numpy as np

_BAD_TEXT = re.compile(r"\bnan\b|\binf\b|infinity", re.IGNORECASE)


def assert_clean(where: str, value) -> None:
    """Fail if ``value`` holds a non-finite number or text that shows one."""
    if isinstance(value, str):
        assert not _BAD_TEXT.search(value), f"{where}: non-finite number in text: {value[:200]!r}"
        return
    if isinstance(value, (bool, type(None))):
        return
    if isinstance(value, (int, float, np.floating, np.integer)):
        assert np.isfinite(value), f"{where} = {value!r}"
        return
    if isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        assert np.all(np.isfinite(value)), f"{where}: non-finite array {value!r}"
        return
    if isinstance(value, (tuple, list)):
        for item in value:
            assert_clean(where, item)


class Node:
    """One fake handle: any attribute, checked on assignment."""

    def __init__(self, kind: str, args: tuple, kwargs: dict) -> None:
        object.__setattr__(self, "kind", kind)
        object.__setattr__(self, "callbacks", [])
        object.__setattr__(self, "writes", 0)
        for i, arg in enumerate(args):
            assert_clean(f"{kind} argument {i}", arg)
        for key, arg in kwargs.items():
            assert_clean(f"{kind}({key}=)", arg)
        self.__dict__.update(kwargs)
        self.__dict__.update(zip(_POSITIONAL.get(kind, ()), args, strict=False))
        initial = kwargs.get("initial_value", _initial(kind, args))
        object.__setattr__(self, "value", initial)
        if kind in ("add_markdown", "add_html"):
            object.__setattr__(self, "content", args[0] if args else kwargs.get("content", ""))

    def __setattr__(self, name: str, value) -> None:
        assert_clean(f"{self.kind}.{name}", value)
        object.__setattr__(self, "writes", self.writes + 1)
        object.__setattr__(self, name, value)

    def __getattr__(self, name: str):  # unknown attributes: a sub-node (e.g. tabs.add_tab)
        if name.startswith("add_"):
            return lambda *a, **k: Node(name, a, k)
        raise AttributeError(name)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None

    def on_update(self, cb):
        self.callbacks.append(cb)
        return cb

    on_click = on_update

    def remove(self) -> None:
        pass


def _initial(kind: str, args: tuple):
    if kind == "add_slider" and len(args) >= 5:
        return args[4]
    if len(args) >= 2:
        return args[1]
    return None


_POSITIONAL = {"add_slider": ("label", "min", "max", "step", "initial_value")}


class FakeApi:
    """A scene or GUI API: ``add_*`` returns a checked :class:`Node`; everything it made is in ``nodes``."""

    def __init__(self) -> None:
        self.nodes: list[Node] = []

    def __getattr__(self, name: str):
        if name.startswith("add_") or name.startswith("configure_"):

            def add(*args, **kwargs):
                node = Node(name, args, kwargs)
                self.nodes.append(node)
                return node

            return add
        raise AttributeError(name)


class FakeView:
    """A browser tab without a browser: the real scene and panel code on fake APIs, drawn like ClientView."""

    def __init__(self, state) -> None:
        from types import SimpleNamespace

        from tpm_viz.ui.panels import Panel
        from tpm_viz.ui.scene import MechanismScene
        from tpm_viz.ui.tabscene import TabScene

        self.scene_api, self.gui_api = FakeApi(), FakeApi()
        self.mechanism = MechanismScene(self.scene_api, state.params)
        self.scene = TabScene(SimpleNamespace(scene=self.scene_api), self.mechanism)
        self.panel = Panel(self.gui_api, state)
        self.frames = 0
        self.failures: list[BaseException] = []

    def render(self, frame, *, dragging: bool) -> None:
        try:
            self.mechanism.update(frame)
            self.scene.update(frame, dragging=dragging)
            self.panel.show(frame)
        except BaseException as exc:  # the hub logs and swallows it: keep it for the test to raise
            self.failures.append(exc)
            raise
        self.frames += 1
