"""The *Design* tab: the atlas as a heat map (:mod:`.map`, :mod:`.scene`), both arrangements drawn
(:mod:`.drawings`), its words (:mod:`.text`) and the tab (:mod:`.tab`)."""
