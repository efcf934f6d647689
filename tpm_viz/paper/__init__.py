"""The paper's mathematics (Pham & Kim 2013), numpy only: kinematics (eqs. 1-4), Jacobians and singularities
(eqs. 7-15), inverse dynamics (eqs. 16-31), workspace, manipulability ellipses and trajectories (Figs. 4-5).

Import rule (checked by ``tests/test_layering.py``): numpy and the standard library, plus the package's base
modules (:mod:`tpm_viz.core.errors`, :mod:`tpm_viz.core.params`, :mod:`tpm_viz.core.csvio`). Conventions:
``docs/conventions.md``.
"""
