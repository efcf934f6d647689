"""The generated C (issue 27) against the Python it is traced from: compiled with the strict flags, called
through ctypes on seeded random states and parameter sets, on the refusal boundaries, and under the sanitizers.

Errors are norm-wise relative per state: ``max_i |x_C - x_Py| / max(max_i |x_Py|, floor)`` (floor: ``l_a`` for
actuator positions, 1 for the Jacobian whose diagonal is 1, 1 m/s² for accelerations).
"""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from tests.support import cbuild
from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.params import Params
from tpm_viz.paper.control import ControlLaw, ControllerKind, Gains, task_space_command
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.kinematics import in_stroke, inverse_kinematics

TOL = 1e-12


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    assert cbuild.cc() is not None, "these tests need a C compiler: Debian packages gcc and libc6-dev"
    return cbuild.load(cbuild.export(tmp_path_factory.mktemp("c")))


def regular_group(params: Params, n: int, rng):
    """``n`` seeded rows for one parameter set: regular poses (cos θ_i, det J_x above 0.25), equal gains per axis."""
    la = params.l_a
    p = np.empty((0, 2))
    while len(p) < n:
        cand = rng.uniform(-0.85 * la, 0.85 * la, (2 * n, 2))
        cos1, cos2 = np.sqrt(1 - (cand[:, 1] / la) ** 2), np.sqrt(1 - (cand[:, 0] / la) ** 2)
        ok = (np.minimum(cos1, cos2) > 0.25) & (np.abs(cos1 * cos2 - cand[:, 0] * cand[:, 1] / la**2) > 0.25)
        p = np.concatenate([p, cand[ok]])
    p = p[:n]
    dp, ddp, f = rng.uniform(-2, 2, (n, 2)), rng.uniform(-30, 30, (n, 2)), rng.normal(0, 20, (n, 2))
    gains = Gains(wn=rng.uniform(2, 50), zeta=rng.uniform(0.5, 1.5))
    kp, kd = np.full((n, 2), gains.kp), np.full((n, 2), gains.kd)
    p_ref, dp_ref = p + rng.normal(0, 0.005, (n, 2)), dp + rng.normal(0, 0.05, (n, 2))
    ddp_ref = rng.uniform(-30, 30, (n, 2))
    tau = inverse_dynamics(params, p, dp, ddp, f)
    prm = np.tile(cbuild.params_row(params), (n, 1))
    rows = np.concatenate([prm, p, dp, ddp, f, kp, kd, p_ref, dp_ref, ddp_ref, tau], axis=1)
    return rows, gains, tau


def rel(c, py, floor) -> np.ndarray:
    return np.max(np.abs(c - py), axis=1) / np.maximum(np.max(np.abs(py), axis=1), floor)


