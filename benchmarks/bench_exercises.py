"""Speed of the exercise grader (run by hand: ``python benchmarks/bench_exercises.py``).

Targets of issue 37 on this 2-core machine: grading p95 <= 50 ms for ``number`` and ``pose`` answers, <= 1 s for
``gains`` (a closed-loop simulation on the closed-form plant, twice when the rad/s mistake is checked). Each exercise
is graded on :data:`SEEDS` variants with a right answer, a wrong one and a format error, every grading from empty
caches (:func:`tpm_viz.app.exercises.grading.clear_caches`: as a first submission computes); prints the median and
the p95 per exercise and the ratio of the p95 to the target. Then the parts: one plant evaluation, one simulation,
the reference search of ``tune-ctc`` (what ``--reveal`` and the selftest pay once per variant).
"""

from __future__ import annotations

import statistics
import time

from timing import median_seconds, p95, report

from tpm_viz.app.exercises.catalogue import by_id, listed
from tpm_viz.app.exercises.gains import reference as gains_reference
from tpm_viz.app.exercises.gains import verdict
from tpm_viz.app.exercises.grading import clear_caches, grade, variant_of
from tpm_viz.app.exercises.model import Kind
from tpm_viz.app.exercises.selftest import GARBAGE, perturbed, reference_text
from tpm_viz.paper.plant import closed_form_plant

SEEDS = range(20)
TARGETS = {Kind.NUMBER: 0.050, Kind.POSE: 0.050, Kind.CHOICE: 0.050, Kind.GAINS: 1.0}


def _gradings(ident: str) -> list[float]:
    exercise = by_id(ident).exercise
    times = []
    for seed in SEEDS:
        variant = variant_of(exercise, seed)
        answers = [reference_text(exercise, variant), perturbed(exercise, variant), GARBAGE[exercise.kind][0]]
        for text in answers:
            clear_caches()
            t0 = time.perf_counter()
            grade(exercise, variant, text)
            times.append(time.perf_counter() - t0)
    return times


def main() -> None:
    for item in listed():
        ex = item.exercise
        times = _gradings(ex.id)
        med, q95 = statistics.median(times), p95(times)
        target = TARGETS[ex.kind]
        print(
            f"{ex.id + ' (' + ex.kind.value + ')':<40} grade median {med * 1e3:8.2f} ms   p95 {q95 * 1e3:8.2f} ms"
            f"   target p95 {target * 1e3:6.0f} ms   ratio {q95 / target:5.2f}"
        )
    variant = variant_of(by_id("tune-ctc").exercise, 0)
    plant = closed_form_plant(variant.params)
    one = median_seconds(lambda: plant(0.02, -0.03, 0.4, 0.2, 50.0, -30.0), repeat=21, inner=500)
    report("closed-form plant p̈(p, ṗ, τ), one call (4 per RK4 step)", one, None, "µs", 1e6)

    def one_run() -> None:
        verdict.cache_clear()
        verdict(variant, 40.0, 1.0)

    report(
        "one verdict: 0.5 s of circle at 1 kHz, closed-form plant", median_seconds(one_run, repeat=11), None, "ms", 1e3
    )

    def search() -> None:
        clear_caches()
        gains_reference(variant)

    report("tune-ctc reference search (14 simulations)", median_seconds(search, repeat=5), None, "ms", 1e3)


if __name__ == "__main__":
    main()
