"""Drawing: the mechanism as trimesh parts for both arrangements (:mod:`.meshes`: a shared base, one module each), the
paper's figures with matplotlib (:mod:`.figures`), names in them drawn as text (:mod:`.labels`) and the one palette
(:mod:`.palette`)."""
