"""The design studio: design indices over a task (:mod:`.indices`), the atlas of designs and its optimum
(:mod:`.atlas`), the paper's claim put to a test (:mod:`.compare`) and the atlas on a Dask cluster (:mod:`.cluster`,
the only module that imports Dask)."""
