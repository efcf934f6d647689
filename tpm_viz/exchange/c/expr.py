"""A tiny expression tracer that turns the project's own Python formulas into C99 statements.

Why not sympy: the C must come from the *same* equations as the Python, not from a restatement of them. The
closed form lives in plain arithmetic functions (:func:`tpm_viz.paper.dynamics._procedure`, ``eq14_row``,
``_v_leg``, ``_w_leg``, the inverse kinematics ``_ik_unchecked``) that accept floats or arrays; they accept a
:class:`Sym` just as well. Calling them on symbols records every operation, in the order Python evaluates it,
as a graph; :class:`Emitter` prints that graph as C with the same operations in the same order (so the C
agrees with the Python to a few units in the last place, not just "mathematically"). sympy would re-order and
re-simplify the terms and would be a core dependency for what is ~150 lines here.

Exact simplifications only (``x + 0``, ``x * 1``, ``x * 0`` for the finite intermediates of the closed form,
constant folding in float64 as C would do it); shared sub-expressions are recorded once (hash-consing) and
become named temporaries. Integer powers are written as products (``x**3`` -> ``x*x*x``: within 2 ulp of
Python's ``pow``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["Emitter", "Graph", "Sym"]


class Graph:
    """The nodes of one trace; identical operations on identical operands are one node."""

    def __init__(self) -> None:
        self._nodes: dict[tuple, Sym] = {}

    def node(self, op: str, args: tuple = (), value: float | str | None = None) -> Sym:
        key = (op, tuple(id(a) for a in args), value)
        found = self._nodes.get(key)
        if found is None:
            found = Sym(self, op, args, value)
            self._nodes[key] = found
        return found

    def var(self, name: str) -> Sym:
        """A C variable (an input or a local the skeleton declares)."""
        return self.node("var", value=name)

    def const(self, value: float) -> Sym:
        return self.node("const", value=float(value))


_FOLD = {
    "add": lambda x, y: x + y,
    "sub": lambda x, y: x - y,
    "mul": lambda x, y: x * y,
    "div": lambda x, y: x / y,
}


def _is(x: Sym, value: float) -> bool:
    return x.op == "const" and x.value == value


class Sym:
    """One node: ``op`` in var, const, add, sub, mul, div, neg, sqrt. Arithmetic with floats and other nodes."""

    __slots__ = ("args", "graph", "op", "value")

    def __init__(self, graph: Graph, op: str, args: tuple, value) -> None:
        self.graph, self.op, self.args, self.value = graph, op, args, value

    def _wrap(self, other) -> Sym | None:
        """``other`` as a node; None for anything else (an array then applies the operation per element)."""
        if isinstance(other, Sym):
            return other
        if isinstance(other, (int, float)) and not isinstance(other, bool):
            return self.graph.const(other)
        return None

    def _op(self, op: str, other, reflected: bool = False):
        o = self._wrap(other)
        if o is None:
            return NotImplemented
        return self._binary(op, o, self) if reflected else self._binary(op, self, o)

    def _binary(self, op: str, a: Sym, b: Sym) -> Sym:
        g = self.graph
        if a.op == "const" and b.op == "const":
            x, y = a.value, b.value
            if op == "div" and y == 0.0:
                raise ZeroDivisionError("a traced formula divides a constant by zero")
            return g.const(_FOLD[op](x, y))
        if op == "add":
            if _is(a, 0.0):
                return b
            if _is(b, 0.0):
                return a
        elif op == "sub":
            if _is(b, 0.0):
                return a
            if _is(a, 0.0):
                return -b
        elif op == "mul":
            if _is(a, 0.0) or _is(b, 0.0):
                return g.const(0.0)
            if _is(a, 1.0):
                return b
            if _is(b, 1.0):
                return a
        elif op == "div":
            if _is(a, 0.0):
                return g.const(0.0)
            if _is(b, 1.0):
                return a
        return g.node(op, (a, b))

    def __add__(self, other):
        return self._op("add", other)

    def __radd__(self, other):
        return self._op("add", other, reflected=True)

    def __sub__(self, other):
        return self._op("sub", other)

    def __rsub__(self, other):
        return self._op("sub", other, reflected=True)

    def __mul__(self, other):
        return self._op("mul", other)

    def __rmul__(self, other):
        return self._op("mul", other, reflected=True)

    def __truediv__(self, other):
        return self._op("div", other)

    def __rtruediv__(self, other):
        return self._op("div", other, reflected=True)

    def __neg__(self):
        if self.op == "const":
            return self.graph.const(-self.value)
        if self.op == "neg":
            return self.args[0]
        return self.graph.node("neg", (self,))

    def __pow__(self, n):
        if not isinstance(n, int) and not (isinstance(n, float) and n.is_integer()):
            raise TypeError(f"only integer powers are traced, got {n!r}")
        n = int(n)
        if n < 1:
            raise TypeError(f"only positive integer powers are traced, got {n}")
        out = self
        for _ in range(n - 1):
            out = out * self
        return out

    def sqrt(self) -> Sym:
        """``numpy.sqrt`` on an object array calls this."""
        if self.op == "const":
            return self.graph.const(math.sqrt(self.value))
        return self.graph.node("sqrt", (self,))

    def __bool__(self):
        raise TypeError("a traced expression has no truth value: the formula must be branch-free")


def _literal(value: float) -> str:
    if not math.isfinite(value):
        raise ValueError(f"non-finite constant {value!r} in a traced formula")
    text = repr(float(value))
    return f"({text})" if text.startswith("-") else text


@dataclass
class Emitter:
    """Prints traced outputs as ``const double`` statements, stage by stage, each temporary once."""

    indent: str = "    "
    _names: dict[int, str] = field(default_factory=dict)
    _uses: dict[int, int] = field(default_factory=dict)
    _counted: set[int] = field(default_factory=set)
    _temp: int = 0

    def _count(self, root: Sym) -> None:
        stack = [root]
        while stack:
            node = stack.pop()
            self._uses[id(node)] = self._uses.get(id(node), 0) + 1
            if id(node) in self._counted:
                continue
            self._counted.add(id(node))
            stack.extend(node.args)

    def _expr(self, node: Sym, lines: list[str], top: bool = False) -> str:
        """C text of ``node``; multi-use interior nodes are emitted into ``lines`` first as temporaries
        (not ``node`` itself when ``top``: the caller names it)."""
        name = self._names.get(id(node))
        if name is not None:
            return name
        if node.op == "var":
            return str(node.value)
        if node.op == "const":
            return _literal(node.value)
        parts = [self._expr(a, lines) for a in node.args]
        if node.op == "neg":
            text = f"(-{parts[0]})"
        elif node.op == "sqrt":
            text = f"sqrt({parts[0]})"
        else:
            text = f"({parts[0]} {dict(add='+', sub='-', mul='*', div='/')[node.op]} {parts[1]})"
        if not top and self._uses.get(id(node), 0) > 1:
            name = f"t{self._temp}"
            self._temp += 1
            lines.append(f"{self.indent}const double {name} = {_strip(text)};")
            self._names[id(node)] = name
            return name
        return text

    def emit(self, stages: list[tuple[str, list[tuple[str, Sym]]]]) -> str:
        """``stages``: ``(comment, [(local name, expression), ...])``; returns the C statements.

        Every expression of every stage is counted first, so a sub-expression shared between stages is
        computed once; a named output that a later stage reuses is referred to by its name.
        """
        for _, outputs in stages:
            for _, expr in outputs:
                self._count(expr)
        lines: list[str] = []
        for comment, outputs in stages:
            lines.append(f"{self.indent}/* {comment} */")
            for name, expr in outputs:
                text = self._expr(expr, lines, top=True)
                lines.append(f"{self.indent}const double {name} = {_strip(text)};")
                if id(expr) not in self._names and expr.op not in ("var", "const"):
                    self._names[id(expr)] = name
        return "\n".join(lines)


def _strip(text: str) -> str:
    """Drop one pair of outer parentheses that encloses the whole text."""
    if not (text.startswith("(") and text.endswith(")")):
        return text
    depth = 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0 and i < len(text) - 1:
            return text
    return text[1:-1]
