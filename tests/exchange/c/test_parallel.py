"""The generated ``tpm_par_*`` functions (the parallel arrangement, docs/parallel.md) against the Python they are
traced from (:mod:`tpm_viz.paper.parallel`): seeded random regular states and parameter sets, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.support import cbuild
from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.params import Params
from tpm_viz.paper import parallel

D, RC_D, J, RC_J, TAU, RC_TAU, ACC, RC_ACC = slice(18, 20), 20, slice(21, 25), 25, slice(26, 28), 28, slice(29, 31), 31


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    assert cbuild.cc() is not None, "these tests need a C compiler: Debian packages gcc and libc6-dev"
    return cbuild.load(cbuild.export(tmp_path_factory.mktemp("cpar")))


def rows_for(params: Params, p, dp, ddp, f, tau_in) -> np.ndarray:
    n = len(p)
    zeros = np.zeros((n, 2))
    ones = np.ones((n, 2))
    prm = np.tile(cbuild.params_row(params), (n, 1))
    return np.concatenate([prm, p, dp, ddp, f, ones, ones, zeros, zeros, zeros, tau_in], axis=1)


def rel(c, py, floor) -> np.ndarray:
    return np.max(np.abs(c - py), axis=1) / np.maximum(np.max(np.abs(py), axis=1), floor)


def test_random_regular_states_agree_with_the_python(lib):
    rng = np.random.default_rng(8)
    worst = dict.fromkeys(("ik", "jac", "id", "fd"), 0.0)
    for _ in range(20):
        params = cbuild.random_params(rng)
        la, n = params.l_a, 500
        p2 = rng.uniform(0.1 * la, 0.85 * la, n) * rng.choice([-1.0, 1.0], n)  # clear of p_2 = 0 and |p_2| = l_a
        p = np.stack([rng.uniform(-0.3, 0.3, n), p2], -1)
        dp, ddp, f = rng.uniform(-2, 2, (n, 2)), rng.uniform(-30, 30, (n, 2)), rng.normal(0, 20, (n, 2))
        tau = parallel.inverse_dynamics(params, p, dp, ddp, f)
        out = cbuild.run_batch(lib, rows_for(params, p, dp, ddp, f, tau))
        assert np.all(out[:, [RC_D, RC_J, RC_TAU, RC_ACC]] == 0)
        worst["ik"] = max(worst["ik"], rel(out[:, D], parallel.inverse_kinematics(params, p), la).max())
        worst["jac"] = max(worst["jac"], rel(out[:, J], parallel.jacobians(params, p).j.reshape(-1, 4), 1.0).max())
        worst["id"] = max(worst["id"], rel(out[:, TAU], tau, 0.0).max())
        worst["fd"] = max(worst["fd"], rel(out[:, ACC], ddp, 1.0).max())
    print("parallel, worst relative errors", worst)
    assert max(worst.values()) <= 1e-12, worst


def python_code(call) -> int:
    try:
        call()
    except UnreachablePoseError:
        return 2
    except SingularConfigurationError as exc:
        return 3 if "cos" in str(exc) else 4
    except InputError as exc:
        return 6 if "overflow" in str(exc) else 1
    return 0


def test_refusals_are_the_pythons_and_leave_the_outputs(lib):
    params = Params.paper()
    la = params.l_a
    poses = [(0.1, la), (0.0, -la), (0.0, 2 * la), (0.05, 0.0), (-0.2, 0.0), (0.0, 1e-15), (0.1, -3e-13)]
    edge = la
    for _ in range(30):
        edge = math.nextafter(edge, 0.0)
        poses += [(0.1, edge), (-0.3, -edge)]
    poses += [(math.nan, 0.1), (0.0, math.inf), (0.02, 0.1)]
    p = np.array(poses)
    n = len(p)
    dp, ddp, f = np.tile([0.3, -0.2], (n, 1)), np.tile([2.0, 1.0], (n, 1)), np.tile([5.0, -3.0], (n, 1))
    out = cbuild.run_batch(lib, rows_for(params, p, dp, ddp, f, np.tile([10.0, 20.0], (n, 1))))
    seen = set()
    for k in range(n):
        code = python_code(lambda k=k: parallel.inverse_dynamics(params, p[k], dp[k], ddp[k], f[k]))
        assert out[k, RC_TAU] == code, (p[k], out[k, RC_TAU], code)
        seen.add(code)
        if code in (1, 2):
            assert out[k, RC_D] == code == python_code(lambda k=k: parallel.inverse_kinematics(params, p[k]))
        for rc, cols in ((RC_D, D), (RC_J, J), (RC_TAU, TAU), (RC_ACC, ACC)):
            block = out[k, cols]
            assert np.all(block == cbuild.SENTINEL) if out[k, rc] != 0 else np.all(np.isfinite(block))
    assert {0, 1, 2, 4} <= seen
