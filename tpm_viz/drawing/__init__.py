"""Drawing: the mechanism as trimesh parts for both arrangements (:mod:`.meshes`, :mod:`.meshes_parallel`), the
paper's figures with matplotlib (:mod:`.figures`) and the one palette (:mod:`.palette`)."""
