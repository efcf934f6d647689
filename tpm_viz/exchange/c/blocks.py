"""The C skeleton every generated function shares, written once for :mod:`.text` and :mod:`.parallel`.

Each public function of ``tpm_2ppa.c`` has one shape: find the legs (``tpm_legs`` or ``tpm_par_legs``: the
parameters, a finite and reachable ``p``) or refuse; refuse the function's own bad inputs and singular poses; then,
in a block, declare the locals, run the traced formulas, refuse a non-finite result (``TPM_E_OVERFLOW``) and only
then copy it out, so a refusal has written nothing. Control flow only: every formula comes from the trace
(:mod:`.expr`); the traced bodies stay ``string.Template`` placeholders (``$id_body``) here.

Also the Python side both arrangements share: the C locals a traced body may read, and the declarations of those
it does read (:func:`traced_block`).
"""

from __future__ import annotations

from collections.abc import Sequence

from tpm_viz.exchange.c.expr import Emitter, Sym

__all__ = [
    "FD_ARGS",
    "ID_ARGS",
    "IK_ARGS",
    "JACOBIAN_ARGS",
    "PRM",
    "Cosines",
    "Legs",
    "Stages",
    "c_function",
    "copy_out",
    "finite_inputs",
    "forward_dynamics",
    "inverse_dynamics",
    "inverse_singular",
    "jacobian",
    "passed",
    "prototype",
    "reachable",
    "refuse",
    "regular",
    "require",
    "result_block",
    "solve2",
    "traced_block",
    "unpack",
    "valid_inputs",
]

WIDTH = 120
"""The generated C's line length (as the project's own)."""

Legs = tuple[str, str]
"""``(declaration, call)`` of the legs step, e.g. ``("double c1, c2;", "tpm_legs(prm, p, &c1, &c2)")``."""

Stages = list[tuple[str, list[tuple[str, Sym]]]]

Cosines = tuple[str, str]
"""C expressions of ``cos θ_1, cos θ_2`` (e.g. ``("c1 / prm->l_a", "c2 / prm->l_a")``), as the app computes them."""

_PARAM_LOCALS = {
    "l_a": "prm->l_a",
    "offset": "prm->a - prm->b",
    "m_a": "prm->m_a",
    "m_b": "prm->m_b",
    "m_p": "prm->m_p",
}
_STATE_LOCALS = {
    "p1": "p[0]",
    "p2": "p[1]",
    "dp1": "dp[0]",
    "dp2": "dp[1]",
    "ddp1": "ddp[0]",
    "ddp2": "ddp[1]",
}


def _wrapped(head: str, items: Sequence[str], sep: str, tail: str, indent: int) -> str:
    """``head + items joined by sep + tail``, broken after a separator where a line would pass :data:`WIDTH`."""
    lines, line = [], head
    for i, item in enumerate(items):
        piece = item + (sep.rstrip() if i < len(items) - 1 else tail)
        if line != head and len(line) + 1 + len(piece) > WIDTH:
            lines.append(line)
            line = " " * indent + piece
        else:
            line += ("" if line == head else " ") + piece
    return "\n".join([*lines, line])


def prototype(name: str, params: Sequence[str]) -> str:
    """``int name(params)``, wrapped under the parenthesis (no ``;``: the header adds it, the source a body)."""
    head = f"int {name}("
    return _wrapped(head, params, ", ", ")", len(head))


def refuse(condition: str, code: str, depth: int = 1) -> str:
    """``if (condition) { return code; }`` at ``depth`` (1: function level, 2: the result block)."""
    pad = "    " * depth
    return f"{pad}if ({condition}) {{\n{pad}    return {code};\n{pad}}}\n"


def require(terms: Sequence[str], code: str, depth: int = 1) -> str:
    """Refuse with ``code`` unless every term holds: ``if (!(t1 && t2 ...))``, wrapped at :data:`WIDTH`."""
    pad = "    " * depth
    head = f"{pad}if (!("
    cond = _wrapped(head, terms, " && ", ")", len(head))[len(pad) + 4 :]
    return refuse(cond, code, depth)


def valid_inputs(array: str) -> str:
    """Refuse bad parameters (``TPM_E_PARAMS``), then a non-finite ``array`` (``TPM_E_NONFINITE``)."""
    return refuse("!tpm_params_ok(prm)", "TPM_E_PARAMS") + refuse(f"!tpm_finite2({array})", "TPM_E_NONFINITE")


