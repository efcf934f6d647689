"""Seeds and variants: stable for the same seed (in another process, with another hash salt), different between
students, keyed by the server's secret; every drawn value on the exercise's grid.

The draw is specified in ``tpm_viz/app/exercises/variants.py`` byte for byte (a JavaScript port reproduces it);
:func:`_uniform` below is that specification written again from the text, and the pinned vector is what both give.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tpm_viz.app.exercises.catalogue import by_id, listed
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.app.exercises.variants import MAX_SEED, parse_seed, student_seed, uniform
from tpm_viz.core.errors import InputError

KEY = b"k" * 32


def _uniform(seed: int, exercise: str, name: str, round_: int) -> float:
    text = f"{seed}\x1f{exercise}\x1f{name}\x1f{round_}"
    return (int.from_bytes(hashlib.sha256(text.encode("utf-8")).digest()[:8], "big") >> 11) / 2**53


def test_the_draw_is_the_documented_hash():
    for seed, name, round_ in ((0, "l_a", 0), (42, "p1", 3), (MAX_SEED, "ddp2", 63)):
        assert uniform(seed, "force-at-pose", name, round_) == _uniform(seed, "force-at-pose", name, round_)
    # coreutils: printf '0\x1fdirect-singularity-diagonal\x1fl_a\x1f0' | sha256sum -> 322cafdd6a2f5070...; Node's
    # crypto with BigInt gives the same 0.19599436908373247 (the vector of docs/exercises.md)
    assert uniform(0, "direct-singularity-diagonal", "l_a") == (0x322CAFDD6A2F5070 >> 11) / 2**53


def test_a_student_seed_is_the_documented_keyed_hash():
    mac = hmac.new(KEY, b"c:abc\x1fforce-at-pose", hashlib.sha256).digest()
    assert student_seed(KEY, "c:abc", "force-at-pose") == int.from_bytes(mac[:8], "big") >> 11


def test_student_seeds_differ_between_students_exercises_and_keys():
    students = [f"c:{hashlib.sha256(str(k).encode()).hexdigest()}" for k in range(200)]
    seeds = {student_seed(KEY, s, "force-at-pose") for s in students}
    assert len(seeds) == len(students)
    assert student_seed(KEY, students[0], "force-at-pose") != student_seed(KEY, students[0], "zero-force-pose")
    assert student_seed(KEY, students[0], "force-at-pose") != student_seed(b"j" * 32, students[0], "force-at-pose")
    assert all(0 <= s <= MAX_SEED for s in seeds)
    with pytest.raises(InputError):
        student_seed(b"short", students[0], "force-at-pose")


_CHILD = """
import json, sys
from tpm_viz.app.exercises.catalogue import listed
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.app.exercises.variants import student_seed
out = {}
for item in listed():
    ex = item.exercise
    seed = student_seed(b"k" * 32, "c:student", ex.id)
    out[ex.id] = [seed, variant_of(ex, seed).values()]
print(json.dumps(out))
"""


def test_the_same_identity_gets_the_same_variants_after_a_restart():
    """A new process with another hash salt (``PYTHONHASHSEED``) draws the same seeds and the same numbers."""
    runs = []
    for salt in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": salt}
        done = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        runs.append(json.loads(done.stdout))
    here = {}
    for item in listed():
        seed = student_seed(KEY, "c:student", item.exercise.id)
        here[item.exercise.id] = [seed, variant_of(item.exercise, seed).values()]
    assert runs[0] == runs[1] == json.loads(json.dumps(here))


@pytest.mark.parametrize("ident", [item.exercise.id for item in listed()])
def test_variants_are_on_the_grid_and_differ_between_seeds(ident):
    exercise = by_id(ident).exercise
    grids = {d.name: set(d.values) for d in exercise.draws}
    seen = set()
    for seed in range(40):
        variant = variant_of(exercise, seed)
        assert variant == variant_of(exercise, seed)  # a pure function of the seed
        values = variant.values()
        for name, grid in grids.items():
            assert values[name] in grid
        seen.add(tuple(sorted((k, values[k]) for k in grids)))
    possible = 1
    for grid in grids.values():
        possible *= len(grid)
    assert len(seen) >= min(20, possible // 2)


@given(st.integers(0, MAX_SEED))
def test_any_seed_gives_a_variant(seed):
    for item in listed():
        if not item.exercise.heavy:
            variant_of(item.exercise, seed)


@pytest.mark.parametrize("text", ["-1", "x", "1.5", str(MAX_SEED + 1), "", "1e3", "٣"])
def test_a_bad_seed_is_refused(text):
    with pytest.raises(InputError, match="the seed must be a whole number from 0 to 9007199254740991"):
        parse_seed(text)


def test_a_class_seed_is_the_seed():
    """The lecturer's class-wide seed: every student's seed is that number, so they all see the same numbers."""
    exercise = by_id("force-at-pose").exercise
    assert variant_of(exercise, parse_seed(" 2024 ")) == variant_of(exercise, 2024)
