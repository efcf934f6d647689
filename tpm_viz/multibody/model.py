"""An independent closed-loop multibody model of the 2-PPa TPM in Pinocchio (the role ADAMS played).

Only :mod:`tpm_viz.multibody` imports :mod:`pinocchio`. The model is built from a :class:`~tpm_viz.Params` (no
model file) with the pieces of :mod:`tpm_viz.multibody.tree`, zero gravity (the paper's ``U = 0``), SI units.

Tree, in the depth-first order Pinocchio needs (``crba`` silently assumes every subtree is
contiguous in ``v``), so ``q = (d_1, φ_10, φ_p, φ_11, d_2, φ_20, φ_21)`` (see
:attr:`MultibodyModel.index`)::

    universe ─PX─ slider1 (origin A_1 = (d_1 - a) e_1) ─RZ─ link1_0 (pivot A_1) ─RZ─ platform (pivot B_1)
                                                      └RZ─ link1_1 (pivot A_1 + s e_2)
    universe ─PY─ slider2 (origin A_2 = (d_2 - a) e_2) ─RZ─ link2_0 (pivot A_2)
                                                      └RZ─ link2_1 (pivot A_2 + s e_1)

``s`` is the pivot spacing; each link frame has its x axis along the link, so ``φ_1k = θ_1``,
``φ_2k = -θ_2`` (docs/conventions.md) and ``φ_p = -θ_1`` keeps the platform translating. Loop closures:
three ``RigidConstraintModel(CONTACT_3D, LOCAL_WORLD_ALIGNED)`` joining the tips of link1_1,
link2_0 and link2_1 to ``B_1 + s e_2``, ``B_2 = P - b e_2`` and ``B_2 + s e_1`` on the platform.
Masses (docs/conventions.md): sliders ``m_a`` and platform ``m_p`` as point masses (the platform never
rotates, so its rotational inertia does not enter), each link a uniform slender rod of mass
``m_b / 2`` along its x axis: ``I_xx = 0``, ``I_yy = I_zz = m l_a² / 12`` about its centre.

Over-constraint. The 9 closure rows have rank 5: the 3 out-of-plane rows vanish identically and
one in-plane row is redundant (both parallelograms fix the platform's orientation, the paper's
"overlapped rotational constraints"). Nothing here picks rows; the solves use SVDs that reveal
the rank (:mod:`tpm_viz.multibody.rank`). Inverse dynamics: the prescribed platform motion gives
``A = [J_c; J_P]`` (rank 7 checked), ``v``, ``a`` and ``N = A⁺ [0; I]``, whose columns span the
null space of ``J_c`` (the 2 admissible motions, checked). Then
``rnea(q, v, a) - J_Pᵀ f_ext = Sᵀ τ + J_cᵀ λ`` is solved in the least-squares sense by projecting on
``N``: ``Nᵀ Sᵀ τ = Nᵀ (rnea - J_Pᵀ f_ext)`` (``Nᵀ Sᵀ`` is the paper's ``Jᵀ``). Only ``J_cᵀ λ`` is
defined, not the redundant part of ``λ``; since the null space is the same for every maximal
independent subset of rows, ``τ`` does not depend on which redundant row one would keep (the tests
solve the square system for every such subset). Forward dynamics
(:meth:`MultibodyModel.forward_dynamics`) is our own KKT solve on the null space from the SVD of
``J_c`` (Gauss's principle) with Pinocchio's ``crba``, ``nle`` and constraint Jacobian; the docstring
of :func:`tpm_viz.multibody.forward.forward_dynamics` says why not ``pinocchio.constraintDynamics``.

Split by concept: this module builds the model and holds every Pinocchio evaluation and the inverse
dynamics; :mod:`tpm_viz.multibody.assembly` (a mixin) the closed-loop kinematics (Newton on the
closures); :mod:`tpm_viz.multibody.forward` the forward dynamics (KKT solve, projection, and the fast
2-DOF :class:`~tpm_viz.multibody.forward.PlatformPlant` of the control lab). The public methods are here.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Callable

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError, SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.multibody import forward
from tpm_viz.multibody.assembly import DOF, ClosedLoopAssembly, ThreeArrays
from tpm_viz.multibody.locking import locked
from tpm_viz.multibody.rank import RankedSvd, ranked_svd
from tpm_viz.multibody.tree import Built, closed_tree, point_mass, rod, se3
from tpm_viz.paper.kinematics import as_xy

__all__ = ["PART_NAMES", "MultibodyModel", "checked_model", "inverse_dynamics", "model_for"]

PART_NAMES = ("slider1", "slider2", "link1_0", "link1_1", "link2_0", "link2_1", "platform")
"""Keys of :meth:`MultibodyModel.placements`, also the Pinocchio joint names (and frame names)."""

_SINGULAR_RTOL = 1e-9


def _build(params: Params) -> Built:
    """The Pinocchio model, its constraint models (LOCAL_WORLD_ALIGNED) and the part frame ids."""
    a, b, la, sp = params.a, params.b, params.l_a, params.pivot_spacing
    e = np.eye(3)
    link, leg2 = rod(params.m_b / 2.0, la), np.pi / 2  # leg 2's link frames: x along e_2 at φ = 0
    # Depth-first order (Pinocchio's crba needs every subtree contiguous in v):
    # (name, parent, joint, placement in parent, body inertia).
    tree = [
        ("slider1", "universe", pin.JointModelPX(), se3(-a * e[0]), point_mass(params.m_a)),
        ("link1_0", "slider1", pin.JointModelRZ(), se3([0, 0, 0]), link),
        ("platform", "link1_0", pin.JointModelRZ(), se3([la, 0, 0]), point_mass(params.m_p, [b, 0, 0])),
        ("link1_1", "slider1", pin.JointModelRZ(), se3(sp * e[1]), link),
        ("slider2", "universe", pin.JointModelPY(), se3(-a * e[1]), point_mass(params.m_a)),
        ("link2_0", "slider2", pin.JointModelRZ(), se3([0, 0, 0], leg2), link),
        ("link2_1", "slider2", pin.JointModelRZ(), se3(sp * e[0], leg2), link),
    ]
    on_platform = {"link1_1": [0, sp, 0], "link2_0": [b, -b, 0], "link2_1": [b + sp, -b, 0]}  # from B_1
    return closed_tree(params, tree, on_platform)


class MultibodyModel(ClosedLoopAssembly):
    """The closed-loop Pinocchio model of one parameter set (see the module docstring).

    Public methods take platform quantities as ``(2,)`` (or ``(..., 2)`` where stated) arrays in SI
    units and raise :mod:`tpm_viz.core.errors` exceptions with one-line messages. Methods are serialised
    by a lock (Pinocchio's ``Data`` is shared scratch memory).
    """

    _build_model = staticmethod(_build)  # the tree, closures and frames; another arrangement overrides it

    def __init__(self, params: Params) -> None:
        if not isinstance(params, Params):
            raise InputError(f"MultibodyModel needs a tpm_viz.Params, got {type(params).__name__}")
        self.params = params
        self.model, self.constraint_models, self._frames = self._build_model(params)
        """``pinocchio.Model`` and the three ``RigidConstraintModel`` loop closures (LOCAL_WORLD_ALIGNED)."""
        self.data = self.model.createData()
        self._cmodel_vec = pin.StdVec_RigidConstraintModel()
        self._cdatas = pin.StdVec_RigidConstraintData()  # holds references: calc() updates these
        for c in self.constraint_models:
            self._cmodel_vec.append(c)
            self._cdatas.append(c.createData())
        self._lock = threading.RLock()
        self.index = {n: self.model.joints[self.model.getJointId(n)].idx_q for n in PART_NAMES}
        """Position of each joint coordinate in ``q`` (and ``v``): Pinocchio's depth-first order."""
        self._slider_idx = np.array([self.index["slider1"], self.index["slider2"]])
        self._angle_idx = np.array([self.index[n] for n in PART_NAMES[2:]])  # φ_10, φ_11, φ_20, φ_21, φ_p
        self._s_t = np.zeros((self.model.nv, DOF))  # Sᵀ: actuator forces -> generalised forces
        self._s_t[self._slider_idx, [0, 1]] = 1.0
        self._select_platform = np.zeros((len(self.constraint_models) * 3 + DOF, DOF))  # [0; I]
        self._select_platform[-DOF:] = np.eye(DOF)
        self._last = None  # warm start (p, q, ∂q/∂p)

    # ----------------------------------------------------------------- Pinocchio evaluations
    def _closure_terms(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World closure residual ``Φ(q)`` (9,) [m] and its Jacobian ``J_c`` (9, 7).

        Order matters (docs/pinocchio.md): joint Jacobians and placements at ``q`` first, then
        ``calc`` of each constraint, then the constraint Jacobian (all three in one call).
        """
        m, d = self.model, self.data
        pin.computeJointJacobians(m, d, q)  # also runs forwardKinematics(q)
        res = np.empty(3 * len(self._cdatas))
        for k, (cm, cd) in enumerate(zip(self.constraint_models, self._cdatas, strict=True)):
            cm.calc(m, d, cd)
            res[3 * k : 3 * k + 3] = cd.oMc1.translation - cd.oMc2.translation
        return res, pin.getConstraintsJacobian(m, d, self._cmodel_vec, self._cdatas)

    def _platform_jacobian(self) -> np.ndarray:
        """In-plane translational Jacobian ``J_P`` (2, 7) of P (after :meth:`_closure_terms`)."""
        j = pin.getFrameJacobian(self.model, self.data, self._frames["platform"], pin.LOCAL_WORLD_ALIGNED)
        return j[:2]

    def _drifts(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``γ_c = J̇_c v`` (9,) and ``J̇_P v`` (2,): classical accelerations at ``a = 0`` [m/s²]."""
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, q, v, np.zeros(m.nv))
        lwa = pin.LOCAL_WORLD_ALIGNED
        gamma = [
            pin.getFrameClassicalAcceleration(m, d, c.joint1_id, c.joint1_placement, lwa).linear
            - pin.getFrameClassicalAcceleration(m, d, c.joint2_id, c.joint2_placement, lwa).linear
            for c in self.constraint_models
        ]
        fp = m.frames[self._frames["platform"]]
        acc_p = pin.getFrameClassicalAcceleration(m, d, fp.parentJoint, fp.placement, lwa).linear
        return np.concatenate(gamma), acc_p[:2]

    def _closure_svd(self, jc: np.ndarray) -> RankedSvd:
        """Rank-revealing SVD of ``J_c``; its null space is the 2 admissible motions (rank 5 expected)."""
        svd = ranked_svd(jc)
        if self.model.nv - svd.rank != DOF:
            raise SingularConfigurationError(
                Phrase(
                    "singular configuration: the closure Jacobian has rank {rank}, not {full} (a parallelogram is "
                    "folded, cos θ_i = 0, eq. 11)",
                    rank=svd.rank,
                    full=self.model.nv - DOF,
                )
            )
        return svd

    def _mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space mass matrix ``M(q)`` (7, 7) from ``crba`` (symmetrised: C++ fills the upper triangle)."""
        mass = pin.crba(self.model, self.data, q)
        return np.triu(mass) + np.triu(mass, 1).T

    def _nle(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Nonlinear effects ``C(q, v) v`` (7,) (no gravity: the plane is horizontal)."""
        return pin.nle(self.model, self.data, q, v)

    def rnea_function(self) -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
        """``rnea(q, v, a)`` (7,) of the tree bound to a *new* Pinocchio ``Data``: for a caller that
        evaluates many states (:class:`tpm_viz.multibody.forward.PlatformPlant`) without the model lock."""
        model, data, rnea = self.model, self.model.createData(), pin.rnea
        return lambda q, v, a: rnea(model, data, q, v, a)

    # ----------------------------------------------------------------- closed-loop kinematics: assembly.py
    def _platform_position_now(self) -> np.ndarray:
        return pin.updateFramePlacement(self.model, self.data, self._frames["platform"]).translation[:2].copy()

    @locked
    def platform_position(self, q: ArrayLike) -> np.ndarray:
        """Platform position ``P`` (2,) [m] of configuration ``q``."""
        pin.forwardKinematics(self.model, self.data, self._as_q(q))
        return self._platform_position_now()

    @locked
    def closure_terms(self, q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Loop-closure residual ``Φ(q)`` (9,) [m] (world, 3 rows per closure) and Jacobian ``J_c`` (9, 7)."""
        phi, jc = self._closure_terms(self._as_q(q))
        return phi.copy(), jc.copy()

    @locked
    def constraint_violation(self, q: ArrayLike) -> float:
        """Largest loop-closure gap [m] (distance between the two sides of a closure) at ``q``."""
        phi, _ = self._closure_terms(self._as_q(q))
        return float(np.max(np.linalg.norm(phi.reshape(-1, 3), axis=1)))

    @locked
    def placements(self, q: ArrayLike) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """``{part: (position (3,) [m], quaternion wxyz (4,))}`` for :data:`PART_NAMES`.

        Sliders: at ``A_i``; links: at their slider-side pivot, local x along the link (length
        ``l_a``); platform: at ``P``. Every part lies in the plane ``z = 0``.
        """
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, self._as_q(q))
        out = {}
        for name in PART_NAMES:
            placement = pin.updateFramePlacement(m, d, self._frames[name])
            x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
            out[name] = (placement.translation.copy(), np.array([w, x, y, z]))
        return out

    def _as_q(self, q: ArrayLike) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.model.nq,) or not np.all(np.isfinite(q)):
            raise InputError(f"q must be a finite array of shape ({self.model.nq},), got shape {q.shape}")
        return q

    # ----------------------------------------------------------------- dynamics
    def _motion(self, p: np.ndarray, dp: np.ndarray, ddp: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(q, v, a, N, J_P)`` for a prescribed platform motion, with ``J_c v = 0``, ``J_c a + γ = 0``.

        ``A = [J_c; J_P]`` (11, 7) must have full column rank (else eq. 11). ``N = A⁺ [0; I]`` (7, 2)
        maps platform velocities to joint velocities; its columns span the null space of ``J_c``
        (checked: this is where a lost closure rank would show).
        """
        q, jc, jp = self._configure(p, None)
        svd = ranked_svd(np.vstack([jc, jp]))
        if svd.rank < self.model.nv:
            raise SingularConfigurationError("singular configuration: cos θ1 cos θ2 = 0 (eq. 11)")
        n = svd.solve(self._select_platform)
        if np.abs(jc @ n).max() > _SINGULAR_RTOL * np.abs(n).max():
            raise SingularConfigurationError("singular configuration: the closures allow a platform-free motion")
        self._last = (p.copy(), q, n)
        v = n @ dp
        gamma, jp_dot_v = self._drifts(q, v)
        a = svd.solve(np.concatenate([-gamma, ddp - jp_dot_v]))
        return q, v, a, n, jp

    def _tau(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray, n: np.ndarray, jp: np.ndarray, f_ext: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``τ`` from ``(Nᵀ Sᵀ) τ = Nᵀ (rnea(q, v, a) - J_Pᵀ f_ext)`` (λ eliminated); also the right side.

        ``Nᵀ Sᵀ`` is the paper's ``Jᵀ`` (eq. 10, ``ḋ = J ṗ``): singular at ``cos(θ1 + θ2) = 0`` (eq. 12).
        """
        rhs = pin.rnea(self.model, self.data, q, v, a) - jp.T @ f_ext
        (g11, g12), (g21, g22) = n[self._slider_idx].T.tolist()  # Nᵀ Sᵀ (2 x 2)
        det = g11 * g22 - g12 * g21
        # |det| / (product of row norms) = |sin| of the angle between the rows; 0 when singular.
        if abs(det) < _SINGULAR_RTOL * math.hypot(g11, g12) * math.hypot(g21, g22):
            raise SingularConfigurationError("singular configuration: cos(θ1 + θ2) = 0 (eq. 12)")
        b1, b2 = (n.T @ rhs).tolist()
        return np.array([g22 * b1 - g12 * b2, g11 * b2 - g21 * b1]) / det, rhs

    @locked
    def constrained_motion(self, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike) -> ThreeArrays:
        """Joint ``(q, v, a)`` (7,) each, consistent with the closures, for one platform state (2,) each."""
        p, dp, ddp = (self._one(x, n) for x, n in ((p, "p"), (dp, "dp"), (ddp, "ddp")))
        q, v, a, _, _ = self._motion(p, dp, ddp)
        return q, v, a

    @locked
    def inverse_dynamics(
        self, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None = None
    ) -> np.ndarray:
        """Actuator forces ``τ`` [N], shape ``(..., 2)``, for platform ``p, ṗ, p̈`` [m, m/s, m/s²].

        ``f_ext`` [N] is a force applied to the platform (as in eq. 28), broadcastable to ``(..., 2)``.
        Batches are solved one state at a time (each Newton solve warm-starts from the previous).
        """
        p, dp, ddp = as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp")
        f = np.zeros(2) if f_ext is None else as_xy(f_ext, "f_ext")
        try:
            p, dp, ddp, f = np.broadcast_arrays(p, dp, ddp, f)
        except ValueError:
            raise InputError("p, dp, ddp and f_ext have incompatible shapes") from None
        flat = [x.reshape(-1, 2) for x in (p, dp, ddp, f)]
        tau = np.empty((flat[0].shape[0], 2))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # huge inputs: checked below
            for k, (pk, dpk, ddpk, fk) in enumerate(zip(*flat, strict=True)):
                q, v, a, n, jp = self._motion(pk, dpk, ddpk)
                tau[k] = self._tau(q, v, a, n, jp, fk)[0]
        if not np.all(np.isfinite(tau)):
            raise InputError("the actuator forces overflowed: the inputs are too large for finite results")
        return tau.reshape(p.shape)

    @locked
    def generalized_forces(
        self, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None = None
    ) -> dict[str, np.ndarray]:
        """Every term of ``rnea - J_Pᵀ f_ext = Sᵀ τ + J_cᵀ λ`` at one state (for checks and teaching):
        ``q, v, a, tau, rhs`` (the left side), ``S_T`` (7, 2), ``J_c`` (9, 7), ``lam`` (minimum-norm λ)."""
        p, dp, ddp = (self._one(x, n) for x, n in ((p, "p"), (dp, "dp"), (ddp, "ddp")))
        f = np.zeros(2) if f_ext is None else self._one(f_ext, "f_ext")
        q, v, a, n, jp = self._motion(p, dp, ddp)
        tau, rhs = self._tau(q, v, a, n, jp, f)
        jc = self._closure_terms(q)[1]
        lam = np.linalg.lstsq(jc.T, rhs - self._s_t @ tau, rcond=None)[0]
        return {"q": q, "v": v, "a": a, "tau": tau, "rhs": rhs, "S_T": self._s_t.copy(), "J_c": jc, "lam": lam}

    @locked
    def forward_dynamics(self, q: ArrayLike, v: ArrayLike, tau: ArrayLike) -> np.ndarray:
        """Joint accelerations ``a`` (7,) [m/s², rad/s²] under actuator forces ``τ`` (2,) [N]
        (the KKT solve of :func:`tpm_viz.multibody.forward.forward_dynamics`)."""
        return forward.forward_dynamics(self, self._as_q(q), self._as_q(v), self._one(tau, "tau"))

    @locked
    def project(self, q: ArrayLike, v: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Constraint stabilisation (:func:`tpm_viz.multibody.forward.project`): the nearest ``q`` on the
        closures and ``v`` projected on the admissible motions ``N Nᵀ v``."""
        return forward.project(self, self._as_q(q), self._as_q(v))

    @locked
    def platform_velocity(self, q: ArrayLike, v: ArrayLike) -> np.ndarray:
        """Platform velocity ``J_P v`` (2,) [m/s]."""
        self._closure_terms(self._as_q(q))
        return self._platform_jacobian() @ self._as_q(v)

    @locked
    def kinetic_energy(self, q: ArrayLike, v: ArrayLike) -> float:
        """Total kinetic energy [J] of the tree at ``(q, v)`` (Pinocchio)."""
        return float(pin.computeKineticEnergy(self.model, self.data, self._as_q(q), self._as_q(v)))

    @staticmethod
    def _one(x: ArrayLike, name: str) -> np.ndarray:
        x = as_xy(x, name)
        if x.shape != (2,):
            raise InputError(f"{name} must have shape (2,), got {x.shape}")
        return x


@functools.lru_cache(maxsize=16)
def model_for(params: Params) -> MultibodyModel:
    """The cached :class:`MultibodyModel` of a parameter set (``Params`` is frozen and hashable)."""
    return MultibodyModel(params)


def checked_model(factory: Callable[[Params], MultibodyModel], params: object) -> MultibodyModel:
    """``factory(params)`` (a cached model of either arrangement), or :class:`InputError` where ``params`` is not a
    :class:`~tpm_viz.Params` (what :func:`inverse_dynamics` was given)."""
    if not isinstance(params, Params):
        raise InputError(f"inverse_dynamics needs a tpm_viz.Params, got {type(params).__name__}")
    return factory(params)


def inverse_dynamics(
    params: Params, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None = None
) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, from the Pinocchio model (see
    :meth:`MultibodyModel.inverse_dynamics`); one cached model per ``params``."""
    return checked_model(model_for, params).inverse_dynamics(p, dp, ddp, f_ext)
