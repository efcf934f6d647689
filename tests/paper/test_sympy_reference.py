"""The benchmarks' sympy reference (``benchmarks/sympy_reference.py``, from the Lagrangian) computes the same forces as
:func:`tpm_viz.inverse_dynamics`, so ``benchmarks/bench_core.py`` compares like with like (issue 27)."""

from __future__ import annotations

import importlib.util
import pathlib

import numpy as np
import pytest

from tests.support.strategies import random_states
from tpm_viz import Params, inverse_dynamics

PATH = pathlib.Path(__file__).resolve().parents[2] / "benchmarks" / "sympy_reference.py"


@pytest.fixture(scope="module")
def reference():
    spec = importlib.util.spec_from_file_location("sympy_reference", PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.reference_inverse_dynamics


@pytest.mark.parametrize("overrides", [{}, {"m_b": 5.0, "m_p": 0.3, "l_a": 0.2, "pivot_spacing": 0.04}])
def test_the_reference_agrees_with_the_closed_form_on_arrays_and_scalars(reference, overrides):
    params = Params.paper(**overrides)
    states = random_states(params, 400, seed=4)
    p, dp, ddp = (np.array([s[k] for s in states]) for k in range(3))
    f = np.random.default_rng(4).normal(0, 30, p.shape)
    want = inverse_dynamics(params, p, dp, ddp, f)
    cols = [x[:, k] for x in (p, dp, ddp, f) for k in (0, 1)]
    got = np.stack(reference(params, *cols), -1)
    assert np.all(np.max(np.abs(got - want), 1) <= 1e-12 * np.max(np.abs(want), 1))  # norm-wise, per state
    one = reference(params, *(float(c[0]) for c in cols))
    assert np.allclose(one, want[0], rtol=1e-12, atol=0.0)
