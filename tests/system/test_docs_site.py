"""The docs site builds with warnings as errors (``tpm-viz docs --strict``: a page outside every toctree, a broken
link or heading anchor, a docstring reference that names nothing, a docutils error in a docstring all fail it),
every hand-written page, folder of the package, module and example has its page, and ``tpm-viz docs --serve``
serves the built site on 127.0.0.1 until Ctrl-C. Importing the package for autodoc starts nothing.

About a minute of CPU (autodoc imports every module; furo writes ~200 pages): marked ``slow``.
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import urllib.request

import pytest

from tests.support.docs import DOCS, ROOT, pages

pytestmark = pytest.mark.slow

IMPORT_ALL = """
import os, pathlib, pkgutil, importlib, threading
import tpm_viz
def sockets():
    found = 0
    for fd in os.listdir('/proc/self/fd'):
        try:
            found += os.readlink(f'/proc/self/fd/{fd}').startswith('socket:')
        except OSError:  # the listing's own descriptor, closed by now
            pass
    return found
before = sockets()
names = [m.name for m in pkgutil.walk_packages(tpm_viz.__path__, 'tpm_viz.') if not m.name.endswith('__main__')]
for name in names:
    importlib.import_module(name)
print(len(names), sockets() - before, sorted(t.name for t in threading.enumerate() if t is not threading.main_thread()))
"""


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built by ``tpm-viz docs --strict`` (its output folder and what Sphinx printed)."""
    out = tmp_path_factory.mktemp("site") / "html"
    done = subprocess.run(
        [sys.executable, "-m", "tpm_viz", "docs", "--strict", "--output", str(out)],
        capture_output=True,
        text=True,
        timeout=1800,
        cwd=ROOT,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    return out, done


def test_the_site_builds_without_a_warning(site):
    out, done = site
    assert done.returncode == 0 and "WARNING" not in done.stderr and "ERROR" not in done.stderr, done.stderr[-4000:]
    assert f"docs built: {out / 'index.html'}" in done.stdout


def test_every_page_folder_module_and_example_has_its_page(site):
    out, _ = site
    for page in pages():
        if page.is_relative_to(DOCS) and page.name != "README.md":
            built = out / page.relative_to(DOCS).with_suffix(".html")
            assert built.is_file(), f"{page.relative_to(ROOT)} was not built"
    modules = [
        ".".join(p.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
        for p in (ROOT / "tpm_viz").rglob("*.py")
        if p.name != "__main__.py"
    ]
    assert len(modules) > 150
    missing = [m for m in modules if not (out / "api" / "generated" / f"{m}.html").is_file()]
    assert not missing, f"modules without an API page: {missing}"
    for example in (ROOT / "examples").glob("[0-9][0-9]_*/[0-9][0-9]_*.py"):
        assert (out / "examples" / example.parent.name / f"{example.stem}.html").is_file(), example.name
    kinematics = (out / "api" / "generated" / "tpm_viz.paper.kinematics.html").read_text()
    assert 'id="tpm_viz.paper.kinematics.inverse_kinematics"' in kinematics
    # :class:`~tpm_viz.Params` (a re-export) links to where Params is documented; :class:`~.control.tab.ControlView`
    # (a suffix) to the one module it names
    multibody = (out / "api" / "generated" / "tpm_viz.multibody.html").read_text()
    assert 'href="tpm_viz.core.params.html#tpm_viz.core.params.Params"' in multibody
    settings = (out / "api" / "generated" / "tpm_viz.ui.teaching.settings.html").read_text()
    assert 'href="tpm_viz.ui.teaching.control.tab.html#tpm_viz.ui.teaching.control.tab.ControlView"' in settings


def test_the_built_site_is_served_on_loopback_until_ctrl_c(site):
    out, done = site
    assert done.returncode == 0
    proc = subprocess.Popen(
        [sys.executable, "-m", "tpm_viz", "docs", "--serve", "--port", "0", "--output", str(out)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        url = None
        for line in proc.stdout:  # the incremental build, then the URL: waits on the command's own lines
            match = re.search(r"tpm-viz docs at (http://127\.0\.0\.1:(\d+)/)", line)
            if match:
                url, port = match.group(1), int(match.group(2))
                break
        assert url is not None, proc.stderr.read()[-2000:]
        for path, words in (("", "tpm-viz"), ("api/generated/tpm_viz.paper.html", "tpm_viz.paper")):
            with urllib.request.urlopen(url + path, timeout=60) as page:
                assert page.status == 200 and words in page.read().decode()
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=5).close()


def test_importing_every_module_for_autodoc_starts_no_thread_and_opens_no_socket():
    done = subprocess.run([sys.executable, "-c", IMPORT_ALL], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr[-2000:]
    count, sockets, threads = done.stdout.strip().split(" ", 2)
    assert int(count) > 150
    assert (int(sockets), threads) == (0, "[]")
