"""The parallel arrangement's closed form as C (``tpm_par_*`` in ``tpm_2ppa.c``), traced like :mod:`.c_code`.

The arithmetic comes from :mod:`tpm_viz.paper.parallel_kinematics` (eq. P3: ``_ik_unchecked``, then
``leg_components``) and :mod:`tpm_viz.paper.parallel_dynamics` (``_procedure``, eqs. P4-P14), called on symbols
held in object arrays; the refusals are the Python's: ``|p_2| >= l_a`` unreachable, ``|c_1 c_2| < tol l_a²``
(``cos θ1 cos θ2 = 0``) and ``|p_2 (c_1 + c_2)| < tol l_a²`` (``sin(θ1 + θ2) = 0``, eq. P6) singular.
"""

from __future__ import annotations

from string import Template
from types import SimpleNamespace
from typing import Any

import numpy as np

from tpm_viz.exchange.c_expr import Emitter, Graph, Sym
from tpm_viz.paper import parallel_dynamics, parallel_kinematics

__all__ = ["parallel_fields"]

_LOCALS = {
    "l_a": "prm->l_a",
    "offset": "prm->a - prm->b",
    "m_a": "prm->m_a",
    "m_b": "prm->m_b",
    "m_p": "prm->m_p",
    "p1": "p[0]",
    "p2": "p[1]",
    "dp1": "dp[0]",
    "dp2": "dp[1]",
    "ddp1": "ddp[0]",
    "ddp2": "ddp[1]",
}


def _setup() -> tuple[SimpleNamespace, Any]:
    """The symbols, and a duck-typed stand-in for :class:`~tpm_viz.params.Params` (``Any`` for the type checker)."""
    g = Graph()
    v = SimpleNamespace(**{n: g.var(n) for n in "p1 p2 dp1 dp2 ddp1 ddp2 c1 c2 f1 f2 l_a offset m_a m_b m_p".split()})
    prm = SimpleNamespace(l_a=v.l_a, offset=v.offset, m_a=v.m_a, m_b=v.m_b, m_p=v.m_p)
    return v, prm


def _pair(x, y) -> np.ndarray:
    return np.array([x, y], dtype=object)


def _block(stages: list[tuple[str, list[tuple[str, Sym]]]]) -> str:
    body = Emitter(indent=" " * 8).emit(stages)
    words = set(body.replace("(", " ").replace(")", " ").replace(";", " ").split())
    decl = "\n".join(f"        const double {n} = {e};" for n, e in _LOCALS.items() if n in words)
    return f"{decl}\n{body}" if decl else body


