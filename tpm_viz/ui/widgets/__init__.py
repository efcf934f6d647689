"""Pure helpers only the UI needs: typed numbers (:mod:`.typed`, :mod:`.typed_sliders`), chart axes
(:mod:`.chart_axes`), camera framing (:mod:`.framing`) and the shapes of a drawing (:mod:`.scene_shapes`)."""
