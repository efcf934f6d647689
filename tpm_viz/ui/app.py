"""The browser app: a viser server on 127.0.0.1, one :class:`ClientView` per tab, one shared mechanism.

``main(host, port)`` is what ``python app.py`` and ``tpm-viz serve`` call. It prints exactly one line with the
URL the server really got (viser moves to the next port when one is busy) and serves until Ctrl-C.

Safety: the default host is loopback. viser's share-URL tunnel (an outside relay that a client can request even
with the button hidden) is disabled by replacing ``server.request_share_url`` with a no-op.
"""

from __future__ import annotations

import contextlib
import io
import ipaddress
import sys
import threading
import time

import viser

from ..params import Params
from ..readouts import Reference
from .client import ClientView
from .scene import camera_pose
from .session import AppState, Hub

__all__ = ["TpmApp", "build_server", "main"]

BRAND = (13, 148, 136)


def _no_share_url(*_args, **_kwargs) -> None:
    """Replacement of ``ViserServer.request_share_url``: the share tunnel stays off."""
    return None


def _reference() -> Reference | None:
    """The Pinocchio model's inverse dynamics, if :mod:`tpm_viz.multibody` can be imported."""
    try:
        from .. import multibody
    except ImportError:  # pragma: no cover - pinocchio is a declared dependency
        return None
    return multibody.inverse_dynamics


def is_loopback(host: str) -> bool:
    """Whether ``host`` only accepts connections from this machine."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def build_server(host: str = "127.0.0.1", port: int = 8080) -> viser.ViserServer:
    """A quiet viser server: no share tunnel, no environment map or shadows (fast first paint)."""
    with contextlib.redirect_stdout(io.StringIO()):  # viser prints its own banner even with verbose=False
        server = viser.ViserServer(host=host, port=port, label="tpm-viz", verbose=False)
    server.request_share_url = _no_share_url  # type: ignore[method-assign]
    server.gui.configure_theme(
        control_width="large", show_share_button=False, show_logo=False, brand_color=BRAND, dark_mode=False
    )
    server.scene.configure_environment_map(None)
    server.scene.configure_default_lights(enabled=True, cast_shadow=False)
    server.scene.add_light_hemisphere(
        "/lights/sky", sky_color=(255, 255, 255), ground_color=(148, 163, 184), intensity=1.4
    )
    server.scene.add_light_directional("/lights/key", intensity=1.2, position=(0.4, -0.6, 1.5))
    server.scene.world_axes.visible = False
    return server


class TpmApp:
    """The app on one server: the hub (shared state, lock) and a view per connected tab."""

    def __init__(self, server: viser.ViserServer, params: Params | None = None, reference="auto") -> None:
        self.server = server
        self.hub = Hub(AppState.initial(params), _reference() if reference == "auto" else reference)
        self.hub.evaluate(self.hub.shared.state)  # warm-up: builds the Pinocchio model once
        self.views: dict[int, ClientView] = {}
        self._views_lock = threading.Lock()
        position, look_at = camera_pose(self.hub.shared.state.params)
        server.initial_camera.position = position
        server.initial_camera.look_at = look_at
        self.hub.on_membership = self._class_info
        server.on_client_connect(self._connect)
        server.on_client_disconnect(self._disconnect)

    @property
    def port(self) -> int:
        """The port the server really listens on."""
        return self.server.get_port()

    def _connect(self, client: viser.ClientHandle) -> None:
        view = ClientView(client, self.hub)
        with self._views_lock:
            self.views[client.client_id] = view
        self._class_info()

    def _disconnect(self, client: viser.ClientHandle) -> None:
        with self._views_lock:
            view = self.views.pop(client.client_id, None)
        if view is not None:
            view.close()

    def _class_info(self) -> None:
        connected = set(self.server.get_clients())
        with self._views_lock:
            views = [v for cid, v in self.views.items() if not v.closed and cid in connected]
        shared = self.hub.shared_viewers()
        for view in views:
            where = "your own copy" if not view.session.shared else "the shared mechanism"
            view.set_class_info(f"{len(views)} tab(s) connected, {shared} on the shared mechanism. You see {where}.")

    def stop(self) -> None:
        """Stop the server (the port is free again at once)."""
        self.server.stop()


def main(host: str = "127.0.0.1", port: int = 8080, block: bool = True) -> TpmApp:
    """Serve the app; print one line with the real URL; block until Ctrl-C unless ``block`` is False."""
    if not is_loopback(host):
        print(
            f"warning: serving on {host}: anyone who can reach this address can change the shared mechanism "
            "(there is no authentication)",
            file=sys.stderr,
        )
    app = TpmApp(build_server(host, port))
    shown = "127.0.0.1" if host in ("0.0.0.0", "::") else host
    print(f"tpm-viz serving at http://{shown}:{app.port}", flush=True)
    if not block:
        return app
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        app.stop()
    return app
