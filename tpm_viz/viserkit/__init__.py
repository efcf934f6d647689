"""The adapter between tpm-viz and viser 1.1.x: every private name of viser or websockets, and every patch, lives here.

- :mod:`.core`: the door (:func:`~.core.check_viser`, the patches installed on one server, handle values read
  without callbacks);
- :mod:`.wire`, :mod:`.windows`, :mod:`.wakeups`: outgoing messages serialised once, leaner senders, safe wakeups;
- :mod:`.transport`: malformed or oversized incoming messages and uploads refused before viser handles them;
- :mod:`.limits`: the websocket server's limits (frame size, URL length, connections per address).

See ``PATCHES.md`` beside this file for each patch, why it is there and the test that shows it.
"""
