"""Seeds and variants: which numbers a student gets, as pure functions of a seed.

- :func:`student_seed`: a student's seed for an exercise, ``HMAC-SHA256(key, identity ␟ exercise id)`` cut to 53
  bits. ``identity`` is what the server issued (the stored hash of the browser's cookie id,
  ``tpm_viz.classroom.identity.hashed``; an LTI user id); ``key`` is a secret the server keeps beside its store (so
  the seed is the same over reconnects, restarts and devices of the same identity, differs between students, and
  cannot be computed by a student for another one). Never Python's ``hash`` (salted per process).
- A class-wide seed: the lecturer fixes one integer ``S``; every student's seed is ``S`` for every exercise (an exam
  projected on the wall).
- :func:`variant`: the exercise's draws (``[exercise.draw]``) from the seed. Quantity ``name`` in round ``r`` takes
  ``values[floor(u · len(values))]`` with ``u`` the first 53 bits of ``SHA-256("<seed>␟<exercise id>␟<name>␟<r>")``
  (UTF-8, ``␟`` the unit separator U+001F) over ``2⁵³``: the same in any language and any version of numpy. A round
  whose parameters the mechanism refuses or whose numbers the exercise's computation cannot use (a pose near a
  singularity, no zero-force pose) is drawn again with ``r + 1``, at most :data:`ROUNDS` times.

Seeds are integers from 0 to :data:`MAX_SEED` (2⁵³ - 1: exact in JavaScript too).
"""

from __future__ import annotations

import hashlib
import hmac
from collections.abc import Callable

from tpm_viz.app.exercises.model import Exercise, Variant
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.core.words import Phrase

__all__ = ["MAX_SEED", "ROUNDS", "parse_seed", "student_seed", "uniform", "variant"]

MAX_SEED = 2**53 - 1
"""Largest seed (seeds are 0 to 2⁵³ - 1)."""
ROUNDS = 64
"""Most rounds of draws before :func:`variant` gives up (one line: widen the exercise's ranges)."""
_SEP = "\x1f"


def parse_seed(text: object) -> int:
    """A seed from text or an integer: a whole number from 0 to :data:`MAX_SEED`, else :class:`InputError`."""
    if isinstance(text, bool):
        raise InputError(Phrase("the seed must be a whole number from 0 to {most}, got {got}", most=MAX_SEED, got=text))
    if isinstance(text, int):
        value = text
    else:
        s = str(text).strip()
        if not (s.isascii() and s.isdigit()) or len(s) > 20:
            raise InputError(
                Phrase("the seed must be a whole number from 0 to {most}, got {got}", most=MAX_SEED, got=repr(s[:40]))
            )
        value = int(s)
    if not 0 <= value <= MAX_SEED:
        raise InputError(
            Phrase("the seed must be a whole number from 0 to {most}, got {got}", most=MAX_SEED, got=value)
        )
    return value


def _top53(digest: bytes) -> int:
    return int.from_bytes(digest[:8], "big") >> 11


def student_seed(key: bytes, identity: str, exercise_id: str) -> int:
    """The seed of ``identity`` for ``exercise_id`` under the server's secret ``key`` (module docstring)."""
    if not isinstance(key, bytes) or len(key) < 16:
        raise InputError(Phrase("the seed key must be at least 16 bytes"))
    message = f"{identity}{_SEP}{exercise_id}".encode()
    return _top53(hmac.new(key, message, hashlib.sha256).digest())


def uniform(seed: int, exercise_id: str, name: str, round_: int = 0) -> float:
    """The number in ``[0, 1)`` that picks quantity ``name`` of ``exercise_id`` for ``seed`` in round ``round_``."""
    message = f"{seed}{_SEP}{exercise_id}{_SEP}{name}{_SEP}{round_}".encode()
    return _top53(hashlib.sha256(message).digest()) / 2.0**53


def variant(exercise: Exercise, seed: int, usable: Callable[[Variant], bool] | None = None) -> Variant:
    """The variant of ``exercise`` for ``seed`` (module docstring); ``usable`` says whether a round's numbers suit
    the exercise's computation (default: any that the mechanism accepts). Raises :class:`InputError` when no round
    of :data:`ROUNDS` gives a usable variant."""
    seed = parse_seed(seed)
    base = Params.paper().replace(**dict(exercise.base))
    for round_ in range(ROUNDS):
        drawn: dict[str, float] = {}
        for draw in exercise.draws:
            if len(draw.values) == 1:
                drawn[draw.name] = draw.values[0]
            else:
                k = int(uniform(seed, exercise.id, draw.name, round_) * len(draw.values))
                drawn[draw.name] = draw.values[min(k, len(draw.values) - 1)]
        try:
            params = base.replace(**{k: v for k, v in drawn.items() if k in PARAM_INFO})
        except TpmVizError:
            continue
        candidate = Variant(
            exercise=exercise.id,
            seed=seed,
            params=params,
            inputs=tuple((k, v) for k, v in drawn.items() if k not in PARAM_INFO),
        )
        if usable is None or usable(candidate):
            return candidate
    raise InputError(
        Phrase(
            "exercise {id}: no usable variant for seed {seed} in {rounds} draws; widen its ranges",
            id=exercise.id,
            seed=seed,
            rounds=ROUNDS,
        )
    )
