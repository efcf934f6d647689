"""``point_camera`` (viserkit/core.py) leaves a tab's camera as viser's two setters do (``camera.position = p`` then
``camera.look_at = l``): the same state on the server, orientation included, and the same last position and look-at
point in the tab; it refuses what they refuse and then leaves the camera as it was."""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.viserkit.core import point_camera


class _CameraTab(ProtocolClient):
    """A tab that remembers the last camera position and look-at point it was sent."""

    def __init__(self, port: int) -> None:
        self.camera: dict[str, tuple] = {}
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        if m["type"] in ("SetCameraPositionMessage", "SetCameraLookAtMessage"):
            self.camera[m["type"]] = tuple(m["position" if "Position" in m["type"] else "look_at"])


def _state(camera) -> tuple[np.ndarray, ...]:
    return camera.position.copy(), camera.look_at.copy(), camera.wxyz.copy()


def _sent(tab: _CameraTab, position: np.ndarray, look_at: np.ndarray) -> bool:
    """Whether the last camera position and look-at point the tab was sent are these."""
    sent = tab.camera.get("SetCameraPositionMessage"), tab.camera.get("SetCameraLookAtMessage")
    return None not in sent and np.allclose(sent[0], position) and np.allclose(sent[1], look_at)


def _poses() -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(7)
    poses = [
        (np.array([0.4, -0.6, 0.5]), np.array([0.1, 0.1, 0.0])),  # the app's framing, roughly
        (np.array([0.0, 0.0, 2.0]), np.zeros(3)),  # straight down: up is along the view (viser's fallback)
        (np.array([0.0, -1.0, 1.0]), np.zeros(3)),  # where the tab's camera already is
    ]
    poses += [(rng.normal(size=3), rng.normal(size=3)) for _ in range(12)]
    return poses


def test_pointing_the_camera_is_visers_two_setters(serve):
    server, _ = serve()
    tabs = [_CameraTab(server.get_port()) for _ in range(2)]
    try:
        wait_for(lambda: len(server.get_clients()) == 2, what="both tabs to be known to viser")
        setters, pointed = (client.camera for client in server.get_clients().values())
        for position, look_at in _poses():
            setters.position = position
            setters.look_at = look_at
            point_camera(pointed, position, look_at)
            for ours, theirs in zip(_state(pointed), _state(setters), strict=True):
                np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
            wait_for(
                lambda p=position, at=look_at: all(_sent(t, p, at) for t in tabs), what="both tabs to get the camera"
            )
    finally:
        for tab in tabs:
            tab.close()


@pytest.mark.parametrize(
    ("position", "look_at"),
    [((np.nan, 0.0, 1.0), (0.0, 0.0, 0.0)), ((0.0, 0.0, 1.0), (0.0, np.inf, 0.0)), ((0.3, 0.2, 0.1), (0.3, 0.2, 0.1))],
    ids=["nan", "inf", "no direction"],
)
def test_what_the_setters_refuse_is_refused_and_the_camera_left_as_it_was(serve, tab, position, look_at):
    server, _ = serve()
    tab(server)
    (client,) = server.get_clients().values()
    before = _state(client.camera)
    with pytest.raises(ValueError):
        point_camera(client.camera, position, look_at)
    for now, then in zip(_state(client.camera), before, strict=True):
        np.testing.assert_array_equal(now, then)
