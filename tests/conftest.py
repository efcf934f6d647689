"""Root of the tests, grouped by layer: ``paper/``, ``multibody/``, ``app/``, ``ui/``, ``cli/``, ``system/``.

Shared helpers live in ``tests/support/``; only ``ui/`` and ``system/`` load the server and browser fixtures, so
the maths tests run without websockets or Chromium.
"""