def reachable(terms: Sequence[str]) -> str:
    """:func:`valid_inputs` of ``p``, then refuse (``TPM_E_UNREACHABLE``) unless every term holds (eq. 4, eq. P3)."""
    return valid_inputs("p") + require(terms, "TPM_E_UNREACHABLE")


def finite_inputs(arrays: Sequence[str], optional: Sequence[str] = ()) -> str:
    """Refuse (``TPM_E_NONFINITE``) unless the 2-vectors are finite; an ``optional`` one may be NULL."""
    terms = [f"tpm_finite2({a})" for a in arrays] + [f"({a} == NULL || tpm_finite2({a}))" for a in optional]
    return require(terms, "TPM_E_NONFINITE")


def _below_min_cos(cosines: Cosines) -> str:
    """``|cos θ_1| < min_cos || |cos θ_2| < min_cos``: the margin's inverse rule (``tpm_viz.app.moves.margins``)."""
    return " || ".join(f"fabs({k}) < prm->min_cos" for k in cosines)


def inverse_singular(product: str, cosines: Cosines) -> str:
    """Refuse at the inverse singularity, ``|c_1 c_2| < tol l_a^2`` (eq. 11; ``product`` is ``c_1 * c_2``), and
    inside the margin ``min_i |cos θ_i| < min_cos`` of ``tpm_params``."""
    exact = refuse(f"fabs({product}) < TPM_SINGULAR_TOL * (prm->l_a * prm->l_a)", "TPM_E_SINGULAR_INVERSE")
    return exact + refuse(_below_min_cos(cosines), "TPM_E_SINGULAR_INVERSE")


def regular(signature: str, product: str, direct: str, direct_tol: str, cosines: Cosines, det: str) -> str:
    """A static check of both singularities and the margin of ``tpm_params``, in the app's order (inverse first):
    ``|product| < tol l_a^2``, ``min_i |cos θ_i| < min_cos`` (eq. 11), then ``|direct| < direct_tol l_a^2``,
    ``|det| < min_det`` (eq. 12). ``cosines`` are ``cos θ_i`` (C expressions, declared as ``k1``, ``k2``), ``det``
    the direct measure ``det J_x`` written with them, as :func:`tpm_viz.app.moves.margins` computes it."""
    return (
        f"static int {signature}\n{{\n    const double la2 = prm->l_a * prm->l_a;\n"
        + "".join(f"    const double k{i + 1} = {k}; /* cos th_{i + 1} */\n" for i, k in enumerate(cosines))
        + f"    const double det = {det}; /* det J_x */\n"
        + refuse(f"fabs({product}) < TPM_SINGULAR_TOL * la2", "TPM_E_SINGULAR_INVERSE")
        + refuse(_below_min_cos(("k1", "k2")), "TPM_E_SINGULAR_INVERSE")
        + refuse(f"fabs({direct}) < {direct_tol} * la2", "TPM_E_SINGULAR_DIRECT")
        + refuse("fabs(det) < prm->min_det", "TPM_E_SINGULAR_DIRECT")
        + "    return TPM_OK;\n}\n"
    )


def unpack(name: str, array: str, optional: bool = False) -> list[str]:
    """``const double name1 = array[0];`` and ``name2``; ``optional``: a NULL ``array`` reads as zeros."""
    if optional:
        return [f"const double {name}{i + 1} = {array} == NULL ? 0.0 : {array}[{i}];" for i in range(2)]
    return [f"const double {name}{i + 1} = {array}[{i}];" for i in range(2)]


def solve2() -> list[str]:
    """``a = M^-1 (tau - h)`` for the 2x2 ``M11..M22`` and ``h1, h2`` by Cramer's rule (``det != 0`` when regular)."""
    return [
        "/* M ddp = tau - h, solved by Cramer's rule */",
        "const double det = M11 * M22 - M12 * M21;",
        "const double r1 = tau[0] - h1;",
        "const double r2 = tau[1] - h2;",
        "const double a1 = (M22 * r1 - M12 * r2) / det;",
        "const double a2 = (M11 * r2 - M21 * r1) / det;",
    ]


def copy_out(out: str, values: Sequence[str], depth: int = 2) -> str:
    """``out[i] = values[i];`` for each value."""
    pad = "    " * depth
    return "".join(f"{pad}{out}[{i}] = {v};\n" for i, v in enumerate(values))


