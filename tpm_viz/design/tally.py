"""The designs a search has evaluated and how many it may still evaluate, for a progress line
(``tpm-viz compare``): an :data:`~tpm_viz.design.optimum.Evaluate` that passes every batch on unchanged (the numbers
do not depend on it) and counts it.

A search (:func:`tpm_viz.design.optimum.search`) evaluates its first population and then one population per
generation: at most ``(generations + 1) * population`` designs (:func:`~tpm_viz.design.optimum.population`), fewer
when the members agree early; then at most ``Search.polish`` designs one at a time (Nelder-Mead; none when it found
nothing feasible). The total reported is the count so far plus the budget still open: it shrinks when a phase ends
early and equals the count after :meth:`Tally.finish`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from tpm_viz.design.optimum import Evaluate, Search

__all__ = ["Tally"]

Progress = Callable[[int, int], None]
"""``progress(done, total)``: designs evaluated and the most there can be in all."""


def _in_turn(cost: Callable[[np.ndarray], float], points: Sequence[np.ndarray]) -> list[float]:
    return [cost(x) for x in points]


class Tally:
    """Counts the designs of consecutive searches with the given ``populations`` (one per search, in order) and
    budget ``how``, calling ``progress(done, total)`` after every batch; ``inner`` evaluates the batches (default:
    in this thread, in order). A new search is told by a new ``cost.__self__`` (its
    :class:`~tpm_viz.design.optimum.Problem`), the polish by batches of one design."""

    def __init__(
        self, populations: Sequence[int], how: Search, progress: Progress, inner: Evaluate | None = None
    ) -> None:
        self.evolution = [(how.generations + 1) * int(n) for n in populations]
        self.polish = int(how.polish)
        self.progress, self.inner = progress, inner if inner is not None else _in_turn
        self.done, self.search, self.used, self.polishing = 0, -1, 0, False
        self._problem: object = None

    @property
    def total(self) -> int:
        """Designs evaluated plus the most the searches may still evaluate."""
        later = sum(n + self.polish for n in self.evolution[self.search + 1 :])
        if self.search < 0:
            return later
        if self.search >= len(self.evolution):  # more searches than told: no budget left to tell
            return self.done
        open_now = self.polish - self.used if self.polishing else self.evolution[self.search] - self.used + self.polish
        return self.done + max(open_now, 0) + later

    def __call__(self, cost: Callable[[np.ndarray], float], points: Sequence[np.ndarray]) -> Sequence[float]:
        problem = getattr(cost, "__self__", cost)
        if problem is not self._problem:  # the next search
            self._problem, self.search, self.used, self.polishing = problem, self.search + 1, 0, False
        if len(points) == 1 and not self.polishing:  # a population has at least 5 members
            self.polishing, self.used = True, 0
        out = self.inner(cost, points)
        self.used += len(points)
        self.done += len(points)
        self.progress(self.done, self.total)
        return out

    def finish(self) -> None:
        """The searches are over: ``progress(done, done)``."""
        self.progress(self.done, self.done)
