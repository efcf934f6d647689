"""The page calculator (``window.tpm``, :mod:`tpm_viz.exchange.c.calculator`) against the app, for any page that has it.

:func:`reference` answers each call as the app would, from the app's and the library's own functions (never from the
script's logic): the parameters as the app builds a set (``Params.paper().replace``, refused in
:mod:`tpm_viz.app.lesson_files`' words), a typed pair by :class:`tpm_viz.app.readouts.Load`'s rule, the pose as the app
places a trajectory sample (:func:`tpm_viz.app.moves.place`), the forces by :func:`tpm_viz.inverse_dynamics` and the
panel by :func:`tpm_viz.app.readouts.evaluate`. :func:`random_cases` draws seeded states over random parameter sets
(valid and not), :data:`RUN_JS` evaluates them all in one ``page.evaluate`` and :func:`compare` finds every
difference. Reused by the offline page's tests (issue 39).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tpm_viz.app import readouts
from tpm_viz.app.moves import Pose, place
from tpm_viz.core.errors import InputError, InvalidParametersError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.kinematics import forward_kinematics_both
from tpm_viz.paper.status import MOVE_LIMITS

FUNCTIONS = ("inverseKinematics", "inverseDynamics", "evaluate")
TOL = 1e-12
_ANYWHERE = Pose(np.zeros(2), np.zeros(2))  # the pose place() keeps on a refusal (only its words are used)


def _error(phrase: Phrase | str) -> dict[str, str]:
    if isinstance(phrase, str):
        return {"en": phrase, "ko": phrase}
    return {"en": phrase.render(Lang.EN), "ko": phrase.render(Lang.KO)}


def _state(given: dict, p: Any, motion: tuple[Any, Any] | None) -> tuple[Params, Pose] | dict[str, str]:
    """The parameter set and the placed pose, or the refusal (``motion``: ``(dp, ddp)`` to check too)."""
    try:
        params = Params.paper().replace(**given)
    except InvalidParametersError as exc:
        return _error(Phrase("parameters refused: {why}", why=readouts.reason(exc)))
    pairs = (("p", p),) if motion is None else (("p", p), ("dp", motion[0]), ("ddp", motion[1]))
    for name, value in pairs:
        try:
            readouts._vec2(value, name)  # the app's rule for a typed pair (Load's)
        except (InputError, TypeError) as exc:
            return _error(readouts.reason(exc))
    with np.errstate(over="ignore"):  # ik_branch squares p without silencing an overflow (p = 1e308): NaN, refused
        move = place(params, _ANYWHERE, p)
    if move.clamped:
        return _error(move.reason)
    return params, move.pose


def reference(function: str, given: dict, p: Any, dp: Any = None, ddp: Any = None) -> dict[str, Any]:
    """What ``window.tpm[function](given, p, dp, ddp)`` must return (``error`` holds both languages)."""
    state = _state(given, p, None if function == "inverseKinematics" else (dp, ddp))
    if isinstance(state, dict):
        return {"error": state}
    params, pose = state
    if function == "inverseKinematics":
        return {"d": pose.d.tolist()}
    try:
        tau = inverse_dynamics(params, pose.p, dp, ddp)
    except TpmVizError as exc:
        return {"error": _error(readouts.reason(exc))}
    if function == "inverseDynamics":
        return {"tau": tau.tolist()}
    out = readouts.evaluate(params, pose, readouts.Load("dynamic", dp=tuple(dp), ddp=tuple(ddp)))
    return {
        "d": out.d.tolist(),
        "theta": out.theta.tolist(),
        "detJx": out.det_jx,
        "detJq": out.det_jq,
        "cond": out.cond,
        "tau": tau.tolist(),
        "mode": out.mode,
    }


# ------------------------------------------------------------------------------------------------ random cases
BAD_VALUES = (math.nan, math.inf, -math.inf, 1e308, -1e308, 0.0, -0.1, 1e-12, 1e9, "0.3", True, None)


def _params_dict(rng: np.random.Generator) -> dict[str, Any]:
    """A parameter set as a page passes it: some keys (the rest default), mostly valid, a fifth not."""
    la = rng.uniform(0.12, 0.5)
    full = {
        "a": rng.uniform(0.2, 1.0),
        "b": rng.uniform(0.02, 0.2),
        "l_a": la,
        "stroke": rng.uniform(0.1, 0.8),
        "pivot_spacing": 0.2 * la,
        "m_a": rng.uniform(0.05, 10),
        "m_b": rng.uniform(0.05, 10),
        "m_p": rng.uniform(0.05, 10),
    }
    keys = [k for k in full if rng.random() < 0.7]
    given = {k: float(full[k]) for k in keys}
    roll = rng.random()
    if roll < 0.1:
        given[str(rng.choice(list(full)))] = BAD_VALUES[rng.integers(len(BAD_VALUES))]
    elif roll < 0.15:
        given["stroke"] = float(rng.uniform(0.001, 0.05))  # a geometry with no pose inside the stroke, often
        given["a"] = float(rng.uniform(0.6, 1.5))
    elif roll < 0.17:
        given["pivot_spacing"] = given.get("l_a", 0.26) * 1.1
    elif roll < 0.18:
        given["colour"] = 1.0
    return given


def _pose(rng: np.random.Generator, params: Params | None) -> list[float]:
    """Inside the stroke (the forward kinematics of actuators drawn inside it), anywhere (reachable and not), near
    the inverse margin (``|cos θ_i|`` within 20 % of it) and near the direct one."""
    la = params.l_a if params is not None else 0.26
    kind = rng.random()
    for _ in range(8 if kind < 0.5 and params is not None else 0):
        assert params is not None
        d = rng.uniform(0.0, params.stroke, 2)
        with np.errstate(all="ignore"):
            sol = forward_kinematics_both(params, d)
        if bool(sol.exists):
            return (sol.plus if rng.random() < 0.9 else sol.minus).tolist()
    if kind < 0.7:
        return rng.uniform(-1.05 * la, 1.05 * la, 2).tolist()
    if kind < 0.85:
        k = MOVE_LIMITS.inverse * rng.uniform(0.8, 1.2)
        pj = la * math.sqrt(1 - k * k) * rng.choice([-1.0, 1.0])
        pi = rng.uniform(-0.6 * la, 0.6 * la)
        return [pi, pj] if rng.random() < 0.5 else [pj, pi]
    m = MOVE_LIMITS.direct * rng.uniform(0.8, 1.2) * rng.choice([-1.0, 1.0])
    half = 0.5 * math.acos(m) + rng.normal(0, 0.01)  # θ1 ≈ θ2 ≈ half: cos(θ1 + θ2) ≈ m
    sign = 1.0 if m > 0 else -1.0
    return [sign * la * math.sin(half), sign * la * math.sin(half + rng.normal(0, 0.02))]


def random_cases(seed: int, sets: int, per: int) -> list[dict[str, Any]]:
    """``sets * per`` seeded cases ``{params, p, dp, ddp}`` (p, dp, ddp mostly finite pairs, a few not)."""
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(sets):
        given = _params_dict(rng)
        try:
            params: Params | None = Params.paper().replace(**given)
        except (InvalidParametersError, TypeError):
            params = None
        for _ in range(per):
            case = {"params": given, "p": _pose(rng, params), "dp": rng.uniform(-2, 2, 2).tolist()}
            case["ddp"] = rng.uniform(-30, 30, 2).tolist()
            if rng.random() < 0.01:
                case[str(rng.choice(["p", "dp", "ddp"]))] = [float(rng.choice([math.nan, math.inf, 1e308])), 0.1]
            cases.append(case)
    return cases


RUN_JS = """
async (cases) => {
  const tpm = await window.tpmReady;
  const out = [];
  for (const c of cases) {
    out.push({
      inverseKinematics: tpm.inverseKinematics(c.params, c.p),
      inverseDynamics: tpm.inverseDynamics(c.params, c.p, c.dp, c.ddp),
      inverseDynamicsKo: tpm.inverseDynamics(c.params, c.p, c.dp, c.ddp, {lang: "ko"}),
      evaluate: tpm.evaluate(c.params, c.p, c.dp, c.ddp),
    });
  }
  return out;
}
"""
"""``page.evaluate(RUN_JS, cases)``: every function on every case, in one call."""


def _numbers(result: dict[str, Any]) -> list[float]:
    flat: list[float] = []
    for key, value in result.items():
        if key in ("error", "near"):
            continue
        flat += value if isinstance(value, list) else [value]
    return flat


def _relative(got: Any, want: Any, floor: float) -> float:
    if want is None or got is None:
        return 0.0 if got is None and want is None else math.inf
    g, w = np.atleast_1d(np.asarray(got, float)), np.atleast_1d(np.asarray(want, float))
    return float(np.max(np.abs(g - w)) / max(float(np.max(np.abs(w))), floor))


FLOORS = {"d": 1e-3, "tau": 1e-9, "theta": 1.0, "detJx": 1.0, "detJq": 1.0, "cond": 1.0, "mode": 1.0}
"""Norm-wise relative errors: ``max |got - want| / max(max |want|, floor)`` (floors: 1 mm, 1 nN, 1 rad, 1)."""


def compare(cases: list[dict[str, Any]], got: list[dict[str, Any]]) -> dict[str, Any]:
    """Every disagreement between the page's answers ``got`` and :func:`reference`, with the worst relative error per
    quantity and how many answers were refusals: ``{"problems": [...], "worst": {...}, "refused": {...}}``."""
    problems: list[str] = []
    worst = dict.fromkeys(FLOORS, 0.0)
    refused = dict.fromkeys(FUNCTIONS, 0)
    for k, (case, answer) in enumerate(zip(cases, got, strict=True)):
        for function in FUNCTIONS:
            want = reference(function, case["params"], case["p"], case["dp"], case["ddp"])
            have = answer[function]
            if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in _numbers(have) if x is not None):
                problems.append(f"{k} {function}: a number that is not finite: {have}")
            if ("error" in want) != ("error" in have):
                problems.append(f"{k} {function}: page {have} but app {want} for {case}")
                continue
            if "error" in want:
                refused[function] += 1
                if have["error"] != want["error"]["en"]:
                    problems.append(f"{k} {function}: words {have['error']!r} != {want['error']['en']!r}")
                if function == "inverseDynamics" and answer["inverseDynamicsKo"]["error"] != want["error"]["ko"]:
                    problems.append(f"{k} ko: {answer['inverseDynamicsKo']['error']!r} != {want['error']['ko']!r}")
                continue
            for key, value in want.items():
                err = _relative(have.get(key), value, FLOORS[key])
                worst[key] = max(worst[key], err)
                if not err <= TOL:
                    problems.append(f"{k} {function} {key}: {have.get(key)} != {value} (relative {err:.2e})")
    return {"problems": problems, "worst": worst, "refused": refused}
