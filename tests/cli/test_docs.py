"""``tpm-viz docs``: the build of a small Sphinx project through the command's own path (warnings fail it only with
``--strict``), one-line refusals without the ``docs`` extra or without the sources, and the folder served on
127.0.0.1 (the next free port when the asked one is busy). The real site is built, served and fetched by
``tests/system/test_docs_site.py``."""

from __future__ import annotations

import socket
import threading
import urllib.request

import pytest

from tests.support.cli import parser_for
from tpm_viz.cli import docs as cli_docs
from tpm_viz.cli import main
from tpm_viz.core.errors import InputError

CONF = 'extensions = ["myst_parser"]\nhtml_theme = "furo"\n'


def _project(folder, page: str):
    folder.mkdir()
    (folder / "conf.py").write_text(CONF)
    (folder / "index.md").write_text(page)
    return folder


def test_register_adds_the_docs_options():
    args = parser_for(cli_docs).parse_args(["docs", "--serve", "--port", "0", "--strict"])
    assert (args.serve, args.port, args.strict, args.output) == (True, 0, True, None)


def test_a_missing_docs_extra_is_one_line_naming_the_install(monkeypatch, capsys, tmp_path):
    real = cli_docs.importlib.util.find_spec
    monkeypatch.setattr(cli_docs.importlib.util, "find_spec", lambda name: None if name == "furo" else real(name))
    assert main(["docs", "--output", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("tpm-viz: error: the docs need furo")
    assert 'pip install -e ".[docs]"' in err
    assert not (tmp_path / "out").exists()


def test_sources_that_are_not_there_are_one_line(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(cli_docs, "SOURCES", tmp_path / "site-packages" / "docs")
    assert main(["docs", "--output", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "clone of the repository" in err


@pytest.mark.slow
def test_a_project_is_built_and_a_warning_fails_only_the_strict_build(monkeypatch, capsys, tmp_path):
    sources = _project(tmp_path / "src", "# Title\n\nSee [the missing page](missing.md).\n")
    monkeypatch.setattr(cli_docs, "SOURCES", sources)
    assert main(["docs", "--output", str(tmp_path / "html")]) == 0
    assert "<h1>Title" in (tmp_path / "html" / "index.html").read_text()
    out = capsys.readouterr().out
    assert f"docs built: {tmp_path / 'html' / 'index.html'}" in out
    assert main(["docs", "--strict", "--output", str(tmp_path / "strict")]) == 1
    assert "the docs build failed" in capsys.readouterr().err


def _serving(server):
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    return thread


def test_the_folder_is_served_on_loopback_and_a_busy_port_moves_on(tmp_path):
    (tmp_path / "index.html").write_text("<p>the site</p>")
    first = cli_docs.serve_folder(tmp_path, 0)
    port = first.server_address[1]
    second = cli_docs.serve_folder(tmp_path, port)  # busy: the next free port
    threads = [_serving(first), _serving(second)]
    try:
        assert first.server_address[0] == "127.0.0.1" and second.server_address[0] == "127.0.0.1"
        assert second.server_address[1] > port
        for server in (first, second):
            url = f"http://127.0.0.1:{server.server_address[1]}/"
            with urllib.request.urlopen(url, timeout=30) as page:
                assert page.status == 200 and page.read() == b"<p>the site</p>"
    finally:
        for server in (first, second):
            server.shutdown()
            server.server_close()
        for thread in threads:
            thread.join(timeout=30)
    with pytest.raises(OSError):  # closed: nothing listens there any more
        socket.create_connection(("127.0.0.1", port), timeout=5).close()


def test_a_port_that_cannot_be_bound_is_one_line(monkeypatch, tmp_path):
    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(cli_docs.http.server, "ThreadingHTTPServer", refuse)
    with pytest.raises(InputError, match=r"cannot serve on 127\.0\.0\.1 port 80: Permission denied"):
        cli_docs.serve_folder(tmp_path, 80)
