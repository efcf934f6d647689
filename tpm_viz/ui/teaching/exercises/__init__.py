"""*Teach › Exercises* and the lesson's exercises under its text: a tab's cards (:mod:`.tab`, :mod:`.card`),
their words (:mod:`.text`), the lecturer's *Exercise results* (:mod:`.lecturer`) and the app's desk that ties them to
the gradebook (:mod:`.desk`; the rules are :mod:`tpm_viz.classroom.results`, the engine
:mod:`tpm_viz.app.exercises`)."""
