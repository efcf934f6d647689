"""``python -m tpm_viz``: the same as the ``tpm-viz`` command."""

from .cli import main

raise SystemExit(main())
