"""One lock per :class:`~tpm_viz.multibody.model.MultibodyModel`: Pinocchio's ``Data`` is shared scratch memory."""

from __future__ import annotations

import functools

__all__ = ["locked"]


def locked(method):
    """Run ``method`` while holding ``self._lock`` (a re-entrant lock)."""

    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)

    return wrapper
