"""Hypothesis profiles: ``dev`` by default (a tenth of each test's examples, at least 10: the one-minute loop) and
``ci`` with the full counts (chosen by ``CI=true``, as ``.ci/run`` runs, or ``HYPOTHESIS_PROFILE=ci``).

A test that needs a count of its own writes ``settings(max_examples=examples(N))``: N under ``ci``, fewer under
``dev``. Both profiles are registered and loaded by ``tests/conftest.py``.
"""

from __future__ import annotations

import os

from hypothesis import settings

DEV, CI = "dev", "ci"


def profile() -> str:
    """The profile this run uses: ``HYPOTHESIS_PROFILE`` if set, else ``ci`` under ``CI=true``, else ``dev``."""
    chosen = os.environ.get("HYPOTHESIS_PROFILE", "").strip().lower()
    if chosen in (DEV, CI):
        return chosen
    return CI if os.environ.get("CI", "").strip().lower() in ("1", "true", "yes") else DEV


def examples(full: int) -> int:
    """How many examples a test with ``full`` examples under ``ci`` runs in this profile."""
    return full if profile() == CI else max(10, full // 10)


def load() -> None:
    """Register both profiles and load the one of this run (its default count for tests without their own)."""
    settings.register_profile(CI, max_examples=100, deadline=None)
    settings.register_profile(DEV, max_examples=examples(100), deadline=None)
    settings.load_profile(profile())
