"""The browser app (viser, through its public API; viser's internals are in :mod:`tpm_viz.viserkit`).

- the server: :mod:`.app` (``main(host, port, ...)``, :func:`~.app.build_server`), :mod:`.room` (presenter, tabs
  that come back, the session file), :mod:`.classroom` (addresses, identities, handshakes), :mod:`.continuity`
  (tabs that left, the saved session), :mod:`.lecturer` and :mod:`.login` (the presenter's folders);
- one tab: :mod:`.client` (its callbacks), :mod:`.panels`, :mod:`.fields`, :mod:`.widgets` (typed number boxes, chart
  axes, camera framing, the shapes of a drawing), :mod:`.scene` and :mod:`.tabscene` (the 3D view), :mod:`.look`
  (layout, presentation mode, camera), :mod:`.worded` (the tab's GUI in its language) and :mod:`.language` (its
  selector), :mod:`.notebook` (Jupyter), :mod:`.takehome` (a lesson recorded for the offline page), and
  :mod:`.teaching` (the teaching tabs).

The shared state every tab draws (sessions, snapshot, drags, pacing, access, worker) is :mod:`tpm_viz.classroom`.
"""
