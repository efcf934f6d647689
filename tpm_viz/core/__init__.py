"""The base layer, standard library and numpy only: one error hierarchy (:mod:`.errors`), validated parameters
(:mod:`.params`), numbers as people type them (:mod:`.numbers`), words in two languages (:mod:`.words`), the one
reader of files (:mod:`.files`) and CSV as spreadsheets write it (:mod:`.csvio`, :mod:`.csvdialect`)."""
