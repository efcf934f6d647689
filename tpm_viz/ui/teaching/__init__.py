"""The teaching tabs of a browser tab: the trajectory player (with its charts and trace), the singularity explorer
and the guided lessons, built by :class:`~tpm_viz.ui.teaching.tabs.Teaching`."""
