"""Start the tpm-viz browser app: ``python app.py [--host 127.0.0.1] [--port 8080] [--presenter-token TOKEN]``."""

import argparse

from tpm_viz.ui.app import main

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1, loopback only)")
    parser.add_argument("--port", type=int, default=8080, help="port (default 8080; the next free one if busy)")
    parser.add_argument(
        "--presenter-token",
        metavar="TOKEN",
        help="only a tab that logs in with TOKEN changes the shared mechanism (others use their own copy)",
    )
    args = parser.parse_args()
    main(host=args.host, port=args.port, presenter_token=args.presenter_token)