def result_block(
    body: str,
    out: str,
    values: Sequence[str],
    *,
    before: Sequence[str] = (),
    after: Sequence[str] = (),
    finite: Sequence[str] | None = None,
) -> str:
    """The block ``{ before; body; after; refuse a non-finite result; out = values }``.

    ``body`` is a template placeholder (its text brings its own indentation); ``finite`` the values to check
    (default: all; a constant entry such as ``J11 = 1`` needs none)."""
    lines = "".join(f"        {line}\n" for line in before) + body + "\n"
    lines += "".join(f"        {line}\n" for line in after)
    checked = values if finite is None else finite
    lines += require([f"isfinite({v})" for v in checked], "TPM_E_OVERFLOW", depth=2)
    return "    {\n" + lines + copy_out(out, values) + "    }\n"


def c_function(signature: str, legs: Legs, checks: Sequence[str], block: str, first: str = "") -> str:
    """A public function: ``first`` lines, the legs (refusal handed on), ``checks``, then ``block``; ``TPM_OK``.

    ``rc`` is ``const`` unless a check re-assigns it."""
    declare, call = legs
    rc = "int rc" if any(c.startswith("    rc = ") for c in checks) else "const int rc"
    head = f"{signature}\n{{\n{first}    {declare}\n    {rc} = {call};\n" + refuse("rc != TPM_OK", "rc")
    return head + "".join(checks) + block + "    return TPM_OK;\n}\n"


def passed(call: str) -> str:
    """``rc = call;``, a refusal handed on."""
    return f"    rc = {call};\n" + refuse("rc != TPM_OK", "rc")


PRM = "const tpm_params *prm"
IK_ARGS = (PRM, "const double p[2]", "double d[2]")
JACOBIAN_ARGS = (PRM, "const double p[2]", "double J[4]")
ID_ARGS = (
    PRM,
    "const double p[2]",
    "const double dp[2]",
    "const double ddp[2]",
    "const double f_ext[2]",
    "double tau[2]",
)
FD_ARGS = (
    PRM,
    "const double p[2]",
    "const double dp[2]",
    "const double tau[2]",
    "const double f_ext[2]",
    "double ddp[2]",
)


def jacobian(
    name: str,
    legs: Legs,
    singular: tuple[str, Cosines],
    body: str,
    finite: Sequence[str],
    before: Sequence[str] = (),
) -> str:
    """``J = dd/dp`` row-major into ``J[4]``; refuses at the inverse singularity and inside the margin's inverse rule
    (``singular``: ``c_1 c_2`` and the cosines, :func:`inverse_singular`). ``J`` stays finite at the direct one."""
    block = result_block(body, "J", ("J11", "J12", "J21", "J22"), before=before, finite=finite)
    return c_function(prototype(name, JACOBIAN_ARGS), legs, [inverse_singular(*singular)], block)


def inverse_dynamics(
    name: str, legs: Legs, regular_call: str, body: str, before: Sequence[str] = (), after: Sequence[str] = ()
) -> str:
    """``tau`` of ``p, dp, ddp, f_ext`` (NULL: none); refuses non-finite inputs, then what ``regular_call`` refuses."""
    checks = [finite_inputs(("dp", "ddp"), ("f_ext",)), passed(regular_call)]
    block = result_block(body, "tau", ("tau1", "tau2"), before=[*before, *unpack("f", "f_ext", True)], after=after)
    return c_function(prototype(name, ID_ARGS), legs, checks, block)


def forward_dynamics(
    name: str, legs: Legs, regular_call: str, body: str, before: Sequence[str] = (), after: Sequence[str] = ()
) -> str:
    """``ddp`` of ``p, dp, tau, f_ext``: the traced ``h`` and ``M``, then :func:`solve2`; checks as the inverse."""
    checks = [finite_inputs(("dp", "tau"), ("f_ext",)), passed(regular_call)]
    before = [*before, *unpack("f", "f_ext", True)]
    block = result_block(body, "ddp", ("a1", "a2"), before=before, after=[*solve2(), *after])
    return c_function(prototype(name, FD_ARGS), legs, checks, block)


def traced_block(stages: Stages, extra: dict[str, str] | None = None) -> str:
    """The traced ``stages`` as C at block depth, after the declarations of the locals they read.

    The locals are the parameters (``l_a``, ``offset``, masses), the state (``p1``...``ddp2``) and ``extra``; only
    those the body names are declared (an unused one is a warning, and ``-Werror``)."""
    body = Emitter(indent=" " * 8).emit(stages)
    words = set(body.replace("(", " ").replace(")", " ").replace(";", " ").replace(",", " ").split())
    candidates = {**_PARAM_LOCALS, **_STATE_LOCALS, **(extra or {})}
    decl = "\n".join(f"        const double {name} = {value};" for name, value in candidates.items() if name in words)
    return f"{decl}\n{body}" if decl else body
