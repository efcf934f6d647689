"""The ``heavy`` marker (``tests/conftest.py``): minutes-long searches that re-derive stored results run only when
asked (``-m heavy``, or ``TPM_VIZ_HEAVY=1``), whatever other ``-m`` a run has (``-m "not slow"``, CI's plain run).
Checked by collecting a real file with one heavy test in a child pytest, as a contributor or CI would run it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.support.docs import ROOT

FILE = "tests/design/test_optimum.py"
HEAVY = f"{FILE}::test_no_independent_search_beats_the_global_search_by_half_a_percent"


def _collected(*options: str, heavy_env: str | None = None) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k != "TPM_VIZ_HEAVY"}
    if heavy_env is not None:
        env["TPM_VIZ_HEAVY"] = heavy_env
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *options, FILE],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=300,
    )
    assert done.returncode in (0, 5), done.stdout + done.stderr  # 5: nothing selected
    return [line for line in done.stdout.splitlines() if line.startswith(FILE)]


@pytest.mark.slow  # a child pytest each, a few seconds
@pytest.mark.parametrize(
    ("options", "heavy_env", "wanted"),
    [
        ((), None, "others"),
        (("-m", "not slow"), None, "others"),
        (("-m", "heavy"), None, "heavy"),
        ((), "1", "all"),
    ],
)
def test_heavy_tests_run_only_when_asked(options, heavy_env, wanted):
    got = _collected(*options, heavy_env=heavy_env)
    others = [n for n in got if n != HEAVY]
    if wanted == "heavy":
        assert got == [HEAVY]
    elif wanted == "all":
        assert HEAVY in got and others
    else:
        assert HEAVY not in got and others
