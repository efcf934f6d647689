"""The configuration file, ``tpm-viz lti keygen`` and ``tpm-viz serve --lti``: one line naming the key for a bad
file (exit 2), the key written 0600 and never over another, its JWKS printed (the kid computed by jwcrypto), the
missing extra named, and the four URL lines of a real ``serve --lti`` process."""

from __future__ import annotations

import json
import stat
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
from jwcrypto.jwk import JWK

from tests.lti.conftest import write_config
from tests.support.protocol import ServerProcess
from tpm_viz.cli import main
from tpm_viz.core.errors import InputError
from tpm_viz.lti.config import read_config
from tpm_viz.lti.keys import ToolKey

ROOT = Path(__file__).resolve().parents[2]
GOOD_PLATFORM = """
[[platform]]
issuer = "https://lms.example"
client_id = "c1"
deployment_ids = ["1"]
auth_login_url = "https://lms.example/auth"
auth_token_url = "https://lms.example/token"
key_set_url = "https://lms.example/jwks"
"""


def test_keygen_writes_a_private_key_0600_prints_its_jwks_and_never_overwrites(tmp_path, capsys):
    assert main(["lti", "keygen", "--output", str(tmp_path / "keys")]) == 0
    out = capsys.readouterr()
    path = tmp_path / "keys" / "tool-key.pem"
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    jwks = json.loads(out.out)  # stdout is the JSON alone (the note goes to stderr)
    (jwk,) = jwks["keys"]
    assert jwk["kid"] == JWK.from_pem(path.read_bytes()).thumbprint() and jwk["alg"] == "RS256"
    assert "d" not in jwk and "p" not in jwk  # public only
    assert ToolKey.read(path).jwks() == jwks  # what /lti/jwks serves
    before = path.read_bytes()
    assert main(["lti", "keygen", "--output", str(tmp_path / "keys")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exists and is not overwritten" in err and path.read_bytes() == before


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("", "[tool]: missing"),
        ('[tool]\nprivate_key = "k.pem"\nprivte = 1\n' + GOOD_PLATFORM, "unknown key 'privte'"),
        ('[tool]\nprivate_key = "k.pem"\nport = 70000\n' + GOOD_PLATFORM, "[tool] port"),
        ('[tool]\nprivate_key = "k.pem"\nurl = "ftp://x"\n' + GOOD_PLATFORM, "[tool] url"),
        ('[tool]\nprivate_key = "k.pem"\nstate_cookie = "maybe"\n' + GOOD_PLATFORM, "[tool] state_cookie"),
        ('[tool]\nprivate_key = "k.pem"\n', "[[platform]]: missing"),
        ('[tool]\nprivate_key = "k.pem"\n' + GOOD_PLATFORM.replace('["1"]', "[]"), "[[platform]] 1 deployment_ids"),
        (
            '[tool]\nprivate_key = "k.pem"\n' + GOOD_PLATFORM.replace('"https://lms.example/jwks"', '"certs"'),
            "[[platform]] 1 key_set_url",
        ),
        ('[tool]\nprivate_key = "k.pem"\n' + GOOD_PLATFORM + GOOD_PLATFORM, "the same issuer and client_id twice"),
        ('[tool]\nprivate_key = "k.pem"\n' + GOOD_PLATFORM.replace('client_id = "c1"\n', ""), "client_id"),
        ("[tool\n", "not valid TOML"),
    ],
)
def test_a_bad_configuration_is_one_line_naming_the_key(tmp_path, text, words):
    path = tmp_path / "lti.toml"
    path.write_text(text)
    with pytest.raises(InputError) as caught:
        read_config(path)
    message = str(caught.value)
    assert words in message and "\n" not in message and str(path) in message


def test_serve_with_a_bad_configuration_or_key_exits_2_with_one_line(tmp_path, capsys):
    bad = tmp_path / "lti.toml"
    bad.write_text('[tool]\nprivate_key = "missing.pem"\nport = 0\n' + GOOD_PLATFORM)
    assert main(["serve", "--port", "0", "--lti", str(bad), "--session", str(tmp_path / "s.sqlite3")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tpm-viz: error: ") and err.count("\n") == 1 and "missing.pem" in err
    (tmp_path / "not-rsa.pem").write_text("-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n")
    bad.write_text('[tool]\nprivate_key = "not-rsa.pem"\nport = 0\n' + GOOD_PLATFORM)
    assert main(["serve", "--port", "0", "--lti", str(bad), "--session", str(tmp_path / "s.sqlite3")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "tpm-viz lti keygen" in err


def test_a_missing_lti_extra_is_named(tmp_path):
    code = (
        "import sys; sys.modules['starlette'] = None; sys.modules['jwt'] = None\n"
        "from tpm_viz.cli import main\n"
        f"sys.exit(main(['lti', 'keygen', '--output', {str(tmp_path)!r}]))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert 'pip install -e ".[lti]"' in done.stderr


def test_serve_lti_prints_the_four_urls_and_serves_them(tmp_path, platform):
    config = write_config(tmp_path, platform)
    server = ServerProcess(session=tmp_path / "store.sqlite3", args=("--lti", str(config)))
    try:
        lines = [server.proc.stdout.readline().rstrip("\n") for _ in range(4)]
        names = ["LTI login URL: ", "LTI launch URL: ", "LTI JWKS URL: ", "LTI deep linking URL: "]
        assert [line[: len(n)] for line, n in zip(lines, names, strict=True)] == names
        urls = [line.split(": ", 1)[1] for line in lines]
        base = urls[0].rsplit("/lti/login", 1)[0]
        assert base.startswith("http://127.0.0.1:") and base != f"http://127.0.0.1:{server.port}"
        assert urls == [f"{base}/lti/login", f"{base}/lti/launch", f"{base}/lti/jwks", f"{base}/lti/deeplink"]
        served = httpx.get(urls[2], timeout=10).json()
        assert served == ToolKey.read(tmp_path / "keys" / "tool-key.pem").jwks()
    finally:
        server.stop()
    assert server.log_problems() == []
