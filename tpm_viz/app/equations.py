"""The paper's procedure (a)-(e) with live numbers, as HTML with MathML (for the app's equations panel).

viser's Markdown does not render LaTeX; MathML inside an HTML block does render in the browser. Every
number comes from :func:`tpm_viz.inverse_dynamics_detail` and :func:`tpm_viz.paper.jacobians`; this module only
formats (mm, mm/s, mm/s², N, N/m) and never computes physics of its own. Non-finite numbers are shown as
"—" so that nothing like NaN or inf reaches the screen. The words are phrases (:mod:`tpm_viz.core.words`), rendered in
the language asked for (the app's tab, ``tpm-viz report --lang``); the formulas are the same in every language.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable
from typing import SupportsFloat

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.markup import Html
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.paper.dynamics import DynamicsResult
from tpm_viz.paper.jacobians import Jacobians

__all__ = ["ERRATA_HTML", "errata_html", "procedure_html"]

_STEPS = (
    T(
        "<b>(a) Inverse kinematics, eq. (4).</b> Each slider sits one link length behind the platform joint, "
        "measured along its rail:"
    ),
    T(
        "<b>(b) Velocities, eq. (9).</b> ḋ = J ṗ with J = J<sub>q</sub><sup>−1</sup> J<sub>x</sub> "
        "= [[1, tan θ<sub>1</sub>], [tan θ<sub>2</sub>, 1]] (eq. 10):"
    ),
    T(
        "<b>(c) Accelerations, eq. (14)</b> with the corrected eq. (15): "
        "J̇<sub>q</sub> = diag(<b>−</b>sin θ<sub>i</sub> θ̇<sub>i</sub>) (the paper prints +):"
    ),
    T(
        "<b>(d) Lagrange multipliers, eqs. (28)-(29).</b> The constraint forces that keep each link at "
        "length l<sub>a</sub>; v<sub>i</sub> gathers the platform's inertia terms, f the external load:"
    ),
    T(
        "<b>(e) Actuator forces, eq. (31).</b> The slider's own inertia w<sub>i</sub> plus the pull of "
        "its leg's constraint, 2 λ<sub>i</sub> (p<sub>i</sub> − d<sub>i</sub> + a − b):"
    ),
)
"""The words of steps (a)-(e), each above its formulas (HTML: the template keeps its tags in every language)."""
_DET = T(
    "det J<sub>x</sub> = cos(θ<sub>1</sub> + θ<sub>2</sub>) = {det}: the matrix of (d) has determinant "
    "4 l<sub>a</sub>² det J<sub>x</sub>, so the multipliers, and with them the forces, grow without bound at the "
    "direct singularity."
)
_ERRATA_HEAD = T("<b>Errata confirmed numerically</b> (evidence in docs/model.md and the test suite):")
_ERRATA = (
    Phrase(
        "Eq. (15): the derivative of cos θ<sub>i</sub> is −sin θ<sub>i</sub> θ̇<sub>i</sub>; the paper prints +. "
        "Finite differences of eq. (4) agree with the corrected sign to {tol}; with the printed sign the circle's "
        "forces change by up to {change} N, as large as the paper's {gap} N gap to ADAMS.",
        tol="1e-6",
        change=10,
        gap=9,
    ),
    T(
        "Eq. (22): the last bracket needs ḋ<sub>i</sub>², not d<sub>i</sub>² (as printed the energy is not zero "
        "at rest)."
    ),
    T("Eq. (28): d/dt(∂L/∂ṗ<sub>j</sub>), not ∂L/∂p<sub>j</sub>, in the first bracket."),
    T("Eqs. (7)-(8): the actuator Jacobian is called J<sub>d</sub> in eq. (7) and J<sub>q</sub> after."),
)


def _num(x: float, digits: int = 1) -> str:
    x = float(x)
    if not math.isfinite(x):
        return "<mn>—</mn>"
    text = f"{x:.{digits}f}" if abs(x) < 1e6 else f"{x:.3e}"
    if text.startswith("-"):
        return f"<mo>−</mo><mn>{text[1:]}</mn>"
    return f"<mn>{text}</mn>"


def _row(*parts: str) -> str:
    return "<mrow>" + "".join(parts) + "</mrow>"


def _sub(base: str, index: str) -> str:
    return f"<msub><mi>{base}</mi><mn>{index}</mn></msub>"


def _vec(values: Iterable[float], digits: int = 1) -> str:
    rows = "".join(f"<mtr><mtd>{_num(v, digits)}</mtd></mtr>" for v in values)
    return f"<mrow><mo>[</mo><mtable>{rows}</mtable><mo>]</mo></mrow>"


def _mat(m: Iterable[Iterable[float]], digits: int = 3) -> str:
    rows = "".join("<mtr>" + "".join(f"<mtd>{_num(v, digits)}</mtd>" for v in r) + "</mtr>" for r in m)
    return f"<mrow><mo>[</mo><mtable>{rows}</mtable><mo>]</mo></mrow>"


def _math(*parts: str) -> str:
    """A display formula in a box of the panel's width that scrolls sideways when the matrices are wider."""
    return '<div style="overflow-x:auto;max-width:100%"><math display="block">' + _row(*parts) + "</math></div>"