def check_against_python(lib, groups: int, per: int, ctc_every: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    worst = dict.fromkeys(("ik", "jac", "id", "fd", "ctc"), 0.0)
    for _ in range(groups):
        params = cbuild.random_params(rng)
        rows, gains, tau = regular_group(params, per, rng)
        out = cbuild.run_batch(lib, rows)
        assert not np.any(np.isnan(out))
        assert np.all(out[:, [2, 7, 10, 13, 16]] == 0)  # every regular state is accepted
        p, ddp = rows[:, 7:9], rows[:, 11:13]
        worst["ik"] = max(worst["ik"], rel(out[:, 0:2], inverse_kinematics(params, p), params.l_a).max())
        worst["jac"] = max(worst["jac"], rel(out[:, 3:7], jacobians(params, p).j.reshape(-1, 4), 1.0).max())
        worst["id"] = max(worst["id"], rel(out[:, 8:10], tau, 0.0).max())
        worst["fd"] = max(worst["fd"], rel(out[:, 11:13], ddp, 1.0).max())
        law = ControlLaw(ControllerKind.CTC, params, gains).force_function()
        for k in range(0, per, ctc_every):
            r = rows[k]
            py = law((*r[19:25], 0, 0, 0, 0, 0, 0), r[7], r[8], r[9], r[10])[:2]
            err = np.max(np.abs(out[k, 14:16] - py)) / np.max(np.abs(py))
            worst["ctc"] = max(worst["ctc"], err)
        stroke = in_stroke(params, p)  # the harness checks p read as actuator positions
        assert np.array_equal(out[:, 17] == 0, stroke) and set(np.unique(out[:, 17])) <= {0, 5}
    print("worst relative errors", worst)
    assert max(worst.values()) <= TOL, worst


def test_the_strict_flags_compile_it_and_a_sample_agrees_with_the_python(lib):
    check_against_python(lib, groups=4, per=500, ctc_every=5, seed=1)


@pytest.mark.slow
def test_1e5_random_regular_states_and_parameter_sets_agree_to_1e12(lib):
    check_against_python(lib, groups=100, per=1000, ctc_every=4, seed=27)


def test_per_axis_gains_are_the_task_space_command_per_axis(lib):
    rng = np.random.default_rng(5)
    params = cbuild.random_params(rng)
    rows, _, _ = regular_group(params, 300, rng)
    rows[:, 15:19] = [400.0, 9000.0, 10.0, 150.0]  # kp1, kp2 [1/s²], kd1, kd2 [1/s]
    out = cbuild.run_batch(lib, rows)
    p, dp = rows[:, 7:9], rows[:, 9:11]
    a = task_space_command(rows[:, 19:21], rows[:, 21:23], rows[:, 23:25], p, dp, rows[:, 15:17], rows[:, 17:19])
    assert rel(out[:, 14:16], inverse_dynamics(params, p, dp, a), 0.0).max() <= TOL


# ------------------------------------------------------------------------------------------------ refusals
def python_code(call) -> int:
    """The C return code the Python's outcome corresponds to (0: a finite result)."""
    try:
        out = call()
    except UnreachablePoseError:
        return 2
    except SingularConfigurationError as exc:
        return 3 if "eq. 11" in str(exc) else 4
    except InputError as exc:
        return 6 if "overflow" in str(exc) else 1
    assert np.all(np.isfinite(out))
    return 0


def boundary_poses(params: Params) -> np.ndarray:
    """Unreachable poses, poses within a few ulp of |p_j| = l_a (eq. 11) and on either side of the direct
    singularity's arc ``|p| = l_a`` in the third quadrant (eq. 12) at both refusal thresholds."""
    la = params.l_a
    poses = [(la, 0.0), (0.0, -la), (2 * la, 2 * la), (-la, 0.1 * la), (0.3 * la, -1.0000001 * la)]
    edge = la
    for _ in range(40):
        edge = math.nextafter(edge, 0.0)
        poses += [(0.1 * la, edge), (-edge, -0.2 * la), (edge, edge)]
    for phi in (1.1 * math.pi, 1.25 * math.pi, 1.4 * math.pi):
        for delta in (0.0, 1e-15, 1e-13, 3e-12, 1e-11, 1e-10, 3e-9, 1e-8, 1e-6, -1e-13, -1e-10):
            r = la * (1 - delta)
            poses.append((r * math.cos(phi), r * math.sin(phi)))
    return np.array(poses)


def test_unreachable_and_singular_poses_get_the_python_refusal_and_outputs_stay_untouched(lib):
    params = Params.paper()
    poses = boundary_poses(params)
    n = len(poses)
    dp, ddp, f = np.tile([0.3, -0.2], (n, 1)), np.tile([2.0, 1.0], (n, 1)), np.tile([5.0, -3.0], (n, 1))
    gains = Gains(wn=10.0, zeta=1.0)
    columns = [np.tile(cbuild.params_row(params), (n, 1)), poses, dp, ddp, f, np.full((n, 2), gains.kp)]
    columns += [np.full((n, 2), gains.kd), np.zeros((n, 2)), dp, ddp, np.tile([10.0, 20.0], (n, 1))]
    rows = np.concatenate(columns, axis=1)
    out = cbuild.run_batch(lib, rows)
    law = ControlLaw(ControllerKind.CTC, params, gains).force_function()
    seen = set()
    for k, (p1, p2) in enumerate(poses):
        p = np.array([p1, p2])
        py_id = python_code(lambda p=p: inverse_dynamics(params, p, dp[0], ddp[0], f[0]))
        py_ctc = python_code(lambda p1=p1, p2=p2: law((0, 0, 0.3, -0.2, 2.0, 1.0), p1, p2, 0.3, -0.2))
        assert (out[k, 10], out[k, 16]) == (py_id, py_ctc), (p, out[k], py_id, py_ctc)
        seen |= {("id", py_id), ("ctc", py_ctc)}
        if py_id == 2:
            assert python_code(lambda p=p: inverse_kinematics(params, p)) == out[k, 2] == 2
        for code_col, outputs in ((2, [0, 1]), (7, [3, 4, 5, 6]), (10, [8, 9]), (13, [11, 12]), (16, [14, 15])):
            if out[k, code_col] != 0:
                assert np.all(out[k, outputs] == cbuild.SENTINEL)
            else:
                assert np.all(np.isfinite(out[k, outputs]))
    # the families exercise every refusal: unreachable, both singularities, and the ctc's wider direct threshold
    assert {("id", 0), ("id", 2), ("id", 3), ("id", 4), ("ctc", 0), ("ctc", 2), ("ctc", 3), ("ctc", 4)} <= seen
    wider = [k for k in range(n) if out[k, 16] == 4 and out[k, 10] == 0]
    assert wider, "a pose between the two direct thresholds (1e-12, 1e-9)"


def test_non_finite_input_bad_parameters_and_overflow_are_refused(lib):
    params = Params.paper()
    base = np.array([*cbuild.params_row(params), 0.01, 0.02, 0.3, -0.2, 2, 1, 5, -3, 900, 900, 60, 60])
    base = np.concatenate([base, [0.0, 0.0, 0.3, -0.2, 2, 1, 10, 20]])
    rows, expect_id = [], []
    for col in range(7, 27):
        for bad in (math.nan, math.inf, -math.inf):
            row = base.copy()
            row[col] = bad
            rows.append(row)
            expect_id.append(1 if col < 15 else 0)
    for col in range(7):
        for bad in (0.0, -1.0, math.nan):
            row = base.copy()
            row[col] = bad
            rows.append(row)
            expect_id.append(7)
    huge = base.copy()
    huge[9:11] = 1e160  # finite inputs, an overflowing result
    rows.append(huge)
    expect_id.append(6)
    out = cbuild.run_batch(lib, np.array(rows))
    assert list(out[:, 10]) == expect_id
    p = base[7:9]
    assert python_code(lambda: inverse_dynamics(params, p, huge[9:11], base[11:13])) == 6
    for row, code in zip(rows, expect_id, strict=True):
        if code == 1:  # the Python refuses the same non-finite inputs
            call = lambda r=row: inverse_dynamics(params, r[7:9], r[9:11], r[11:13], r[13:15])  # noqa: E731
            assert python_code(call) == 1
    gain_cols = out[[3 * (c - 7) for c in range(15, 25)], 16]  # a non-finite gain or reference
    assert set(gain_cols) == {1}
    neg = base.copy()
    neg[15] = -1.0
    assert cbuild.run_batch(lib, neg[None])[0, 16] == 7
    refused = out[:, [2, 7, 10, 13, 16]] != 0
    for block, cols in zip(range(5), ([0, 1], [3, 4, 5, 6], [8, 9], [11, 12], [14, 15]), strict=True):
        assert np.all(out[refused[:, block]][:, cols] == cbuild.SENTINEL)
    assert np.all(np.isfinite(out))


@pytest.mark.slow
def test_the_sanitized_build_runs_every_function_cleanly_and_gives_the_same_numbers(lib, tmp_path):
    directory = cbuild.export(tmp_path / "asan")
    driver = cbuild.build_driver(directory, cbuild.SANITIZE)
    rng = np.random.default_rng(3)
    params = cbuild.random_params(rng)
    rows, _, _ = regular_group(params, 2000, rng)
    poses = boundary_poses(params)
    special = np.repeat(rows[:1], len(poses), axis=0)
    special[:, 7:9] = poses
    bad = np.repeat(rows[:1], 20, axis=0)
    bad[np.arange(20), 7 + np.arange(20)] = math.nan
    everything = np.concatenate([rows, special, bad])
    (tmp_path / "in.bin").write_bytes(cbuild.with_margin(everything).astype("<f8").tobytes())
    done = subprocess.run(
        [str(driver), str(tmp_path / "in.bin"), str(tmp_path / "out.bin")], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    assert "runtime error" not in done.stderr and "AddressSanitizer" not in done.stderr
    got = np.frombuffer((tmp_path / "out.bin").read_bytes(), dtype="<f8").reshape(-1, cbuild.OUT_COLS)
    assert np.array_equal(got, cbuild.run_batch(lib, everything))
    assert done.stdout.strip() == "direct singularity: the two legs are parallel (eq. 12)"
