"""The independent closed-loop multibody model in Pinocchio: the only package of tpm-viz that imports pinocchio.

- :mod:`.model`: the model built from :class:`~tpm_viz.Params`, its constrained inverse and forward dynamics;
- :mod:`.assembly`: its closed-loop kinematics (the configuration ``q`` from ``p`` or ``d``), a mixin of the model;
- :mod:`.forward`: forward dynamics: the KKT solve, the constraint projection, the 2-DOF platform plant;
- :mod:`.locking`: the per-model lock (Pinocchio's ``Data`` is shared scratch memory);
- :mod:`.rank`: rank-revealing SVD helpers for the over-constrained closures;
- :mod:`.parallel`: the parallel arrangement's own closed-loop model (``docs/parallel.md``), a subclass of the model;
- :mod:`.replay`: the paper's forces applied to the model and integrated (does the platform follow the path?);
- :mod:`.crosscheck`: closed form against the model, on random states and on the paper's trajectories;
- :mod:`.control`: the control lab: sampled controllers (:mod:`tpm_viz.paper.control`) drive the model.

Import rule (checked by ``tests/system/test_layering.py``): pinocchio, numpy, the base modules and :mod:`tpm_viz.paper`.
Pinocchio pitfalls met on the way: ``docs/pinocchio.md``.
"""

from tpm_viz.multibody.model import PART_NAMES, MultibodyModel, inverse_dynamics, model_for

__all__ = ["PART_NAMES", "MultibodyModel", "inverse_dynamics", "model_for"]