def _unit(text: str) -> str:
    return f'<mspace width="0.4em"/><mtext>{html.escape(text)}</mtext>'


def procedure_html(
    params: Params, res: DynamicsResult, jac: Jacobians, f_ext: ArrayLike = (0.0, 0.0), lang: Lang = Lang.EN
) -> Html:
    """HTML of steps (a)-(e) for one state (arrays of shape ``(2,)`` in ``res``), numbers substituted, words in
    ``lang``.

    Lengths in mm, velocities in mm/s, accelerations in mm/s², multipliers in N/m, forces in N.
    """
    mm = 1e3
    c = res.p - res.d + params.offset
    g = np.array([[2 * c[0], 2 * res.p[0]], [2 * res.p[1], 2 * c[1]]])
    f = np.asarray(f_ext, dtype=float)
    step = [f"<p>{say(lang, words)}</p>" for words in _STEPS]
    parts = [
        step[0],
        _math(
            _sub("d", "i"),
            "<mo>=</mo>",
            _sub("p", "i"),
            "<mo>+</mo><mi>a</mi><mo>−</mo><mi>b</mi><mo>−</mo>",
            "<msqrt>",
            _sub("l", "a"),
            "<msup><mi></mi><mn>2</mn></msup><mo>−</mo>",
            "<msubsup><mi>p</mi><mi>j</mi><mn>2</mn></msubsup></msqrt>",
        ),
        _math(
            _vec(res.d * mm),
            _unit("mm"),
            "<mo>=</mo>",
            _vec(res.p * mm),
            "<mo>+</mo>",
            _num(params.offset * mm),
            "<mo>−</mo>",
            _vec((res.p - res.d + params.offset) * mm),
            _unit("mm"),
        ),
        step[1],
        _math(_vec(res.dd * mm), _unit("mm/s"), "<mo>=</mo>", _mat(jac.j), _vec(res.dp * mm), _unit("mm/s")),
        step[2],
        _math(
            _vec(res.ddd * mm),
            _unit("mm/s²"),
            "<mo>=</mo>",
            "<msubsup><mi>J</mi><mi>q</mi><mn>−1</mn></msubsup>",
            "<mo>(</mo><msub><mover><mi>J</mi><mo>˙</mo></mover><mi>x</mi></msub><mover><mi>p</mi><mo>˙</mo></mover>",
            "<mo>+</mo><msub><mi>J</mi><mi>x</mi></msub><mover><mi>p</mi><mo>¨</mo></mover><mo>−</mo>",
            "<msub><mover><mi>J</mi><mo>˙</mo></mover><mi>q</mi></msub><mover><mi>d</mi><mo>˙</mo></mover><mo>)</mo>",
        ),
        step[3],
        _math(  # two lines: the result stays in view in a narrow panel
            '<mtable columnalign="left"><mtr><mtd>',
            _row(
                "<mi>λ</mi><mo>=</mo>",
                _mat(g, 4),
                "<msup><mi></mi><mn>−1</mn></msup>",
                _unit("m⁻¹"),
                "<mo>(</mo>",
                _vec(res.v, 2),
                "<mo>−</mo>",
                _vec(f, 2),
                "<mo>)</mo>",
                _unit("N"),
            ),
            "</mtd></mtr><mtr><mtd>",
            _row("<mspace width='1em'/><mo>=</mo>", _vec(res.lam, 1), _unit("N/m")),
            "</mtd></mtr></mtable>",
        ),
        step[4],
        _math(
            "<mi>τ</mi><mo>=</mo>",
            _vec(res.w, 2),
            "<mo>+</mo><mn>2</mn>",
            _vec(res.lam, 1),
            "<mo>∘</mo>",
            _vec(c, 4),
            _unit("m"),
            "<mo>=</mo>",
            _vec(res.tau, 2),
            _unit("N"),
        ),
        f"<p>{say(lang, Phrase(_DET.template, det=_plain(jac.det_jx)))}</p>",
    ]
    # contain:inline-size: the panel's width decides the block's width, not the widest matrix (which scrolls)
    return Html(
        '<div class="tpm-equations" style="contain:inline-size;padding-right:10px">' + "".join(parts) + "</div>"
    )


def _plain(x: str | SupportsFloat) -> str:
    x = float(x)
    return f"{x:.4f}" if math.isfinite(x) else "—"


def errata_html(lang: Lang = Lang.EN) -> Html:
    """The confirmed errata, as HTML in ``lang``, for the equations panel and the lab report."""
    items = "".join(f"<li>{say(lang, item)}</li>" for item in _ERRATA)
    return Html(
        f'<div style="contain:inline-size;padding-right:10px"><p>{say(lang, _ERRATA_HEAD)}</p><ol>{items}</ol></div>'
    )


ERRATA_HTML = errata_html()
"""The confirmed errata, as HTML, in English."""
