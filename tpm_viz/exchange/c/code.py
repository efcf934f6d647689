"""The closed form as C99 for a real-time controller: ``tpm_2ppa.h`` and ``tpm_2ppa.c``.

The arithmetic is not restated here: :mod:`.expr` traces the project's own Python functions on symbols and
prints what they compute, operation by operation:

- inverse kinematics, eq. (4): :func:`tpm_viz.paper.kinematics._ik_unchecked`;
- Jacobian ``J = ∂d/∂p``, eqs. (9)-(10): the ``ḋ = J ṗ`` step of :func:`tpm_viz.paper.dynamics._procedure`
  traced with ``ṗ = e_1`` and ``ṗ = e_2``;
- inverse dynamics, eqs. (9), (14)-(15) (corrected sign of ``J̇_q``), (28)-(31): ``_procedure`` itself;
- forward dynamics: the closed form is affine in ``p̈`` (no gravity), ``τ = M(p) p̈ + h(p, ṗ, f_ext)``, so
  ``h = τ(p, ṗ, 0)`` and the columns of ``M = τ(p, 0, e_j)`` are ``_procedure`` again; a 2x2 solve gives ``p̈``;
- computed torque: :func:`tpm_viz.paper.control.task_space_command` then ``_procedure`` at the measurement.

The symbols, ``J`` and the forward dynamics' ``h`` and ``M`` are traced alike for both arrangements
(:mod:`.tracing`). The checks are a short C skeleton per function (:mod:`.text`, the shape they share in
:mod:`.blocks`) with
the Python's own thresholds (:data:`tpm_viz.paper.dynamics.SINGULAR_TOL`, :data:`tpm_viz.paper.control.CTC_DIRECT_TOL`,
the default tolerance of :func:`tpm_viz.paper.kinematics.in_stroke`) and a margin in ``tpm_params`` (``min_cos``,
``min_det``: the rules of :func:`tpm_viz.app.moves.margins`, by default the app's move limits
:data:`tpm_viz.paper.status.MOVE_LIMITS`) inside which the dynamics refuse. C99, ``libm`` only, no allocation, no
global state; a function that refuses returns a non-zero code and leaves its outputs untouched. The parallel
arrangement's functions (``tpm_par_*``) come from :mod:`.parallel` the same way.
"""

from __future__ import annotations

import inspect
from types import SimpleNamespace

import numpy as np

from tpm_viz.core.params import Params
from tpm_viz.exchange.c.blocks import Stages, traced_block
from tpm_viz.exchange.c.parallel import parallel_fields
from tpm_viz.exchange.c.stamp import stamped
from tpm_viz.exchange.c.text import HEADER, SOURCE
from tpm_viz.exchange.c.tracing import Forces, forward_dynamics_stages, jacobian_entries, symbols
from tpm_viz.paper.control import CTC_DIRECT_TOL, task_space_command
from tpm_viz.paper.dynamics import SINGULAR_TOL, _procedure
from tpm_viz.paper.kinematics import _ik_unchecked, in_stroke
from tpm_viz.paper.status import MOVE_LIMITS

__all__ = ["FILES", "c_files"]

FILES = ("tpm_2ppa.h", "tpm_2ppa.c")
"""The names of the two generated files."""

_STAGES = (  # (slice of _procedure's outputs, names, comment)
    ((0, 2), ("dd1", "dd2"), "(b) actuator velocities, eq. (9): dd_i = dp_i + tan(theta_i) dp_j [m/s]"),
    ((2, 4), ("ddd1", "ddd2"), "(c) actuator accelerations, eq. (14) with the corrected sign of eq. (15) [m/s^2]"),
    ((4, 6), ("v1", "v2"), "v_i below eq. (29), less the external force f_i (eq. 28) [N]"),
    ((8, 10), ("lam1", "lam2"), "(d) Lagrange multipliers, eq. (29): G_p lam = v [N/m]"),
    ((6, 8), ("w1", "w2"), "w_i below eq. (31) [N]"),
    ((10, 12), ("tau1", "tau2"), "(e) actuator forces, eqs. (30)-(31): tau_i = w_i + 2 lam_i c_i [N]"),
)


def _ik_body() -> str:
    s = symbols()
    d = _ik_unchecked(s.params, np.array([s.p1, s.p2], dtype=object))
    return traced_block(
        [
            (
                "working-mode inverse kinematics, eq. (4): d_i = p_i + a - b - sqrt(l_a^2 - p_j^2) [m]",
                [("d1", d[0]), ("d2", d[1])],
            )
        ]
    )


