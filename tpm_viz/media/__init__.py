"""What leaves the room: frames of a clip (:mod:`.clips`: the top view; :mod:`.views3d`: through a tab's 3D camera),
their GIF / MP4 encoders (:mod:`.videos`) and the self-contained HTML lab report (:mod:`.report`)."""
