"""Each outgoing message is serialised once for every tab it goes to (``shared_serializer`` in viserkit/wire.py), and
what a tab receives is exactly what viser's own serialisation gives, wherever the message falls in a window."""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

from tpm_viz.viserkit.probe import VISER_SERIALIZE as _SERIALIZE
from tpm_viz.viserkit.probe import messages as _messages
from tpm_viz.viserkit.probe import shared_serialize


def _node_update(seed: int):
    rng = np.random.default_rng(seed)
    return _messages.SceneNodeUpdateMessage(
        "/tpm/links", {"batched_positions": rng.normal(size=(4, 3)).astype(np.float32)}
    )


def _decoded(out, buffers):
    """The message as the page rebuilds it: placeholders replaced by their arrays."""
    if isinstance(out, dict) and "__binary_index" in out:
        return np.frombuffer(buffers[out["__binary_index"]], dtype=out["dtype"]).tolist()
    if isinstance(out, dict):
        return {k: _decoded(v, buffers) for k, v in out.items()}
    if isinstance(out, (list, tuple)):
        return [_decoded(v, buffers) for v in out]
    return out


@pytest.mark.parametrize("offset", [0, 1, 3])
def test_a_message_in_any_window_position_decodes_as_viser_serialises_it(offset):
    message, others = _node_update(0), [_node_update(k) for k in range(1, 4)]
    first: list = []
    out_first = shared_serialize(message, first)  # the first tab: viser's own path, cached
    window: list = []
    for other in others[:offset]:
        shared_serialize(other, window)
    out = shared_serialize(message, window)  # another tab, the message later in its window
    fresh: list = []
    expected = _decoded(_SERIALIZE(message, fresh), fresh)
    assert _decoded(out, window) == expected == _decoded(out_first, first)
    assert out["updates"]["batched_positions"]["__binary_index"] == offset


def test_the_second_tab_reuses_the_first_serialisation():
    message = _messages.SetPositionMessage("/tpm/platform", (0.1, 0.2, 0.0))
    one, two = shared_serialize(message, []), shared_serialize(message, [])
    assert one is two  # made once


def test_a_changed_copy_is_serialised_again():
    """A changed copy of a message (``dataclasses.replace``, ``copy.copy``) never reuses its original's wire dict."""
    original = _messages.GuiUpdateMessage("uuid-1", {"label": "Move"})
    assert shared_serialize(original, [])["updates"] == {"label": "Move"}
    replaced = dataclasses.replace(original, updates={"label": "이동"})
    assert shared_serialize(replaced, [])["updates"] == {"label": "이동"}
    shallow = copy.copy(original)
    shallow.updates = {"label": "힘"}
    assert shared_serialize(shallow, [])["updates"] == {"label": "힘"}
