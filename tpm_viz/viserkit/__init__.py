"""The adapter between tpm-viz and viser 1.1.x: every private name of viser or websockets, and every patch, lives here.

- :mod:`.adapter`: the entry point (:func:`~.adapter.new_server`, :func:`~.adapter.install` on one server,
  :meth:`~.adapter.Installed.remove`);
- :mod:`.core`: the door to one server's internals (:func:`~.core.check_viser`, handle values read without callbacks);
- :mod:`.doors`: a tab's and the websocket server's message handling (:class:`~.doors.ClientDoor`,
  :class:`~.doors.ServerDoor`);
- :mod:`.patches`: the few patches that act through a class, guarded to act for tpm-viz's own servers only;
- :mod:`.incoming`: a smaller frame limit, no HTTP 500, incoming messages decoded quietly (on registered loops);
- :mod:`.gate`: a tab's callbacks one at a time in viser's thread pool (for :mod:`.limits`);
- :mod:`.wire`, :mod:`.windows`, :mod:`.wakeups`: outgoing messages serialised once, leaner senders, safe wakeups;
- :mod:`.transport`: malformed or oversized incoming messages and uploads refused before viser handles them;
- :mod:`.limits`: the websocket server's limits (callbacks per tab, backlog, connections, malformed messages);
- :mod:`.probe`: small public functions for tests and benchmarks (a widget's uuid, a tab's uploads, ...);
- :mod:`.page`: tpm-viz's own script in viser's page.

See ``PATCHES.md`` beside this file for each patch, why it is there, the test that shows it and the condition that
retires it; ``upstream/`` holds the issue each would file at viser, with a script that shows it on viser alone.
"""
