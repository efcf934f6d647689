"""What leaves the room: frames of a clip (:mod:`.clips`: the top view; :mod:`.views3d`: through a tab's 3D camera),
their GIF / MP4 encoders (:mod:`.videos`), the self-contained HTML lab report (:mod:`.report`), and the offline lesson
page (:mod:`.page_html` with :mod:`.page_parts`; its exercises :mod:`.page_exercises` and grader :mod:`.page_grader`;
its SCORM 1.2 package :mod:`.scorm`)."""
