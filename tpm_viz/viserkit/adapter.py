"""The one entry point: :func:`new_server` builds a viser server (the handshake hook on it), :func:`install` puts every
patch on that one server, in the order of :data:`PATCHES`, and :meth:`Installed.remove` takes them off again.

Each patch can be switched off alone (``install(server, skip={"frames"})``, ``new_server(handshake=None)``); what
each one is for, and the test that shows it, is in ``PATCHES.md``. Nothing here changes another viser server of the
same process: the patches that act through a class (:mod:`.patches`) are guarded by the registered server.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.classroom.guard import guard_executor, log_fault
from tpm_viz.viserkit import patches
from tpm_viz.viserkit.core import check_viser, disable_share_url, enable_share_url, thread_pool
from tpm_viz.viserkit.doors import ServerDoor
from tpm_viz.viserkit.limits import Limits, ServerGuard, harden_server
from tpm_viz.viserkit.wire import Handshake

__all__ = ["PATCHES", "Installed", "install", "installed_on", "new_server"]

PATCHES = ("share_url", "wakeups", "senders", "serialization", "casts", "callbacks", "limits", "frames", "decoding")
"""The patches :func:`install` puts on a server, in this order (names for ``skip``). Besides them: ``handshakes``
(:func:`new_server`'s ``handshake``), ``transport`` (each tab's filters, :func:`~.transport.harden`, a no-op when
skipped) and ``gizmo_echo`` (:func:`~.core.drop_gizmo_echo`, a no-op when skipped)."""
SKIPPABLE = frozenset(PATCHES) | {"transport", "gizmo_echo"}
_ATTR = "tpm_viz_installed"


def new_server(*, handshake: Handshake | None = None, **kwargs: Any) -> viser.ViserServer:
    """``viser.ViserServer(**kwargs)`` (quiet: viser prints its banner even with ``verbose=False``), after
    :func:`~.core.check_viser`. ``handshake``: every HTTP request and websocket handshake of this server goes through
    it first (:data:`~.wire.Handshake`; None: viser's own handling, the ``handshakes`` patch skipped)."""
    check_viser()
    server = viser.ViserServer.__new__(viser.ViserServer)
    hooked = contextlib.nullcontext() if handshake is None else patches.building(server, handshake)
    with contextlib.redirect_stdout(io.StringIO()), hooked:
        server.__init__(**kwargs)
    return server


@dataclasses.dataclass(eq=False)
class Installed:
    """The patches on one server (:func:`install`)."""

    server: viser.ViserServer
    skip: frozenset[str]
    guard: ServerGuard | None
    """The limits (None if ``limits`` is skipped)."""
    _undo: list[Callable[[], None]] = dataclasses.field(default_factory=list)

    def has(self, name: str) -> bool:
        """Whether the patch ``name`` is on."""
        return name not in self.skip

    def remove(self) -> None:
        """Take every patch off this server, in reverse order (connections already open keep what they had; the
        class-level guards are gone once no tpm-viz server is installed)."""
        while self._undo:
            self._undo.pop()()
        if getattr(self.server, _ATTR, None) is self:
            delattr(self.server, _ATTR)


def install(server: viser.ViserServer, *, skip: frozenset[str] | set[str] = frozenset()) -> Installed:
    """Put the patches of :data:`PATCHES` on ``server`` (started, no tab connected yet), in that order, except
    those named in ``skip``. -> :class:`Installed` (also kept on the server: :func:`installed_on`). Raises
    ValueError for an unknown name, RuntimeError if ``server`` already has them."""
    skip = frozenset(skip)
    if unknown := skip - SKIPPABLE:
        raise ValueError(f"unknown patches {sorted(unknown)}; known: {sorted(SKIPPABLE)}")
    if installed_on(server) is not None:
        raise RuntimeError("this viser server already has tpm-viz's patches")
    door = ServerDoor(server)
    loop = door.loop
    if loop is None:
        raise RuntimeError("the viser server has no event loop yet")
    done = Installed(server, skip, None)
    on = done.has
    if on("share_url"):  # per instance
        disable_share_url(server)
        done._undo.append(lambda: enable_share_url(server))
    encode = patches.lean_encoder(on("serialization")) if on("senders") or on("serialization") else None

    def upgrade(buffer: Any) -> None:
        patches.upgrade_buffer(buffer, on("wakeups"), on("senders"), encode)

    upgrade(door.shared_buffer())  # every later tab's own buffer as it connects, before its sender starts
    done._undo.append(door.on_new_buffer(upgrade))
    done._undo.append(lambda: patches.downgrade_buffer(door.shared_buffer()))
    if on("callbacks"):  # per instance: every callback's exception is logged (classroom/guard.py)
        pool = thread_pool(server)
        guard_executor(pool)
        done._undo.append(lambda: pool.__dict__.pop("submit", None))
    if on("limits"):  # per instance (viserkit/limits.py)
        done.guard = harden_server(server, Limits())
        done._undo.append(_forget_guard(server, done.guard))
    loop_patches = patches.LoopPatches(
        max_frame_bytes=Limits().max_frame_bytes if on("frames") else None,
        on_garbage=(lambda text: log_fault("server", "garbage", text)) if on("decoding") else None,
    )
    if done.guard is not None and loop_patches.max_frame_bytes is not None:
        loop_patches.max_frame_bytes = done.guard.limits.max_frame_bytes
    patches.register(server, loop, loop_patches, skip)  # guarded class-level: frames, decoding, producer, hints, casts
    done._undo.append(lambda: patches.unregister(server, loop))
    setattr(server, _ATTR, done)
    return done


def _forget_guard(server: viser.ViserServer, guard: ServerGuard) -> Callable[[], None]:
    def forget() -> None:
        guard.remove()
        with contextlib.suppress(AttributeError):
            delattr(server, "tpm_viz_limits")

    return forget


def installed_on(server: viser.ViserServer) -> Installed | None:
    """The patches :func:`install` put on ``server``, if any."""
    found = getattr(server, _ATTR, None)
    return found if isinstance(found, Installed) else None
