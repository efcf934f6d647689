"""The trajectory player: the tab (:mod:`.tab`), its charts (:mod:`.charts`), the path and trace in the scene
(:mod:`.trace`) and its summary line (:mod:`.text`)."""
