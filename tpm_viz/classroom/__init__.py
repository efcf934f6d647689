"""The classroom's memory and identities, without viser: what survives a restart and who may claim it.

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

Layer rule (tests/system/test_layering.py): the standard library, the base layer, ``paper`` and ``app`` only.
"""
