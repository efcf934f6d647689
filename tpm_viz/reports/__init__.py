"""Documents of a run for people outside the room: the self-contained HTML lab report.

May import the base modules, :mod:`tpm_viz.paper`, the drawing layer (:mod:`tpm_viz.figures`) and :mod:`tpm_viz.app`
(``tests/system/test_layering.py``); the command line and the UI call it.
"""
