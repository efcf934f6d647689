"""The browser app (viser). The only package of tpm-viz that imports viser; nothing in the library imports it.

- :mod:`.scene`: the 3D mechanism of one tab, handles built once, then moved;
- :mod:`.panels`: the control panel of one tab, handles built once, then written;
- :mod:`.text`: formatting of the readouts (HTML), no maths;
- :mod:`.session`: shared state, private copies and the lock that serialises changes;
- :mod:`.frame`: one committed state and its drawing data, computed once for all tabs;
- :mod:`.client`: one tab's callbacks (widget -> pure library function -> commit);
- :mod:`.transitions`: the state transitions those callbacks run (pure), :mod:`.validate`: the readers of
  untrusted values and uploads, :mod:`.guard`: callbacks that log and keep going, :mod:`.access`: presenter mode,
  :mod:`.transport`: malformed messages and oversized uploads dropped before viser handles them;
- :mod:`.teaching`: the teaching layer of one tab: :mod:`.player` (trajectories, with :mod:`.runs` per session
  and :mod:`.charts`), :mod:`.explorer` (floor maps, ellipses), :mod:`.demos_panel`; :mod:`.worker` runs their slow
  computations off the callbacks;
- :mod:`.app`: the server and ``main(host, port, presenter_token=None)``.
"""
