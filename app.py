"""Start the tpm-viz browser app: ``python app.py [--host 127.0.0.1] [--port 8080] [--presenter-token TOKEN]``.

The same as ``tpm-viz serve``: the options are defined once, in :mod:`tpm_viz.cli`.
"""

import sys

from tpm_viz.cli import main

if __name__ == "__main__":
    raise SystemExit(main(["serve", *sys.argv[1:]]))
