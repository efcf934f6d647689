"""The margin of ``tpm_params`` (issue 35, item 11): near a singularity the generated C refuses with its codes instead
of returning absurd forces, by the app's own rules; just outside the margin it gives the Python closed form's numbers.

Poses are built a relative 1e-7 either side of the margin on the quantity it bounds (``cos θ_i``, ``det J_x``); on
which side each lies is read from the app's functions (:func:`tpm_viz.app.moves.margins`, the rule of its drags, and
:func:`tpm_viz.paper.jacobians.pose_status` for the parallel arrangement), not from the C.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.support import cbuild
from tpm_viz.app.moves import margins
from tpm_viz.core.params import Params
from tpm_viz.paper import parallel
from tpm_viz.paper.control import ControlLaw, ControllerKind, Gains
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.jacobians import pose_status
from tpm_viz.paper.kinematics import inverse_kinematics
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus

STEP = 1e-7
"""Relative distance of a test pose from the edge of the margin, on ``cos θ_i`` or ``det J_x``."""
RC_J, RC_ID, RC_FD, RC_CTC = 7, 10, 13, 16
PAR_RC_J, PAR_RC_ID, PAR_RC_FD = 25, 28, 31
OUTPUTS = {RC_J: [3, 4, 5, 6], RC_ID: [8, 9], RC_FD: [11, 12], RC_CTC: [14, 15]}
PAR_OUTPUTS = {PAR_RC_J: [21, 22, 23, 24], PAR_RC_ID: [26, 27], PAR_RC_FD: [29, 30]}
DEFAULT = (MOVE_LIMITS.inverse, MOVE_LIMITS.direct)


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    assert cbuild.cc() is not None, "these tests need a C compiler: Debian packages gcc and libc6-dev"
    return cbuild.load(cbuild.export(tmp_path_factory.mktemp("cmargin")))


def perpendicular_poses(params: Params, margin: tuple[float, float], side: float) -> tuple[np.ndarray, list[int]]:
    """Poses ``side`` (-1 inside, +1 outside) of the margin, and the code each gets inside: leg 1 and leg 2 at
    ``cos θ_i = min_cos (1 + side STEP)``, and ``cos(θ1 + θ2) = ±min_det (1 + side STEP)`` with ``θ1 = θ2`` (first
    quadrant, the leg circles coincide; third quadrant, beyond the arc where the assembly modes merge)."""
    la, (k, m) = params.l_a, margin
    cos = k * (1 + side * STEP)
    inverse = [(0.3 * la, la * math.sqrt(1 - cos**2)), (la * math.sqrt(1 - cos**2), -0.25 * la)]
    half_plus = 0.5 * math.acos(m * (1 + side * STEP))  # θ1 = θ2: cos(θ1 + θ2) = cos 2θ
    half_minus = 0.5 * math.acos(-m * (1 + side * STEP))
    direct = [(la * math.sin(half_plus),) * 2, (-la * math.sin(half_minus),) * 2]
    return np.array(inverse + direct), [3, 3, 4, 4]


def parallel_poses(params: Params, margin: tuple[float, float], side: float) -> tuple[np.ndarray, list[int]]:
    """The same for the parallel arrangement: ``cos θ_1 = cos θ_2 = sqrt(1 - (p_2/l_a)²)`` at the inverse margin,
    ``|sin(θ1 + θ2)| = |sin 2θ|`` at the direct one, above and below the rails."""
    la, (k, m) = params.l_a, margin
    p2_inverse = la * math.sqrt(1 - (k * (1 + side * STEP)) ** 2)
    p2_direct = la * math.sin(0.5 * math.asin(m * (1 + side * STEP)))
    poses = [(0.05, p2_inverse), (-0.02, -p2_inverse), (0.03, p2_direct), (0.0, -p2_direct)]
    return np.array(poses), [3, 3, 4, 4]


def rows_for(params: Params, poses: np.ndarray, tau_in: np.ndarray, margin: tuple[float, float]) -> np.ndarray:
    """Harness rows: the poses, a moving state with a load, 10 Hz gains, the reference on the pose."""
    n = len(poses)
    dp, ddp, f = np.tile([0.3, -0.2], (n, 1)), np.tile([2.0, 1.0], (n, 1)), np.tile([5.0, -3.0], (n, 1))
    gains = Gains(wn=2 * math.pi * 10, zeta=1.0)
    cols = [np.tile(cbuild.params_row(params), (n, 1)), poses, dp, ddp, f, np.full((n, 2), gains.kp)]
    cols += [np.full((n, 2), gains.kd), poses, dp, ddp, tau_in, np.tile(margin, (n, 1))]
    return np.concatenate(cols, axis=1)


def app_side(params: Params, poses: np.ndarray, margin: tuple[float, float]) -> np.ndarray:
    """Per pose, the smallest singularity margin of the app's drag rule (negative inside), working mode."""
    d = inverse_kinematics(params, poses)
    c = poses - d + params.offset
    mode = np.where(c[:, 0] * c[:, 1] - poses[:, 0] * poses[:, 1] >= 0, 1, -1)
    limits = MOVE_LIMITS._replace(inverse=margin[0], direct=margin[1])
    return np.array([margins(params, p, dd, int(s), limits)[2:].min() for p, dd, s in zip(poses, d, mode, strict=True)])


