"""The browser app (viser). The only package of tpm-viz that imports viser; nothing in the library imports it.

- the server: :mod:`.app` (``main(host, port, ...)``, :func:`~.app.build_server`), :mod:`.room` (presenter, tabs
  that come back, the session file), :mod:`.classroom` (addresses, identities, handshakes), :mod:`.continuity`
  (tabs that left, the saved session), :mod:`.lecturer` and :mod:`.login` (the presenter's folders);
- shared state: :mod:`.session` (the hub, sessions and the lock), :mod:`.snapshot` (one committed state drawn once
  for all tabs), :mod:`.drags` and :mod:`.dragging` (when drags are committed), :mod:`.worker` (slow jobs);
- one tab: :mod:`.client` (its callbacks), :mod:`.panels`, :mod:`.fields` and :mod:`.text` (the panel),
  :mod:`.scene` and :mod:`.tabscene` (the 3D view), :mod:`.look` (layout, presentation mode, camera),
  :mod:`.language`, :mod:`.notebook` (Jupyter), and :mod:`.teaching` (the teaching tabs);
- viser's internals and the server's limits: :mod:`._viser` (every private viser name), :mod:`.wire`,
  :mod:`.windows`, :mod:`.wakeups`, :mod:`.transport`, :mod:`.limits`, :mod:`.guard`.
"""
