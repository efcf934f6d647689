"""What both arrangements' C bodies trace alike (:mod:`.code`, :mod:`.parallel`): the symbols, ``J`` and ``M``, ``h``.

Each arrangement's closed form is a Python function of the state (the paper's ``_procedure``, eqs. 9-31; the
parallel one's, eqs. P4-P14). Traced on the symbols of :func:`symbols` (the C locals the skeletons of :mod:`.blocks`
declare), it gives the inverse dynamics; two more shapes are the same for both:

- the Jacobian ``J = ∂ḋ/∂ṗ`` (eq. 10 / P4): the actuator velocities ``ḋ = J ṗ`` (eq. 9 / P4) at ``ṗ = e_1`` and
  ``ṗ = e_2`` are its columns (:func:`jacobian_entries`);
- the forward dynamics: the closed form is affine in ``p̈`` (no gravity), ``τ = M(p) p̈ + h(p, ṗ, f_ext)``, so
  ``h = τ(p, ṗ, 0)`` and the columns of ``M`` are ``τ(p, 0, e_k)`` without load (:func:`forward_dynamics_stages`).
"""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

from tpm_viz.exchange.c.blocks import Stages
from tpm_viz.exchange.c.expr import Graph, Sym

__all__ = ["Component", "Forces", "Pair", "forward_dynamics_stages", "jacobian_entries", "symbols"]

_LOCALS = "p1 p2 dp1 dp2 ddp1 ddp2 c1 c2 f1 f2 l_a offset m_a m_b m_p"
"""The C locals of a skeleton a trace may read: the state, the legs' ``c_i``, the load and the parameters."""

Component = Any
"""One traced quantity: a symbol, or a number (``0.0``, ``1.0``) fixed at trace time (duck-typed: the closed forms
take floats or arrays, and are traced on symbols)."""

Pair = tuple[Component, Component]

Forces = Callable[[Pair, Pair, Pair], Any]
"""``(τ_1, τ_2)`` (a pair, or an array of two) of the closed form traced at ``(ṗ, p̈, f_ext)``, each a pair."""


def symbols(extra: str = "") -> SimpleNamespace:
    """A new trace (``graph``) with the locals as its symbols (``p1``, ..., ``m_p``, then the ``extra`` names) and
    ``params``, a stand-in for :class:`~tpm_viz.core.params.Params` whose fields are the locals (duck-typed)."""
    graph = Graph()
    s = SimpleNamespace(graph=graph, **{n: graph.var(n) for n in f"{_LOCALS} {extra}".split()})
    s.params = SimpleNamespace(l_a=s.l_a, offset=s.offset, m_a=s.m_a, m_b=s.m_b, m_p=s.m_p)
    return s


def jacobian_entries(velocities: Callable[[float, float], Any]) -> list[tuple[str, Sym]]:
    """``J11, J12, J21, J22`` from ``velocities(ṗ_1, ṗ_2) = (ḋ_1, ḋ_2)``, traced at ``ṗ = e_1`` then ``e_2``."""
    cols = [velocities(1.0, 0.0), velocities(0.0, 1.0)]
    return [("J11", cols[0][0]), ("J12", cols[1][0]), ("J21", cols[0][1]), ("J22", cols[1][1])]


def forward_dynamics_stages(s: SimpleNamespace, forces: Forces, comments: tuple[str, str]) -> Stages:
    """The stages ``h1, h2`` (``τ`` at the state's ``ṗ`` and load, ``p̈ = 0``) and ``M11, M21, M12, M22`` (``τ`` at
    ``ṗ = 0``, ``p̈ = e_k``, no load), with ``comments`` (``h``, ``M``)."""
    zero = (0.0, 0.0)
    h = forces((s.dp1, s.dp2), zero, (s.f1, s.f2))
    m1 = forces(zero, (1.0, 0.0), zero)
    m2 = forces(zero, (0.0, 1.0), zero)
    return [
        (comments[0], [("h1", h[0]), ("h2", h[1])]),
        (comments[1], [("M11", m1[0]), ("M21", m1[1]), ("M12", m2[0]), ("M22", m2[1])]),
    ]
