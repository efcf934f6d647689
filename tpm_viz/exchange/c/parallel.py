"""The parallel arrangement's closed form as C (``tpm_par_*`` in ``tpm_2ppa.c``), traced like :mod:`.code`.

The arithmetic comes from :mod:`tpm_viz.paper.parallel.kinematics` (eq. P3: ``_ik_unchecked``, then
``leg_components``) and :mod:`tpm_viz.paper.parallel.dynamics` (``_procedure``, eqs. P4-P14), called on symbols
held in object arrays; the refusals are the Python's: ``|p_2| >= l_a`` unreachable, ``|c_1 c_2| < tol l_a²``
(``cos θ1 cos θ2 = 0``) and ``|p_2 (c_1 + c_2)| < tol l_a²`` (``sin(θ1 + θ2) = 0``, eq. P6) singular.
"""

from __future__ import annotations

from string import Template
from types import SimpleNamespace
from typing import Any

import numpy as np

from tpm_viz.exchange.c.blocks import (
    FD_ARGS,
    ID_ARGS,
    IK_ARGS,
    JACOBIAN_ARGS,
    Cosines,
    Legs,
    c_function,
    copy_out,
    forward_dynamics,
    inverse_dynamics,
    jacobian,
    prototype,
    reachable,
    refuse,
    regular,
    traced_block,
    unpack,
)
from tpm_viz.exchange.c.expr import Graph
from tpm_viz.paper.parallel import dynamics as parallel_dynamics
from tpm_viz.paper.parallel import kinematics as parallel_kinematics

__all__ = ["parallel_fields"]


def _setup() -> tuple[SimpleNamespace, Any]:
    """The symbols, and a duck-typed stand-in for :class:`~tpm_viz.core.params.Params` (``Any`` for the type
    checker)."""
    g = Graph()
    v = SimpleNamespace(**{n: g.var(n) for n in "p1 p2 dp1 dp2 ddp1 ddp2 c1 c2 f1 f2 l_a offset m_a m_b m_p".split()})
    prm = SimpleNamespace(l_a=v.l_a, offset=v.offset, m_a=v.m_a, m_b=v.m_b, m_p=v.m_p)
    return v, prm


def _pair(x, y) -> np.ndarray:
    return np.array([x, y], dtype=object)


def _legs_body() -> str:
    v, prm = _setup()
    p = _pair(v.p1, v.p2)
    d = parallel_kinematics._ik_unchecked(prm, p)
    c = np.stack([p[..., 0] - d[..., 0], -p[..., 0] - d[..., 1]], axis=-1) + prm.offset  # as leg_components
    return traced_block(
        [
            (
                "eq. (P3): d_1 = p_1 + a - b - u, d_2 = -p_1 + a - b - u, u = sqrt(l_a^2 - p_2^2) [m]",
                [("d1", d[0]), ("d2", d[1])],
            ),
            ("inward reach c_i = l_a cos th_i (eq. P2) [m]", [("c1_", c[0]), ("c2_", c[1])]),
        ]
    )


def _procedure(v, prm, dp, ddp, f):
    return parallel_dynamics._procedure(prm, _pair(v.p1, v.p2), _pair(*dp), _pair(*ddp), _pair(v.c1, v.c2), _pair(*f))


def _jacobian_body() -> str:
    v, prm = _setup()
    cols = [_procedure(v, prm, e, (0.0, 0.0), (0.0, 0.0))[0] for e in ((1.0, 0.0), (0.0, 1.0))]
    entries = [("J11", cols[0][0]), ("J12", cols[1][0]), ("J21", cols[0][1]), ("J22", cols[1][1])]
    return traced_block([("J = dd/dp, eq. (P4): [[1, tan th1], [-1, tan th2]]", entries)])


def _id_body() -> str:
    v, prm = _setup()
    _, ddd, vv, w, lam, tau = _procedure(v, prm, (v.dp1, v.dp2), (v.ddp1, v.ddp2), (v.f1, v.f2))  # ḋ: not needed
    return traced_block(
        [
            ("(c) actuator accelerations, eq. (P5) [m/s^2]", [("ddd1", ddd[0]), ("ddd2", ddd[1])]),
            ("v_i of eq. (P11) [N]", [("v1", vv[0]), ("v2", vv[1])]),
            ("(d) Lagrange multipliers, eq. (P12) [N/m]", [("lam1", lam[0]), ("lam2", lam[1])]),
            ("w_i of eq. (P13) [N]", [("w1", w[0]), ("w2", w[1])]),
            ("(e) actuator forces, eq. (P14) [N]", [("tau1", tau[0]), ("tau2", tau[1])]),
        ]
    )


