"""The watchdog's size of a queued message (viserkit/wire.py ``message_bytes``) runs in its own thread while the
event loop
may add to the message's dict (the shared serialisation stores its wire dict there): it must never fail with
"dictionary changed size during iteration", which stopped the watchdog in a lecture-hall run."""

from __future__ import annotations

import numpy as np

from tpm_viz.viserkit.wire import message_bytes


class _Message:
    pass


class _Growing:
    """A payload whose ``nbytes`` is read mid-iteration, and adds a key to its message's dict as the loop would."""

    def __init__(self, message: _Message) -> None:
        self.message = message

    @property
    def nbytes(self) -> int:
        self.message.__dict__.setdefault("_tpm_viz_wire", ("cached",))
        return 10


def test_a_message_whose_dict_grows_while_it_is_sized_is_sized():
    message = _Message()
    message.name = "/tpm/links"  # 10 characters
    message.points = np.zeros((4, 3), dtype=np.float32)  # 48 bytes
    message.grows = _Growing(message)  # 10 bytes, and a new key mid-iteration
    assert message_bytes(message) == 64 + 10 + 48 + 10
    assert "_tpm_viz_wire" in vars(message)
