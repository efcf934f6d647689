"""Model exchange: the 2-PPa TPM written as MJCF (MuJoCo, Pinocchio's MJCF reader) or URDF text.

- :mod:`.topology`: the one description both writers read (bodies, joints, masses, inertias, loop
  closures, the joint positions of a platform pose);
- :mod:`.mjcf`: MJCF with the loop closures as ``<equality><connect>`` and stiff solver settings;
- :mod:`.urdf`: URDF (a tree: the parallelogram's inner loops as mimic joints, the leg closure in a comment);
- :mod:`.c.code`: the closed form as C99 for a controller (written into a folder by :mod:`.c.folder`);
- :mod:`.c.wasm` and :mod:`.c.calculator`: that C as WebAssembly and the script that makes it ``window.tpm`` in a page.

Import rule: the standard library, numpy, the base modules (:mod:`tpm_viz.core.params`, :mod:`tpm_viz.core.errors`,
:mod:`tpm_viz.core.words`) and :mod:`tpm_viz.paper` only; neither MuJoCo nor Pinocchio (the files are text; the tests
load them); the WebAssembly build runs clang as a program.
Conventions: ``docs/conventions.md`` (SI units, frame OXY with Z up, the mechanism in the plane ``z = 0``).
"""

from __future__ import annotations

from tpm_viz.exchange.mjcf import MjcfSettings, mjcf_text
from tpm_viz.exchange.topology import Topology, joint_positions, topology
from tpm_viz.exchange.urdf import urdf_text

__all__ = ["MjcfSettings", "Topology", "joint_positions", "mjcf_text", "topology", "urdf_text"]
