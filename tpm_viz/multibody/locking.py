"""One lock per :class:`~tpm_viz.multibody.model.MultibodyModel`: Pinocchio's ``Data`` is shared scratch memory."""

from __future__ import annotations

import functools
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Concatenate, ParamSpec, Protocol, TypeVar

__all__ = ["locked"]


class Locking(Protocol):
    """An object with a re-entrant ``_lock`` (a :class:`threading.RLock`)."""

    @property
    def _lock(self) -> AbstractContextManager[object]: ...


_S = TypeVar("_S", bound=Locking)
_P = ParamSpec("_P")
_R = TypeVar("_R")


def locked(method: Callable[Concatenate[_S, _P], _R]) -> Callable[Concatenate[_S, _P], _R]:
    """Run ``method`` while holding ``self._lock`` (a re-entrant lock)."""

    @functools.wraps(method)
    def wrapper(self: _S, *args: _P.args, **kwargs: _P.kwargs) -> _R:
        with self._lock:
            return method(self, *args, **kwargs)

    return wrapper
