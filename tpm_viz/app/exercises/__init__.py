"""The exercise engine: practice in the lessons that grades itself (PrairieLearn's model; ``docs/exercises.md``).

Exercises are data: ``[[exercise]]`` tables in the lesson files (``assets/lessons/README.md``), read with the
lesson (:mod:`.reader`); each names the computation of its reference answer (:mod:`.tasks`, :mod:`.gains`), never
the answer itself. Pure functions, no viser, no Pinocchio, no store: the browser tab, the results store and the
lecturer's table are built on this API.

**The API for the UI** (every text a student reads is a :class:`~tpm_viz.core.words.Phrase`: ``.render(lang)`` gives
English or Korean):

- list: :func:`.catalogue.listed` ``(lessons=DEMOS, lesson=None)`` -> ``Listed(lesson_number, lesson, exercise)``
  in tour order; ``demo.exercises`` are a lesson's own; :func:`.catalogue.by_id` ``(id)``. An
  :class:`~.model.Exercise` has ``id``, ``kind`` (number, pose, gains, choice), ``unit``, ``title`` and
  ``options`` (:class:`~.model.Texts`: ``.get(lang)``), ``attempts`` (:class:`~.model.AttemptRule`) and ``heavy``
  (grading simulates for up to a second: submit it to the fair worker, ``tpm_viz.classroom.worker``).
- seed: :func:`.variants.student_seed` ``(key, identity, exercise_id)`` with the server's secret ``key`` and the
  identity's stored hash (``tpm_viz.classroom.identity.hashed``), or the class-wide seed the lecturer fixed.
- variant and prompt: :func:`.grading.variant_of` ``(exercise, seed)`` -> :class:`~.model.Variant` (``params``
  and drawn ``inputs``, SI); :func:`.grading.prompt` ``(exercise, variant)`` -> the filled prompt (a phrase).
- grade: :func:`.grading.grade` ``(exercise, variant, text, attempt)`` -> :class:`~.model.Grade` with ``score``
  (after the ladder; None for a format error), ``raw``, ``format_error`` (a phrase: what to change; no attempt
  used), ``feedback`` (a phrase: the matched mistake or why), ``attempts_used`` (0 or 1), ``attempts_left`` (None:
  unlimited) and the answer as read (``values`` in the exercise's unit, or ``choice``). ``attempt`` is the number
  of counted attempts so far plus one (format errors do not count); an attempt beyond the ladder raises
  :class:`~tpm_viz.core.errors.InputError` (show "no attempts left" instead of calling).
- attempt rule: :meth:`~.model.AttemptRule.best` over the scores of a student's attempts is the exercise's score
  (homework and exam alike); :meth:`~.model.AttemptRule.latest` the last one; ``max_attempts`` and ``left(used)``.
- results: :class:`~.model.Result` ``(student, exercise, seed, attempt, answer, score, time)`` is the record the
  store keeps for each graded (not format-error) submission.
- the reference: :func:`.grading.reference` (for a lecturer's *reveal*); :func:`.selftest.selftest`.

"Use current pose" for a pose answer: type the platform's position in mm, ``f"{p1:.2f}; {p2:.2f}"``.
"""

from __future__ import annotations
