"""The teaching tabs of a browser tab, built by :class:`~tpm_viz.ui.teaching.tabs.Teaching`: the trajectory player
(:mod:`.player`), the singularity explorer (:mod:`.explorer`), the guided lessons (:mod:`.lessons`), the control lab
(:mod:`.control`), the planner (:mod:`.planner`), the design studio (:mod:`.design`) and what a tab takes out of the
room (:mod:`.takeout`); :mod:`.motion`, :mod:`.settings` and :mod:`.stage` are what several of them share."""