def _fd_body() -> str:
    v, prm = _setup()
    h = _procedure(v, prm, (v.dp1, v.dp2), (0.0, 0.0), (v.f1, v.f2))[5]
    m1 = _procedure(v, prm, (0.0, 0.0), (1.0, 0.0), (0.0, 0.0))[5]
    m2 = _procedure(v, prm, (0.0, 0.0), (0.0, 1.0), (0.0, 0.0))[5]
    return traced_block(
        [
            ("h = tau(p, dp, ddp = 0), eqs. (P4)-(P14) [N]", [("h1", h[0]), ("h2", h[1])]),
            (
                "M = [tau(p, 0, e_1), tau(p, 0, e_2)] [kg]",
                [("M11", m1[0]), ("M21", m1[1]), ("M12", m2[0]), ("M22", m2[1])],
            ),
        ]
    )


_PAR = ("tpm_par_inverse_kinematics", "tpm_par_jacobian", "tpm_par_inverse_dynamics", "tpm_par_forward_dynamics")
_PROTOTYPES = [prototype(n, a) for n, a in zip(_PAR, (IK_ARGS, JACOBIAN_ARGS, ID_ARGS, FD_ARGS), strict=True)]

DECLS = """
/* The parallel arrangement (Liu & Wang's 2-PPa: both rails on the X axis, docs/parallel.md, eqs. P1-P15), same
 * tpm_params, codes and conventions. Reachable: |p_2| < l_a (p_1 is free). Direct singularity: p_2 = 0. */
""" + "".join(f"{proto};\n" for proto in _PROTOTYPES)

_LEGS: Legs = ("double d[2], c[2];", "tpm_par_legs(prm, p, d, c)")
_REGULAR_CALL = "tpm_par_regular(prm, p, c)"
_C = unpack("c", "c")
_COSINES: Cosines = ("c[0] / prm->l_a", "c[1] / prm->l_a")  # cos th_i = c_i / l_a (eq. P2)

_HELPERS = (
    """
/* ---------------------------------------------------------------- the parallel arrangement (docs/parallel.md) */
static int tpm_par_legs(const tpm_params *prm, const double p[2], double d[2], double c[2])
{
"""
    + reachable(("fabs(p[1]) < prm->l_a",))
    + "    {\n$legs_body\n"
    + copy_out("d", ("d1", "d2"))
    + copy_out("c", ("c1_", "c2_"))
    + """    }
    return TPM_OK;
}

/* cos th1 cos th2 = c_1 c_2 / l_a^2; sin(th1 + th2) = p_2 (c_1 + c_2) / l_a^2 (eq. P6); then the margin on
 * cos th_i = c_i / l_a and det J_x = cos th1 sin th2 + sin th1 cos th2, as tpm_viz.paper.parallel.kinematics. */
"""
    + regular(
        "tpm_par_regular(const tpm_params *prm, const double p[2], const double c[2])",
        "c[0] * c[1]",
        "p[1] * (c[0] + c[1])",
        "TPM_SINGULAR_TOL",
        _COSINES,
        "k1 * (p[1] / prm->l_a) + (p[1] / prm->l_a) * k2",
    )
)

_FUNCTIONS = [
    c_function(
        _PROTOTYPES[0],
        ("double dd[2], c[2];", "tpm_par_legs(prm, p, dd, c)"),
        [],
        refuse("!tpm_finite2(dd)", "TPM_E_OVERFLOW") + copy_out("d", ("dd[0]", "dd[1]"), depth=1),
    ),
    jacobian(_PAR[1], _LEGS, ("c[0] * c[1]", _COSINES), "$jacobian_body", finite=("J12", "J22"), before=_C),
    inverse_dynamics(_PAR[2], _LEGS, _REGULAR_CALL, "$id_body", before=_C),
    forward_dynamics(_PAR[3], _LEGS, _REGULAR_CALL, "$fd_body", before=_C),
]

SOURCE = Template(_HELPERS + "".join("\n" + f for f in _FUNCTIONS))


def parallel_fields() -> dict[str, str]:
    """``{"parallel_decls": ..., "parallel_source": ...}`` for the templates of :mod:`.text`."""
    source = SOURCE.substitute(
        legs_body=_legs_body(), jacobian_body=_jacobian_body(), id_body=_id_body(), fd_body=_fd_body()
    )
    return {"parallel_decls": DECLS, "parallel_source": source}
