"""The page calculator's WebAssembly module, ``tpm_2ppa.wasm``: the generated C compiled for ``wasm32``.

Shipped prebuilt in ``assets/calculator/`` (installed as ``tpm_viz.assets``), so a user needs no compiler; this module
knows how to build it again, and ``tests/exchange/c/test_wasm.py`` checks that a rebuild from today's export gives
the same bytes. The sources: ``tpm_2ppa.c`` and ``tpm_2ppa.h`` as :func:`tpm_viz.exchange.c.code.c_files` writes them
(the paper's parameters; the module reads its parameters at run time) and the glue ``assets/calculator/tpm_wasm.c``
(the exchange buffer the page's script reads and writes). The build:

- ``clang --target=wasm32-wasi`` with :data:`FLAGS`: C99, ``-O2``, ``-ffp-contract=off`` (no fused multiply-add: the
  operations of the trace, in its order, as the Python does them), the strict warnings of the C tests as errors;
- linked by ``wasm-ld`` with no C runtime (``-nostdlib``, ``--no-entry``): only ``atan2`` comes from wasi-libc's
  ``libc.a`` (``sqrt`` and ``fabs`` are WebAssembly instructions), so the module imports nothing and runs in a page
  without WASI; ``--strip-all`` drops names, debug sections and the ``producers`` section;
- deterministic: the sources are written to a temporary folder and compiled by relative name, with no debug
  information, no timestamp and no path in the output: the same compiler and ``libc.a`` give the same bytes
  (:data:`MANIFEST` records which, with the module's SHA-256).

``python -m tpm_viz.exchange.c.wasm`` rebuilds it and prints its size and hash; ``--write`` replaces the shipped module
and its manifest (a maintainer's step after the generated C changes; the test says when it is due).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase
from tpm_viz.exchange.c.code import c_files

__all__ = ["FLAGS", "GLUE", "MANIFEST", "WASM", "Toolchain", "build", "manifest", "shipped", "toolchain"]

WASM = "tpm_2ppa.wasm"
"""The module's file name in ``assets/calculator/``."""
GLUE = "tpm_wasm.c"
"""The glue's file name in ``assets/calculator/``."""
MANIFEST = "build.json"
"""What the shipped module was built with: ``{"clang": version line, "libc_sha256": ..., "flags": [...],
"sha256": of the module, "bytes": its size}``."""
FLAGS = (
    "--target=wasm32-wasi",
    "-std=c99",
    "-O2",
    "-ffp-contract=off",
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-nostdlib",
    "-Wl,--no-entry",
    "-Wl,--strip-all",
)
"""The compiler's flags (the sysroot, the sources, ``libc.a`` and ``-o`` are added by :func:`build`)."""
_SYSROOTS = ("/usr", "/usr/share/wasi-sysroot", "/opt/wasi-sdk/share/wasi-sysroot")
"""Where wasi-libc is looked for (Debian's package, the upstream layout, the wasi-sdk), after ``$WASI_SYSROOT``."""


@dataclass(frozen=True)
class Toolchain:
    """A compiler that can build the module: ``clang`` [path], the wasi-libc ``sysroot`` [path] and its ``libc``."""

    clang: str
    sysroot: str
    libc: str

    @property
    def version(self) -> str:
        """``clang --version``'s first line (e.g. ``Debian clang version 14.0.6``)."""
        done = subprocess.run([self.clang, "--version"], capture_output=True, text=True, timeout=60, check=False)
        return done.stdout.splitlines()[0].strip() if done.stdout else ""

    @property
    def libc_sha256(self) -> str:
        return hashlib.sha256(Path(self.libc).read_bytes()).hexdigest()


def toolchain() -> Toolchain | None:
    """``clang``, ``wasm-ld`` and wasi-libc, if all are installed (Debian: ``clang lld wasi-libc``), else None."""
    clang = shutil.which("clang")
    if clang is None or shutil.which("wasm-ld") is None:
        return None
    roots = [os.environ["WASI_SYSROOT"]] if os.environ.get("WASI_SYSROOT") else []
    for root in (*roots, *_SYSROOTS):
        libc = Path(root) / "lib" / "wasm32-wasi" / "libc.a"
        if libc.is_file() and (Path(root) / "include" / "wasm32-wasi" / "math.h").is_file():
            return Toolchain(clang, root, str(libc))
    return None


def _asset(name: str) -> Path:
    return Path(str(resources.files("tpm_viz.assets") / "calculator" / name))


def build(tools: Toolchain | None = None) -> bytes:
    """The module's bytes, compiled now from :func:`~tpm_viz.exchange.c.code.c_files` and the glue (see the module
    docstring); :class:`~tpm_viz.core.errors.InputError` if no toolchain is installed or the compiler fails."""
    tools = tools if tools is not None else toolchain()
    if tools is None:
        raise InputError(
            Phrase("building the WebAssembly module needs clang, wasm-ld and wasi-libc (Debian: clang lld wasi-libc)")
        )
    with tempfile.TemporaryDirectory(prefix="tpm-wasm-") as tmp:
        folder = Path(tmp)
        for name, text in c_files().items():
            (folder / name).write_text(text, encoding="utf-8")
        shutil.copyfile(_asset(GLUE), folder / GLUE)
        cmd = [tools.clang, *FLAGS, f"--sysroot={tools.sysroot}", GLUE, "tpm_2ppa.c", tools.libc, "-o", WASM]
        done = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, timeout=600, check=False)
        if done.returncode != 0:
            raise InputError(Phrase("the WebAssembly build failed: {why}", why=(done.stderr or done.stdout).strip()))
        return (folder / WASM).read_bytes()


def shipped() -> bytes:
    """The module shipped in the package (``assets/calculator/tpm_2ppa.wasm``)."""
    return _asset(WASM).read_bytes()


def manifest() -> dict[str, object]:
    """The shipped module's :data:`MANIFEST`."""
    data: dict[str, object] = json.loads(_asset(MANIFEST).read_text(encoding="utf-8"))
    return data


def _write(module: bytes, tools: Toolchain) -> None:
    record = {
        "clang": tools.version,
        "libc_sha256": tools.libc_sha256,
        "flags": list(FLAGS),
        "sha256": hashlib.sha256(module).hexdigest(),
        "bytes": len(module),
    }
    _asset(WASM).write_bytes(module)
    _asset(MANIFEST).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    """``python -m tpm_viz.exchange.c.wasm [--write]``: rebuild, compare with the shipped module, optionally replace."""
    parser = argparse.ArgumentParser(prog="python -m tpm_viz.exchange.c.wasm", description=main.__doc__)
    parser.add_argument("--write", action="store_true", help="replace the shipped module and its manifest")
    args = parser.parse_args(argv)
    tools = toolchain()
    if tools is None:
        print("no toolchain: install clang, lld and wasi-libc")
        return 2
    module = build(tools)
    same = _asset(WASM).is_file() and module == shipped()
    print(f"{WASM}: {len(module)} bytes, sha256 {hashlib.sha256(module).hexdigest()} ({tools.version})")
    print("the shipped module is identical" if same else "the shipped module differs (or is missing)")
    if args.write:
        _write(module, tools)
        print(f"wrote {_asset(WASM)} and {MANIFEST}")
    return 0 if same or args.write else 1


if __name__ == "__main__":
    raise SystemExit(main())
