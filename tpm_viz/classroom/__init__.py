"""The classroom without viser: the shared state every tab draws, what survives a restart and who may claim it.

- :mod:`.session`: the hub, the sessions (shared or a tab's own copy) and their lock; :mod:`.snapshot` (one
  committed state drawn once for all tabs) and :mod:`.text` (the panel's texts); :mod:`.drags` and
  :mod:`.dragging` (when a drag is committed); :mod:`.pacing` (how often tabs redraw); :mod:`.access` (who may
  change what); :mod:`.worker` (a tab's slow jobs on :mod:`.jobs`); :mod:`.guard` (callbacks that never take the
  server down, the bounded fault log).

- :mod:`.store`: the store (a :class:`~.store.Store` protocol, :class:`~.store.SqliteStore` over the standard
  library's ``sqlite3``): the lecture in its own record, each remembered browser's tabs in its own record, uploaded
  trajectories once by content hash; a store it cannot read is moved aside, never overwritten.
- :mod:`.records`: the records' JSON bodies (the lecture, a browser's tabs) and the one-time import of an old JSON
  session file.
- :mod:`.identity`: cookies the server mints and signs (HMAC-SHA256 with a secret kept beside the store, mode
  0600); the stored identity is a hash of the cookie, never the cookie.
- :mod:`.away`: the tabs that left, bounded per browser, per source address and in total; the presenter's right
  comes back only to the same address within :data:`~.away.PRESENTER_SECONDS`.
- :mod:`.saver`: the saving thread: one transaction per save, failures said once, retried with back-off, recovery
  said once.
- :mod:`.jobs`: the fair queue of every tab's heavy jobs (runs, maps, control lab, planner): one pending job per tab
  and kind (latest wins), light tabs before flooders, bounded per tab and in total, a small thread pool.

- :mod:`.runhub`: each session's trajectory runs (loading in the background, playback, pause and seek).
- :mod:`.sessionfile`: the saved session's versioned JSON format; :mod:`.links`: share links; :mod:`.network`: who a
  connection really comes from and which ``Host`` names this server answers to.

Layer rule (tests/system/test_layering.py): the standard library, :mod:`tpm_viz.core`, ``paper``, the drawing layer
and ``app`` only.
"""
