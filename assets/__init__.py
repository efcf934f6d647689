"""tpm-viz's packaged data, installed as ``tpm_viz.assets``: ``lessons/`` (the guided tour, TOML), ``trajectories/``
(example ``t,p1,p2`` CSV files) and ``presets/`` (parameter sets, TOML). Found at run time by
:func:`tpm_viz.app.lesson_files.assets_dir`; each folder's README.md documents its files."""
