"""The parallel arrangement's closed form as C (``tpm_par_*`` in ``tpm_2ppa.c``), traced like :mod:`.code`.

The arithmetic comes from :mod:`tpm_viz.paper.parallel.kinematics` (eq. P3: ``_ik_unchecked``, then
``leg_components``) and :mod:`tpm_viz.paper.parallel.dynamics` (``_procedure``, eqs. P4-P14), called on symbols
held in object arrays (the symbols, ``J`` and ``h``, ``M`` traced as the perpendicular ones, :mod:`.tracing`); the
refusals are the Python's: ``|p_2| >= l_a`` unreachable, ``|c_1 c_2| < tol l_a²``
(``cos θ1 cos θ2 = 0``) and ``|p_2 (c_1 + c_2)| < tol l_a²`` (``sin(θ1 + θ2) = 0``, eq. P6) singular.
"""

from __future__ import annotations

from string import Template
from types import SimpleNamespace

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
from tpm_viz.exchange.c.tracing import Component, Pair, forward_dynamics_stages, jacobian_entries, symbols
from tpm_viz.paper.parallel import dynamics as parallel_dynamics
from tpm_viz.paper.parallel import kinematics as parallel_kinematics

__all__ = ["parallel_fields"]


def _pair(x: Component, y: Component) -> np.ndarray:
    return np.array([x, y], dtype=object)


def _legs_body() -> str:
    s = symbols()
    p = _pair(s.p1, s.p2)
    d = parallel_kinematics._ik_unchecked(s.params, p)
    c = np.stack([p[..., 0] - d[..., 0], -p[..., 0] - d[..., 1]], axis=-1) + s.params.offset  # as leg_components
    return traced_block(
        [
            (
                "eq. (P3): d_1 = p_1 + a - b - u, d_2 = -p_1 + a - b - u, u = sqrt(l_a^2 - p_2^2) [m]",
                [("d1", d[0]), ("d2", d[1])],
            ),
            ("inward reach c_i = l_a cos th_i (eq. P2) [m]", [("c1_", c[0]), ("c2_", c[1])]),
        ]
    )


def _procedure(s: SimpleNamespace, dp: Pair, ddp: Pair, f: Pair) -> tuple[np.ndarray, ...]:
    """:func:`tpm_viz.paper.parallel.dynamics._procedure` on the symbols: ``(dd, ddd, v, w, lam, tau)``, pairs."""
    return parallel_dynamics._procedure(
        s.params, _pair(s.p1, s.p2), _pair(*dp), _pair(*ddp), _pair(s.c1, s.c2), _pair(*f)
    )


def _jacobian_body() -> str:
    s = symbols()
    entries = jacobian_entries(lambda e1, e2: _procedure(s, (e1, e2), (0.0, 0.0), (0.0, 0.0))[0])
    return traced_block([("J = dd/dp, eq. (P4): [[1, tan th1], [-1, tan th2]]", entries)])


def _id_body() -> str:
    s = symbols()
    _, ddd, vv, w, lam, tau = _procedure(s, (s.dp1, s.dp2), (s.ddp1, s.ddp2), (s.f1, s.f2))  # ḋ: not needed
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
    s = symbols()
    comments = ("h = tau(p, dp, ddp = 0), eqs. (P4)-(P14) [N]", "M = [tau(p, 0, e_1), tau(p, 0, e_2)] [kg]")
    return traced_block(forward_dynamics_stages(s, lambda dp, ddp, f: _procedure(s, dp, ddp, f)[5], comments))


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
