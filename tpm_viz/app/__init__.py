"""Pure app behaviour, no browser: the app's state, its transitions, input readers, interactive moves, special
poses, readouts, trajectory runs, lessons, floor overlays, the equations panel, who a connection
comes from (:mod:`.network`), share links (:mod:`.links`), and the design studio (:mod:`.design`, :mod:`.atlas`,
:mod:`.compare`).

Import rule (checked by ``tests/system/test_layering.py``): no viser and no pinocchio; the Pinocchio reference forces
come in as a callable (:data:`tpm_viz.app.readouts.Reference`). May import the base modules and :mod:`tpm_viz.paper`.
"""
