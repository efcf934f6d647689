"""Pure app behaviour, no browser: the app's state, its transitions, input readers, interactive moves, special
poses, readouts, trajectory runs, lessons, floor overlays, the equations panel and the presenter policy.

Import rule (checked by ``tests/test_layering.py``): no viser and no pinocchio; the Pinocchio reference forces come
in as a callable (:data:`tpm_viz.app.readouts.Reference`). May import the base modules and :mod:`tpm_viz.paper`.
"""
