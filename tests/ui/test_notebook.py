"""The notebook story: tpm_viz.ui.notebook embeds the mechanism and a run as viser recordings, and docs/example.ipynb
runs headless in under a minute (executed with nbclient when the optional 'notebook' extra is installed)."""

from __future__ import annotations

import base64
import pathlib
import socket
import subprocess
import sys
import time

import pytest

from tpm_viz import InputError, Params
from tpm_viz.app.runs import Source, build_run
from tpm_viz.ui.notebook import MAX_FRAMES, Embed
from tpm_viz.viserkit.probe import recorded_seconds

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

NOTEBOOK = pathlib.Path(__file__).resolve().parents[2] / "docs" / "example.ipynb"
BUDGET = 60.0  # s, the whole notebook in CI


def _embedded(page: str) -> bytes:
    start = page.index('window.__VISER_EMBED_DATA__="') + len('window.__VISER_EMBED_DATA__="')
    return base64.b64decode(page[start : page.index('"', start)])


def test_a_pose_and_a_run_embed_as_standalone_pages_and_the_port_is_freed():
    with Embed() as embed:
        port = embed.server.get_port()
        still = embed.pose_html((0.05, -0.03))
        run = build_run(Params.paper(), Source.paper("circle", 0.5))
        played = embed.run_html(run, fps=30)
        assert "</html>" in still.lower() and "</html>" in played.lower()
        assert len(_embedded(played)) > len(_embedded(still))  # 16 more frames of moves and force arrows
        with pytest.raises(InputError, match="fps must be a positive number"):
            embed.record(run, fps=0.0)
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", port))  # closed: the port is free again


def test_a_long_run_is_capped_in_frames():
    with Embed() as embed:
        run = build_run(Params.paper(), Source.paper("line", 100.0))
        serializer = embed.record(run, fps=30.0)
        assert recorded_seconds(serializer) == pytest.approx(run.duration * MAX_FRAMES / (MAX_FRAMES - 1))


def test_the_notebook_module_is_imported_by_nothing_else_and_importing_the_library_loads_no_ipython():
    package = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"
    users = [p for p in package.rglob("*.py") if "ui.notebook" in p.read_text() and p.name != "notebook.py"]
    assert users == []
    code = "import sys, tpm_viz.ui.notebook, tpm_viz.app.lessons; print('IPython' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


@pytest.mark.slow
def test_the_example_notebook_runs_headless_within_a_minute(tmp_path):
    nbformat = pytest.importorskip("nbformat", reason="the optional 'notebook' extra is not installed")
    nbclient = pytest.importorskip("nbclient", reason="the optional 'notebook' extra is not installed")
    pytest.importorskip("ipykernel", reason="the optional 'notebook' extra is not installed")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells)  # stored without outputs
    client = nbclient.NotebookClient(
        notebook, timeout=int(BUDGET), kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    start = time.monotonic()
    client.execute()
    elapsed = time.monotonic() - start
    assert elapsed < BUDGET, f"the notebook took {elapsed:.1f} s"
    outputs = [out for cell in notebook.cells for out in cell.get("outputs", [])]
    assert not [out for out in outputs if out.output_type == "error"]
    html = [out["data"]["text/html"] for out in outputs if "text/html" in out.get("data", {})]
    assert sum("iframe srcdoc=" in h for h in html) == 4  # the pose and three runs, inline
    assert any("peak |τ_i| = 177.1 N" in out.get("text", "") for out in outputs)
