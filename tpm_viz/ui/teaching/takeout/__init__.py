"""What a tab takes out of the room: the buttons (:mod:`.buttons`), the material of each run
(:mod:`.materials`) and the recording of a clip (:mod:`.recording`)."""
