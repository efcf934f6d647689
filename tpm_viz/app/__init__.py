"""Pure app behaviour, no browser: the app's state (:mod:`.state`), its transitions (:mod:`.transitions`), input
readers (:mod:`.inputs`), interactive moves (:mod:`.moves`), special poses (:mod:`.poses`), readouts
(:mod:`.readouts`), trajectory runs (:mod:`.runs`), lessons (:mod:`.lessons`), floor overlays (:mod:`.overlays`), the
equations panel (:mod:`.equations`), the planner's paths and timing (:mod:`.paths`, :mod:`.planner`,
:mod:`.planning`) and motor sizing (:mod:`.sizing`).

Import rule (checked by ``tests/system/test_layering.py``): no viser and no pinocchio; the Pinocchio reference forces
come in as a callable (:data:`tpm_viz.app.readouts.Reference`). May import :mod:`tpm_viz.core` and
:mod:`tpm_viz.paper`.
"""