def _legs_body() -> str:
    v, prm = _setup()
    p = _pair(v.p1, v.p2)
    d = parallel_kinematics._ik_unchecked(prm, p)
    c = np.stack([p[..., 0] - d[..., 0], -p[..., 0] - d[..., 1]], axis=-1) + prm.offset  # as leg_components
    return _block(
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
    return _block([("J = dd/dp, eq. (P4): [[1, tan th1], [-1, tan th2]]", entries)])


def _id_body() -> str:
    v, prm = _setup()
    _, ddd, vv, w, lam, tau = _procedure(v, prm, (v.dp1, v.dp2), (v.ddp1, v.ddp2), (v.f1, v.f2))  # ḋ: not needed
    return _block(
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
    return _block(
        [
            ("h = tau(p, dp, ddp = 0), eqs. (P4)-(P14) [N]", [("h1", h[0]), ("h2", h[1])]),
            (
                "M = [tau(p, 0, e_1), tau(p, 0, e_2)] [kg]",
                [("M11", m1[0]), ("M21", m1[1]), ("M12", m2[0]), ("M22", m2[1])],
            ),
        ]
    )


DECLS = """
/* The parallel arrangement (Liu & Wang's 2-PPa: both rails on the X axis, docs/parallel.md, eqs. P1-P15), same
 * tpm_params, codes and conventions. Reachable: |p_2| < l_a (p_1 is free). Direct singularity: p_2 = 0. */
int tpm_par_inverse_kinematics(const tpm_params *prm, const double p[2], double d[2]);
int tpm_par_jacobian(const tpm_params *prm, const double p[2], double J[4]);
int tpm_par_inverse_dynamics(const tpm_params *prm, const double p[2], const double dp[2], const double ddp[2],
                             const double f_ext[2], double tau[2]);
int tpm_par_forward_dynamics(const tpm_params *prm, const double p[2], const double dp[2], const double tau[2],
                             const double f_ext[2], double ddp[2]);
"""

SOURCE = Template(
    r"""
/* ---------------------------------------------------------------- the parallel arrangement (docs/parallel.md) */
static int tpm_par_legs(const tpm_params *prm, const double p[2], double d[2], double c[2])
{
    if (!tpm_params_ok(prm)) {
        return TPM_E_PARAMS;
    }
    if (!tpm_finite2(p)) {
        return TPM_E_NONFINITE;
    }
    if (!(fabs(p[1]) < prm->l_a)) {
        return TPM_E_UNREACHABLE;
    }
    {
$legs_body
        d[0] = d1;
        d[1] = d2;
        c[0] = c1_;
        c[1] = c2_;
    }
    return TPM_OK;
}

/* cos th1 cos th2 = c_1 c_2 / l_a^2; sin(th1 + th2) = p_2 (c_1 + c_2) / l_a^2 (eq. P6) */
static int tpm_par_regular(const tpm_params *prm, const double p[2], const double c[2])
{
    const double la2 = prm->l_a * prm->l_a;
    if (fabs(c[0] * c[1]) < TPM_SINGULAR_TOL * la2) {
        return TPM_E_SINGULAR_INVERSE;
    }
    if (fabs(p[1] * (c[0] + c[1])) < TPM_SINGULAR_TOL * la2) {
        return TPM_E_SINGULAR_DIRECT;
    }
    return TPM_OK;
}

int tpm_par_inverse_kinematics(const tpm_params *prm, const double p[2], double d[2])
{
    double dd[2], c[2];
    const int rc = tpm_par_legs(prm, p, dd, c);
    if (rc != TPM_OK) {
        return rc;
    }
    if (!tpm_finite2(dd)) {
        return TPM_E_OVERFLOW;
    }
    d[0] = dd[0];
    d[1] = dd[1];
    return TPM_OK;
}

int tpm_par_jacobian(const tpm_params *prm, const double p[2], double J[4])
{
    double d[2], c[2];
    int rc = tpm_par_legs(prm, p, d, c);
    if (rc != TPM_OK) {
        return rc;
    }
    if (fabs(c[0] * c[1]) < TPM_SINGULAR_TOL * (prm->l_a * prm->l_a)) {
        return TPM_E_SINGULAR_INVERSE;
    }
    {
        const double c1 = c[0];
        const double c2 = c[1];
$jacobian_body
        if (!(isfinite(J12) && isfinite(J22))) {
            return TPM_E_OVERFLOW;
        }
        J[0] = J11;
        J[1] = J12;
        J[2] = J21;
        J[3] = J22;
    }
    return TPM_OK;
}

int tpm_par_inverse_dynamics(const tpm_params *prm, const double p[2], const double dp[2], const double ddp[2],
                             const double f_ext[2], double tau[2])
{
    double d[2], c[2];
    int rc = tpm_par_legs(prm, p, d, c);
    if (rc != TPM_OK) {
        return rc;
    }
    if (!(tpm_finite2(dp) && tpm_finite2(ddp) && (f_ext == NULL || tpm_finite2(f_ext)))) {
        return TPM_E_NONFINITE;
    }
    rc = tpm_par_regular(prm, p, c);
    if (rc != TPM_OK) {
        return rc;
    }
    {
        const double c1 = c[0];
        const double c2 = c[1];
        const double f1 = f_ext == NULL ? 0.0 : f_ext[0];
        const double f2 = f_ext == NULL ? 0.0 : f_ext[1];
$id_body
        if (!(isfinite(tau1) && isfinite(tau2))) {
            return TPM_E_OVERFLOW;
        }
        tau[0] = tau1;
        tau[1] = tau2;
    }
    return TPM_OK;
}

int tpm_par_forward_dynamics(const tpm_params *prm, const double p[2], const double dp[2], const double tau[2],
                             const double f_ext[2], double ddp[2])
{
    double d[2], c[2];
    int rc = tpm_par_legs(prm, p, d, c);
    if (rc != TPM_OK) {
        return rc;
    }
    if (!(tpm_finite2(dp) && tpm_finite2(tau) && (f_ext == NULL || tpm_finite2(f_ext)))) {
        return TPM_E_NONFINITE;
    }
    rc = tpm_par_regular(prm, p, c);
    if (rc != TPM_OK) {
        return rc;
    }
    {
        const double c1 = c[0];
        const double c2 = c[1];
        const double f1 = f_ext == NULL ? 0.0 : f_ext[0];
        const double f2 = f_ext == NULL ? 0.0 : f_ext[1];
$fd_body
        const double det = M11 * M22 - M12 * M21;
        const double r1 = tau[0] - h1;
        const double r2 = tau[1] - h2;
        const double a1 = (M22 * r1 - M12 * r2) / det;
        const double a2 = (M11 * r2 - M21 * r1) / det;
        if (!(isfinite(a1) && isfinite(a2))) {
            return TPM_E_OVERFLOW;
        }
        ddp[0] = a1;
        ddp[1] = a2;
    }
    return TPM_OK;
}
"""
)


def parallel_fields() -> dict[str, str]:
    """``{"parallel_decls": ..., "parallel_source": ...}`` for the templates of :mod:`.c_text`."""
    source = SOURCE.substitute(
        legs_body=_legs_body(), jacobian_body=_jacobian_body(), id_body=_id_body(), fd_body=_fd_body()
    )
    return {"parallel_decls": DECLS, "parallel_source": source}
