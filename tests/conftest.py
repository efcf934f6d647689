"""Root of the tests, which mirror the package: ``tests/<folder>/test_<module>.py`` tests
``tpm_viz/<folder>/<module>.py`` (``core/``, ``paper/``, ``drawing/``, ``media/``, ``exchange/``, ``multibody/``,
``app/``, ``design/``, ``classroom/``, ``viserkit/``, ``ui/``, ``cli/``), plus ``e2e/`` (a served app with its browsers
and attackers, as a class meets it) and ``system/`` (the rules of the repository: layering, cross-references, the README
and the docs site, the examples, the lock).

Shared helpers live in ``tests/support/``; only ``classroom/``, ``viserkit/``, ``ui/`` and ``e2e/`` load the server
and browser fixtures, so the maths tests run without websockets or Chromium.

Profiles: ``python -m pytest -m "not slow" -n 2`` is the one-minute loop (Hypothesis's small ``dev`` profile, no
Chromium, no long server runs); ``CI=true python -m pytest`` runs everything but the ``heavy`` tests with the full
example counts (``tests/support/hypo.py``); ``python -m pytest -m heavy`` runs the minutes-long searches that re-derive
stored results (``docs/contributing.md``).
"""

from __future__ import annotations

import os

import pytest

from tests.support import hypo

hypo.load()


HEAVY_ENV = "TPM_VIZ_HEAVY"
"""``TPM_VIZ_HEAVY=1`` keeps the ``heavy`` tests in a run whose ``-m`` does not name them."""


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """A browser test is a slow one: ``-m "not slow"`` (the one-minute loop) leaves out Chromium. A ``heavy`` test
    (minutes-long searches re-deriving stored results) runs only when asked: ``-m heavy`` (any ``-m`` naming it), or
    ``TPM_VIZ_HEAVY=1``; otherwise it is deselected, whatever else ``-m`` says."""
    for item in items:
        if item.get_closest_marker("browser") is not None:
            item.add_marker(pytest.mark.slow)
    asked = "heavy" in (config.getoption("markexpr", "") or "") or os.environ.get(HEAVY_ENV, "") == "1"
    if asked:
        return
    heavy = [item for item in items if item.get_closest_marker("heavy") is not None]
    if heavy:
        config.hook.pytest_deselected(items=heavy)
        items[:] = [item for item in items if item.get_closest_marker("heavy") is None]
