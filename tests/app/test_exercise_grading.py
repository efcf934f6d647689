"""Grading with PrairieLearn's semantics, over seeds and answers (Hypothesis).

Perturbations inside the tolerance score 1, outside less; the same answer typed as people type it (a decimal comma,
the Unicode minus, another unit of the quantity) scores the same; each declared mistake is recognised in an answer
built by an independent route (Pinocchio for τ₂, ``J⁻ᵀ m_p p̈`` by eq. 13, the formulas of the paper); a pose scores
1 exactly when Pinocchio's τ1 there is within the tolerance and the pose is clear of both singularities; format
errors use no attempt; the ladder and the best score.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from tests.support.hypo import examples
from tpm_viz.app.exercises.catalogue import by_id, listed
from tpm_viz.app.exercises.grading import grade, reference, shown_values, tolerance, variant_of
from tpm_viz.app.exercises.model import AttemptRule, Kind, Result
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Lang
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces
from tpm_viz.paper.jacobians import actuator_forces_from_platform_force

NUMBERS = [item.exercise.id for item in listed() if item.exercise.kind is Kind.NUMBER]
SEEDS = st.integers(0, 10**6)


def _setup(ident: str, seed: int):
    exercise = by_id(ident).exercise
    variant = variant_of(exercise, seed)
    ref = reference(exercise, variant)
    return exercise, variant, ref


@pytest.mark.parametrize("ident", NUMBERS)
@settings(max_examples=examples(60))
@given(seed=SEEDS, f=st.floats(-0.99, 0.99))
def test_inside_the_tolerance_scores_one(ident, seed, f):
    exercise, variant, (ref,) = _setup(ident, seed)
    rtol, atol = tolerance(exercise, variant)
    result = grade(exercise, variant, repr(ref + f * (atol + rtol * abs(ref))))
    assert (result.score, result.attempts_used, str(result.feedback)) == (1.0, 1, "correct")


@pytest.mark.parametrize("ident", NUMBERS)
@settings(max_examples=examples(60))
@given(seed=SEEDS, g=st.floats(1.01, 1e3), sign=st.sampled_from([-1.0, 1.0]))
def test_outside_the_tolerance_scores_less(ident, seed, g, sign):
    exercise, variant, (ref,) = _setup(ident, seed)
    rtol, atol = tolerance(exercise, variant)
    result = grade(exercise, variant, repr(ref + sign * g * (atol + rtol * abs(ref))))
    assert result.format_error is None and result.attempts_used == 1
    assert result.score is not None and result.score < 1.0


_OTHER_UNIT = {"mm": ("m", 1e-3), "N": ("kN", 1e-3), "deg": ("rad", math.pi / 180)}


@pytest.mark.parametrize("ident", NUMBERS)
@settings(max_examples=examples(30))
@given(seed=SEEDS)
def test_typed_as_people_type_it(ident, seed):
    exercise, variant, (ref,) = _setup(ident, seed)
    unit, scale = _OTHER_UNIT[exercise.unit]
    comma = f"{ref:.6f}".replace(".", ",").replace("-", "\u2212")
    for text in (comma, f"{ref!r} {exercise.unit}", f"{ref * scale!r} {unit}", f"  {ref:.6e}  "):
        assert grade(exercise, variant, text).score == 1.0, text


def _mistaken(ident: str, variant) -> dict[str, float]:
    """Wrong answers as students make them, by mistake (a factor or the other computation's name), from
    independent routes."""
    prm = variant.params
    la, k = prm.l_a * 1e3, (prm.a - prm.b) * 1e3
    if ident == "direct-singularity-diagonal":
        x = -la / math.sqrt(2)
        return {
            "-1.0": -x,
            "minus_l_a": -la,
            "l_a": la,
            "diagonal_singularity_d": k - math.sqrt(2) * la,
            "0.001": x / 1e3,
        }
    if ident == "force-at-pose":
        p, ddp = np.array([variant["p1"], variant["p2"]]), np.array([variant["ddp1"], variant["ddp2"]])
        tau = pinocchio_forces(prm, p, np.zeros(2), ddp)
        platform = actuator_forces_from_platform_force(prm, p, prm.m_p * ddp)  # eq. (13), f = m_p p̈
        return {"-1.0": -tau[0], "tau2": tau[1], "tau1_platform_only": platform[0], "0.001": tau[0] / 1e3}
    if ident == "actuator-position":
        p1, p2 = variant["p1"] * 1e3, variant["p2"] * 1e3
        root = math.sqrt(la**2 - p2**2)
        return {
            "d1_other_branch": p1 + k + root,
            "d2": p2 + k - math.sqrt(la**2 - p1**2),
            "d1_no_offset": p1 - root,
            "0.001": (p1 + k - root) / 1e3,
        }
    if ident == "peak-force-scaling":
        peak2 = reference(by_id(ident).exercise, variant)[0]
        peak1, r = peak2 * (variant["t2"] / variant["t1"]) ** 2, variant["t1"] / variant["t2"]
        return {
            "circle_peak_linear": peak1 * r,
            "circle_peak_inverse": peak1 / r**2,
            "circle_peak_t1": peak1,
            "0.001": peak2 / 1e3,
        }
    if ident == "modes-merge-stroke":
        return {"diagonal_singularity": -la / math.sqrt(2), "l_a": la, "0.001": (k - math.sqrt(2) * la) / 1e3}
    assert ident == "leg-angle"
    t1 = math.asin(variant["p2"] / prm.l_a)
    return {
        "0.017453292519943295": t1,
        "theta2": math.degrees(math.asin(variant["p1"] / prm.l_a)),
        "theta1_from_e2": 90.0 - math.degrees(t1),
        "-1.0": -math.degrees(t1),
    }


@pytest.mark.parametrize("ident", NUMBERS)
def test_each_declared_mistake_is_recognised(ident):
    exercise = by_id(ident).exercise
    for mistake in exercise.mistakes:
        name = mistake.answer or repr(mistake.factor)
        for seed in range(40):
            variant = variant_of(exercise, seed)
            rtol, atol = tolerance(exercise, variant)
            answers = _mistaken(ident, variant)
            wrong, ref = answers[name], reference(exercise, variant)[0]
            others = [ref] + [v for k, v in answers.items() if k != name]
            if all(abs(wrong - o) > 3 * (atol + rtol * abs(o)) + 3e-3 * abs(o) for o in others):
                break
        else:
            pytest.fail(f"{ident}: no seed separates the mistake {name}")
        result = grade(exercise, variant, repr(float(wrong)))
        assert result.score == mistake.score, (name, str(result.format_error or result.feedback))
        said = mistake.feedback.phrase(**shown_values(exercise, variant))  # its {placeholders} filled
        assert result.feedback is not None and result.feedback.render(Lang.EN) == said.render(Lang.EN)
        assert result.feedback.render(Lang.KO) == said.render(Lang.KO) != said.render(Lang.EN)


def _zero_on_row(variant, y: float) -> float | None:
    """An x with Pinocchio's τ1(x, y) = 0 at the variant's p̈ (ṗ = 0) between two poses clear of the
    singularities, by brentq on a sign change."""
    ddp = np.array([variant["ddp1"], variant["ddp2"]])
    la = variant.params.l_a
    xs = [x for x in np.linspace(-0.95 * la, 0.95 * la, 96) if _clear(variant, np.array([x, y]))]
    if len(xs) < 2:
        return None
    points = np.array([[x, y] for x in xs])
    tau = pinocchio_forces(variant.params, points, np.zeros_like(points), np.broadcast_to(ddp, points.shape))[:, 0]
    change = [i for i in range(len(xs) - 1) if tau[i] * tau[i + 1] <= 0 and xs[i + 1] - xs[i] < 0.02 * la]
    if not change:
        return None

    def f(x):
        return float(pinocchio_forces(variant.params, np.array([x, y]), np.zeros(2), ddp)[0])

    return float(brentq(f, xs[change[0]], xs[change[0] + 1], xtol=1e-12))


def _clear(variant, p) -> bool:
    """Inside the stroke, the working mode, and clear of both singularities by the warning thresholds with room."""
    prm = variant.params
    c = np.sqrt(prm.l_a**2 - p[::-1] ** 2)
    d = p + prm.a - prm.b - c
    det = (c[0] * c[1] - p[0] * p[1]) / prm.l_a**2
    return bool(np.all((d > 1e-6) & (d < prm.stroke - 1e-6)) and np.min(c) / prm.l_a > 0.2 + 1e-6 and det > 0.2 + 1e-6)


@settings(max_examples=examples(40))
@given(seed=SEEDS, y=st.floats(-0.2, 0.2))
def test_every_correct_pose_scores(seed, y):
    exercise, variant, _ = _setup("zero-force-pose", seed)
    x = _zero_on_row(variant, y)
    assume(x is not None and _clear(variant, np.array([x, y])))
    result = grade(exercise, variant, f"{x * 1e3!r}; {y * 1e3!r}")
    assert result.score == 1.0, str(result.format_error or result.feedback)


@settings(max_examples=examples(60))
@given(seed=SEEDS, p=st.tuples(st.floats(-0.25, 0.25), st.floats(-0.25, 0.25)))
def test_a_pose_scores_as_pinocchio_says(seed, p):
    exercise, variant, _ = _setup("zero-force-pose", seed)
    pose = np.array(p)
    result = grade(exercise, variant, f"{p[0] * 1e3!r}; {p[1] * 1e3!r}")
    prm = variant.params
    if np.any(np.abs(pose) >= prm.l_a) or not np.all(np.isfinite(np.sqrt(prm.l_a**2 - pose**2))):
        assert result.format_error is not None and result.attempts_used == 0
        return
    c = np.sqrt(prm.l_a**2 - pose[::-1] ** 2)
    d = pose + prm.a - prm.b - c
    det = (c[0] * c[1] - pose[0] * pose[1]) / prm.l_a**2
    if np.any(d < -1e-9) or np.any(d > prm.stroke + 1e-9) or det <= 0:
        assert result.format_error is not None and result.attempts_used == 0 and result.score is None
        return
    assume(np.all(np.abs(d - np.clip(d, 0, prm.stroke)) < 1e-12))
    assert result.format_error is None and result.attempts_used == 1
    tau1 = pinocchio_forces(prm, pose, np.zeros(2), np.array([variant["ddp1"], variant["ddp2"]]))[0]
    near = np.min(c) / prm.l_a < 0.2 or det < 0.2
    assume(abs(abs(tau1) - variant["tol"]) > 1e-6 and abs(np.min(c) / prm.l_a - 0.2) > 1e-9 and abs(det - 0.2) > 1e-9)
    if near:
        assert result.score == 0.0 and "near the" in str(result.feedback)
    else:
        assert (result.score == 1.0) == (abs(tau1) <= variant["tol"])


def test_a_pose_typed_in_metres_is_recognised():
    exercise, variant, ref = _setup("zero-force-pose", 3)
    result = grade(exercise, variant, f"{ref[0] / 1e3!r}; {ref[1] / 1e3!r}")
    assert result.score == 0.0 and "metres" in str(result.feedback)
    assert grade(exercise, variant, f"{ref[0] / 1e3!r} m; {ref[1] / 1e3!r} m").score == 1.0


def test_gains_graded_with_feedback():
    exercise, variant, (wn, zeta) = _setup("tune-ctc", 1)
    right = grade(exercise, variant, f"{wn}; {zeta}")
    assert right.score == 1.0 and str(right.feedback).startswith("correct: RMS error")
    omega = grade(exercise, variant, f"{2 * math.pi * wn}; {zeta}")
    assert omega.score == 0.0 and "rad/s" in str(omega.feedback)
    assert grade(exercise, variant, f"{2 * math.pi * wn} rad/s; {zeta}").score == 1.0
    soft = grade(exercise, variant, "1; 1")
    assert soft.score == 0.0 and "too soft" in str(soft.feedback)
    assert "이득이 너무 작습니다" in soft.feedback.render(Lang.KO)


def test_the_ladder_and_format_errors():
    exercise, variant, (ref,) = _setup("force-at-pose", 5)
    assert exercise.attempts == AttemptRule((1.0, 0.7, 0.5))
    scores = [grade(exercise, variant, repr(ref), k).score for k in (1, 2, 3)]
    assert scores == [1.0, 0.7, 0.5]
    assert [grade(exercise, variant, repr(ref), k).attempts_left for k in (1, 2, 3)] == [2, 1, 0]
    with pytest.raises(InputError, match="allows 3 attempts"):
        grade(exercise, variant, repr(ref), 4)
    bad = grade(exercise, variant, "twelve", 2)
    assert (bad.score, bad.attempts_used, bad.attempts_left, bad.feedback) == (None, 0, 2, None)
    assert "not a number" in str(bad.format_error) and bad.json()["score"] is None
    half = grade(exercise, variant, repr(-ref), 2)  # the sign mistake: 0.5, then the ladder's 0.7
    assert half.raw == 0.5 and half.score == pytest.approx(0.35)
    homework = by_id("zero-force-pose").exercise
    assert homework.attempts.max_attempts is None
    hv = variant_of(homework, 0)
    assert grade(homework, hv, "; ".join(map(repr, reference(homework, hv))), 100).score == 1.0
    assert AttemptRule.best([0.35, None, 0.5, 0.2]) == 0.5 and AttemptRule.latest([0.35, 0.5, None]) == 0.5
    assert AttemptRule.best([None]) is None


@pytest.mark.parametrize("ident", [item.exercise.id for item in listed()])
def test_grading_is_deterministic(ident):
    exercise = by_id(ident).exercise
    variant = variant_of(exercise, 2)
    for text in ("12", "1; 2", "leg 1", "nonsense"):
        assert grade(exercise, variant, text) == grade(exercise, variant, text)


def test_a_result_record_is_bounded():
    kept = Result("c:abc", "force-at-pose", 7, 1, "x" * 500, 0.7, 1.0)
    assert len(kept.answer) == 200
    with pytest.raises(InputError):
        Result("c:abc", "force-at-pose", 7, 1, "1", 1.5, 1.0)
