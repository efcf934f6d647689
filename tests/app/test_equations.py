"""The equations panel: well-formed MathML, the numbers of the procedure (a)-(e), never NaN or inf."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tpm_viz import Params, inverse_dynamics_detail
from tpm_viz.app.equations import ERRATA_HTML, procedure_html
from tpm_viz.paper.jacobians import jacobians

P = Params.paper()
NON_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


def _render(p, dp, ddp, f=(0.0, 0.0)):
    res = inverse_dynamics_detail(P, p, dp, ddp, f_ext=f)
    return res, procedure_html(P, res, jacobians(P, p), f)


def test_html_is_well_formed_and_carries_the_forces():
    res, text = _render([0.05, -0.03], [0.4, 0.2], [3.0, -2.0], f=(4.0, 1.0))
    root = ET.fromstring(text)  # well-formed XML
    assert root.tag == "div" and len(root.findall(".//math")) == 6  # (a) two, (b)-(e) one each
    # the last vector of step (e) is tau in N, to 2 decimals, equal to an independent re-derivation:
    # tau_i = w_i + 2 lam_i (p_i - d_i + a - b)
    c = res.p - res.d + P.a - P.b
    expected = res.w + 2 * res.lam * c
    step_e = text.split("(e) Actuator forces")[1]
    numbers = [float(x) for x in re.findall(r"<mn>([0-9.]+)</mn>", step_e.split("<mo>=</mo>")[-1])][:2]
    signs = [-1 if "−" in chunk else 1 for chunk in step_e.split("<mo>=</mo>")[-1].split("</mtr>")[:2]]
    assert np.array(numbers) * signs == pytest.approx(expected, abs=0.006)
    assert not NON_FINITE.search(text)


def test_non_finite_numbers_never_reach_the_screen():
    res, _ = _render([0.0, 0.0], [0.0, 0.0], [0.0, 0.0])
    broken = res.__class__(**{**res.__dict__, "tau": np.array([np.nan, np.inf])})
    text = procedure_html(P, broken, jacobians(P, [0.0, 0.0]))
    assert not NON_FINITE.search(text) and "—" in text


def test_errata_name_each_equation():
    for eq in ("(15)", "(22)", "(28)", "(7)"):
        assert eq in ERRATA_HTML