def _forces(s: SimpleNamespace) -> Forces:
    """``(τ_1, τ_2)`` of :func:`~tpm_viz.paper.dynamics._procedure` at the state's ``p`` and ``c``."""
    return lambda dp, ddp, f: _procedure(s.params, s.p1, s.p2, *dp, *ddp, s.c1, s.c2, *f)[10:12]


def _jacobian_body() -> str:
    s = symbols()
    entries = jacobian_entries(
        lambda e1, e2: _procedure(s.params, s.p1, s.p2, e1, e2, 0.0, 0.0, s.c1, s.c2, 0.0, 0.0)[0:2]
    )
    return traced_block(
        [("J = dd/dp, eqs. (9)-(10): [[1, tan theta_1], [tan theta_2, 1]], tan theta_i = p_j / c_i", entries)]
    )


_CTC_ARRAYS = (("pr", "p_ref"), ("vr", "dp_ref"), ("ar", "ddp_ref"), ("kp", "kp"), ("kd", "kd"))
"""The control lab's C arrays and the locals of their components (``pr1`` is ``p_ref[0]``)."""


def _procedure_stages(out: tuple, suffix: str = "") -> Stages:
    return [
        (comment, [(n + suffix, out[k]) for n, k in zip(names, range(*sl), strict=True)])
        for sl, names, comment in _STAGES
    ]


def _id_body() -> str:
    s = symbols()
    out = _procedure(s.params, s.p1, s.p2, s.dp1, s.dp2, s.ddp1, s.ddp2, s.c1, s.c2, s.f1, s.f2)
    return traced_block(_procedure_stages(out))


def _fd_body() -> str:
    s = symbols()
    comments = (
        "velocity and external-force terms h = tau(p, dp, ddp = 0), eqs. (9)-(31) [N]",
        "mass matrix M = [tau(p, 0, e_1), tau(p, 0, e_2)], eqs. (14)-(31) [kg]",
    )
    return traced_block(forward_dynamics_stages(s, _forces(s), comments))


def _ctc_body() -> str:
    s = symbols("pr1 pr2 vr1 vr2 ar1 ar2 kp1 kp2 kd1 kd2")
    a1 = task_space_command(s.pr1, s.vr1, s.ar1, s.p1, s.dp1, s.kp1, s.kd1)
    a2 = task_space_command(s.pr2, s.vr2, s.ar2, s.p2, s.dp2, s.kp2, s.kd2)
    out = _procedure(s.params, s.p1, s.p2, s.dp1, s.dp2, a1, a2, s.c1, s.c2, 0.0, 0.0)
    stages = [
        ("the control lab's command, e = p_ref - p: a = ddp_ref + K_d de + K_p e [m/s^2]", [("a1", a1), ("a2", a2)])
    ]
    stages += _procedure_stages(out)
    extra = {f"{n}{i}": f"{array}[{i - 1}]" for n, array in _CTC_ARRAYS for i in (1, 2)}
    return traced_block(stages, extra)


def _params_initializer(params: Params) -> str:
    values = (params.a, params.b, params.l_a, params.m_a, params.m_b, params.m_p, params.stroke)
    return "{ " + ", ".join(repr(float(v)) for v in values) + ", TPM_MIN_COS_APP, TPM_MIN_DET_APP }"


def c_files(params: Params | None = None) -> dict[str, str]:
    """``{file name: text}`` of the generated C; ``params`` fills ``TPM_PARAMS_EXPORTED`` (default: the paper's).
    Each text ends with its content hash (:func:`.stamp.stamped`)."""
    params = Params.paper() if params is None else params
    stroke_tol = inspect.signature(in_stroke).parameters["tol"].default
    fields = {
        "singular_tol": repr(SINGULAR_TOL),
        "ctc_direct_tol": repr(CTC_DIRECT_TOL),
        "stroke_tol": repr(float(stroke_tol)),
        "min_cos": repr(MOVE_LIMITS.inverse),
        "min_det": repr(MOVE_LIMITS.direct),
        "exported": _params_initializer(params),
        "ik_body": _ik_body(),
        "jacobian_body": _jacobian_body(),
        "id_body": _id_body(),
        "fd_body": _fd_body(),
        "ctc_body": _ctc_body(),
        **parallel_fields(),
    }
    return {"tpm_2ppa.h": stamped(HEADER.substitute(fields)), "tpm_2ppa.c": stamped(SOURCE.substitute(fields))}
