"""The *Planner* tab: the tab (:mod:`.tab`) and its words (:mod:`.text`)."""
