"""The shipped WebAssembly module (``assets/calculator/tpm_2ppa.wasm``, issue 39): rebuilt from today's exported C it
gives the same bytes; the build is deterministic; the module is small, imports nothing and exports the calculator's
three functions; its manifest describes it."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
from pathlib import Path

import pytest

from tpm_viz.exchange.c import wasm


@pytest.fixture(scope="module")
def tools():
    found = wasm.toolchain()
    if found is None:
        pytest.skip("clang, wasm-ld or wasi-libc is not installed (Debian: clang lld wasi-libc); CI installs them")
    return found


def test_the_manifest_describes_the_shipped_module():
    module, record = wasm.shipped(), wasm.manifest()
    assert record["sha256"] == hashlib.sha256(module).hexdigest() and record["bytes"] == len(module)
    assert record["flags"] == list(wasm.FLAGS)
    assert module[:8] == b"\0asm\x01\0\0\0"  # a WebAssembly binary, version 1
    assert len(module) < 16 * 1024
    doc = (Path(__file__).resolve().parents[3] / "docs" / "realtime.md").read_text()
    assert f"**{len(module):,} bytes**" in doc  # the size docs/realtime.md states


@pytest.mark.slow
def test_rebuilding_from_todays_exported_c_gives_the_shipped_bytes(tools):
    first, second = wasm.build(tools), wasm.build(tools)
    assert first == second, "the build is not deterministic"
    record = wasm.manifest()
    if (tools.version, tools.libc_sha256) != (record["clang"], record["libc_sha256"]):
        pytest.skip(
            f"this machine's toolchain ({tools.version}, libc.a {tools.libc_sha256[:12]}) is not the one the shipped "
            f"module was built with ({record['clang']}, libc.a {record['libc_sha256'][:12]}): the bytes may differ; "
            "the build above is deterministic"
        )
    assert first == wasm.shipped(), (
        "the shipped module is stale: the generated C or the glue changed; "
        "run python -m tpm_viz.exchange.c.wasm --write"
    )


def test_the_module_imports_nothing_and_exports_the_calculator(tmp_path):
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed (Debian package nodejs)")
    (tmp_path / "m.wasm").write_bytes(wasm.shipped())
    script = (
        "const m = new WebAssembly.Module(require('fs').readFileSync(process.argv[1]));"
        "console.log(JSON.stringify({imports: WebAssembly.Module.imports(m), "
        "exports: WebAssembly.Module.exports(m).map((e) => e.name), "
        "custom: WebAssembly.Module.customSections(m, 'producers').length}));"
    )
    done = subprocess.run([node, "-e", script, str(tmp_path / "m.wasm")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    info = json.loads(done.stdout)
    assert info["imports"] == []  # no WASI, no host function: it runs in any page
    assert sorted(info["exports"]) == ["memory", "tpm_wasm_buffer", "tpm_wasm_evaluate", "tpm_wasm_layout"]
    assert info["custom"] == 0  # no producers section (compiler version, paths)


def test_the_build_needs_its_toolchain_or_says_what_to_install(monkeypatch):
    monkeypatch.setattr(wasm.shutil, "which", lambda name: None)
    assert wasm.toolchain() is None
    with pytest.raises(wasm.InputError, match="clang lld wasi-libc"):
        wasm.build()
