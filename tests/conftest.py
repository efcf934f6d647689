"""Root of the tests, which mirror the package: ``tests/<folder>/test_<module>.py`` tests
``tpm_viz/<folder>/<module>.py`` (``core/``, ``paper/``, ``drawing/``, ``media/``, ``exchange/``, ``multibody/``,
``app/``, ``design/``, ``classroom/``, ``viserkit/``, ``ui/``, ``cli/``), plus ``e2e/`` (a served app with its browsers
and attackers, as a class meets it) and ``system/`` (the rules of the repository: layering, cross-references, the README
and the docs site, the examples, the lock).

Shared helpers live in ``tests/support/``; only ``classroom/``, ``viserkit/``, ``ui/`` and ``e2e/`` load the server
and browser fixtures, so the maths tests run without websockets or Chromium.

Profiles: ``python -m pytest -m "not slow" -n 2`` is the one-minute loop (Hypothesis's small ``dev`` profile, no
Chromium, no long server runs); ``CI=true python -m pytest`` runs everything with the full example counts
(``tests/support/hypo.py``).
"""

from __future__ import annotations

import pytest

from tests.support import hypo

hypo.load()


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """A browser test is a slow one: ``-m "not slow"`` (the one-minute loop) leaves out Chromium."""
    for item in items:
        if item.get_closest_marker("browser") is not None:
            item.add_marker(pytest.mark.slow)