def rel(c, py) -> float:
    return float(np.max(np.abs(c - py)) / np.max(np.abs(py)))


PARAMS = [Params.paper(), *(cbuild.random_params(np.random.default_rng(seed)) for seed in (11, 12, 13))]


@pytest.mark.parametrize("margin", [DEFAULT, (0.1, 0.15)], ids=["app-move-limits", "wider"])
@pytest.mark.parametrize("params", PARAMS, ids=["paper", "random-11", "random-12", "random-13"])
def test_just_inside_the_margin_is_refused_and_just_outside_gives_the_python_numbers(lib, params, margin):
    law = ControlLaw(ControllerKind.CTC, params, Gains(wn=2 * math.pi * 10, zeta=1.0)).force_function()
    for side in (-1.0, 1.0):
        poses, codes = perpendicular_poses(params, margin, side)
        assert np.all(np.sign(app_side(params, poses, margin)) == side)  # the app puts them on that side
        rows = rows_for(params, poses, np.tile([10.0, 20.0], (len(poses), 1)), margin)
        out = cbuild.run_batch(lib, rows)
        for k, code in enumerate(codes):
            if side < 0:
                expected = {RC_J: code if code == 3 else 0, RC_ID: code, RC_FD: code, RC_CTC: code}
                assert {rc: out[k, rc] for rc in expected} == expected, (poses[k], out[k])
                for rc, cols in OUTPUTS.items():
                    if expected[rc]:
                        assert np.all(out[k, cols] == cbuild.SENTINEL)  # nothing written
                continue
            assert np.all(out[k, [RC_J, RC_ID, RC_FD, RC_CTC]] == 0), (poses[k], out[k])
            tau = inverse_dynamics(params, poses[k], rows[k, 9:11], rows[k, 11:13], rows[k, 13:15])
            assert rel(out[k, 8:10], tau) <= 1e-12
            ctc = law((*poses[k], *rows[k, 9:13], 0, 0, 0, 0, 0, 0), *poses[k], *rows[k, 9:11])[:2]
            assert rel(out[k, 14:16], ctc) <= 1e-12
        if side > 0:  # the forward dynamics inverts the inverse just outside the margin
            fd = cbuild.run_batch(lib, rows_for(params, poses, out[:, 8:10], margin))
            assert rel(fd[:, 11:13], rows[:, 11:13]) <= 1e-9


