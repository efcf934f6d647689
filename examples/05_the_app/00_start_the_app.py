"""Start the app from Python

The browser app, started from a script instead of `python app.py` (or `tpm-viz serve`): the same server, on
127.0.0.1 only, on any free port (`port=0`), with `block=False` so the script keeps control. It prints the URL; open
it in a browser to drag the platform. The script waits for Ctrl-C, then stops the server. In Jupyter the same call
shows the app in an IFrame ([notebook.md](../../notebook.md)).
"""

import threading
import urllib.request

from tpm_viz.ui.app import main as serve

app = serve(port=0, block=False)  # prints "tpm-viz serving at http://127.0.0.1:PORT"
try:
    with urllib.request.urlopen(f"http://127.0.0.1:{app.port}/", timeout=30) as page:
        print(f"the page answers: HTTP {page.status}")
    print("open the URL above in a browser; Ctrl-C stops the server")
    threading.Event().wait()  # until Ctrl-C
except KeyboardInterrupt:
    pass
finally:
    app.stop()
    print("stopped")
