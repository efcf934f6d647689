"""``python -m tpm_viz``: the same as the ``tpm-viz`` command."""

from tpm_viz.cli import main

raise SystemExit(main())