@pytest.mark.parametrize("margin", [DEFAULT, (0.1, 0.15)], ids=["app-move-limits", "wider"])
@pytest.mark.parametrize("params", PARAMS, ids=["paper", "random-11", "random-12", "random-13"])
def test_the_parallel_arrangement_has_the_same_margin(lib, params, margin):
    limits = MOVE_LIMITS._replace(inverse=margin[0], direct=margin[1])
    for side in (-1.0, 1.0):
        poses, codes = parallel_poses(params, margin, side)
        jac = parallel.jacobians(params, poses)
        status = pose_status(np.ones(len(poses), bool), jac, np.ones(len(poses), bool), limits)
        app = [PoseStatus.NEAR_INVERSE] * 2 + [PoseStatus.NEAR_DIRECT] * 2 if side < 0 else [PoseStatus.REGULAR] * 4
        assert list(status) == app
        rows = rows_for(params, poses, np.tile([10.0, 20.0], (len(poses), 1)), margin)
        out = cbuild.run_batch(lib, rows)
        for k, code in enumerate(codes):
            if side < 0:
                expected = {PAR_RC_J: code if code == 3 else 0, PAR_RC_ID: code, PAR_RC_FD: code}
                assert {rc: out[k, rc] for rc in expected} == expected, (poses[k], out[k])
                for rc, cols in PAR_OUTPUTS.items():
                    if expected[rc]:
                        assert np.all(out[k, cols] == cbuild.SENTINEL)
                continue
            assert np.all(out[k, [PAR_RC_J, PAR_RC_ID, PAR_RC_FD]] == 0), (poses[k], out[k])
            tau = parallel.inverse_dynamics(params, poses[k], rows[k, 9:11], rows[k, 11:13], rows[k, 13:15])
            assert rel(out[k, 26:28], tau) <= 1e-12


def test_inside_the_margin_the_unguarded_closed_form_gives_absurd_forces(lib):
    """Why the margin exists: the same pose a hair from the inverse singularity, with the margin off, returns
    forces three orders above the paper's peak (177 N) for a modest state; the margin refuses it."""
    params = Params.paper()
    la = params.l_a
    poses = np.array([(0.3 * la, la * math.sqrt(1 - 1e-6**2))])  # cos θ1 = 1e-6
    rows = rows_for(params, poses, np.zeros((1, 2)), DEFAULT)
    assert cbuild.run_batch(lib, rows)[0, RC_ID] == 3
    unguarded = cbuild.run_batch(lib, rows[:, :27])  # the tests' negligible margin
    assert unguarded[0, RC_ID] == 0 and np.max(np.abs(unguarded[0, 8:10])) > 1e5


def test_a_margin_outside_0_1_is_a_parameter_error(lib):
    params = Params.paper()
    rows = rows_for(params, np.array([(0.01, 0.02)]), np.zeros((1, 2)), DEFAULT)
    for bad in ((0.0, 0.03), (0.03, 0.0), (-0.1, 0.03), (1.0, 0.03), (0.03, 1.5), (math.nan, 0.03), (0.03, math.inf)):
        row = rows.copy()
        row[0, 27:29] = bad
        out = cbuild.run_batch(lib, row)
        # every function checks the whole struct, those that do not apply the margin too (a configuration error)
        assert np.all(out[0, [2, RC_J, RC_ID, RC_FD, RC_CTC, 17, 20, PAR_RC_J, PAR_RC_ID, PAR_RC_FD]] == 7), bad


def test_the_forces_docs_realtime_quotes_near_the_singularities():
    """The figures of docs/realtime.md's *The margin* (paper's parameters, the state of this file's rows)."""
    text = (Path(__file__).resolve().parents[3] / "docs" / "realtime.md").read_text()
    params = Params.paper()
    la = params.l_a
    state = ((0.3, -0.2), (2.0, 1.0), (5.0, -3.0))
    assert f"{math.hypot(*state[2]):.1f} N load" in text
    shown = {0.2: ("29 N", 29.0), 0.03: ("7.0 kN", 7.0e3), 1e-3: ("1.9e8 N", 1.9e8), 1e-6: ("1.9e17 N", 1.9e17)}
    for k, (words, value) in shown.items():
        peak = np.max(np.abs(inverse_dynamics(params, (0.3 * la, la * math.sqrt(1 - k * k)), *state)))
        assert words in text and f"{peak:.2g}" == f"{value:.2g}", (k, peak)
    for m, (words, value) in {0.03: ("96 N", 96.0), 1e-6: ("2.7e6 N", 2.7e6)}.items():
        half = 0.5 * math.acos(m)
        peak = np.max(np.abs(inverse_dynamics(params, (la * math.sin(half),) * 2, *state)))
        assert words in text and f"{peak:.2g}" == f"{value:.2g}", (m, peak)
