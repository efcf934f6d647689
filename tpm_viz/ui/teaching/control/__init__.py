"""The *Control* tab: the tab (:mod:`.tab`), its runs without widgets (:mod:`.run`) and its words (:mod:`.text`)."""
