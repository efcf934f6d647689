"""Compile the generated C (``tpm-viz export --format c``) for the tests and benchmarks, and call it.

``CFLAGS`` are the issue's strict flags (C99, every warning an error). The harness ``tests/support/tpm_batch.c``
runs every generated function on rows of inputs: :func:`load` builds it as a shared library for ``ctypes``,
:func:`build_driver` as a program (for the sanitizers, whose runtime cannot be loaded into a running Python).
"""

from __future__ import annotations

import ctypes
import pathlib
import shutil
import subprocess

import numpy as np

from tpm_viz.core.errors import InvalidParametersError
from tpm_viz.core.params import Params
from tpm_viz.exchange.c.code import c_files

CFLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-g"]
HERE = pathlib.Path(__file__).resolve().parent
BATCH = HERE / "tpm_batch.c"
IN_COLS, OUT_COLS = 29, 32
SENTINEL = 12345.0
NO_MARGIN = (1e-300, 1e-300)
"""A margin (``min_cos``, ``min_det`` of ``tpm_params``) so small that only the exact guards (``TPM_SINGULAR_TOL``,
``TPM_CTC_DIRECT_TOL``) refuse: what the tests of the traced formulas and of those guards use."""


def cc() -> str | None:
    """The system C compiler (``cc``), or None."""
    return shutil.which("cc")


def export(directory: pathlib.Path, params: Params | None = None) -> pathlib.Path:
    """Write the generated files into ``directory`` (created) and return it."""
    directory.mkdir(parents=True, exist_ok=True)
    for name, text in c_files(params).items():
        (directory / name).write_text(text)
    return directory


def compile_c(sources: list[pathlib.Path], out: pathlib.Path, include: pathlib.Path, extra: list[str]) -> pathlib.Path:
    """``cc CFLAGS extra -I include sources -o out -lm``; raises with the compiler's output on failure."""
    cmd = [str(cc()), *CFLAGS, *extra, "-I", str(include), *map(str, sources), "-o", str(out), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if done.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
    return out


def load(directory: pathlib.Path) -> ctypes.CDLL:
    """The generated C and the harness as a shared library in ``directory`` (must hold the generated files)."""
    lib = compile_c([directory / "tpm_2ppa.c", BATCH], directory / "libtpm.so", directory, ["-shared", "-fPIC"])
    dll = ctypes.CDLL(str(lib))
    dll.batch_all.argtypes = [ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]
    dll.batch_all.restype = None
    return dll


def build_driver(directory: pathlib.Path, extra: list[str]) -> pathlib.Path:
    """The harness as a program ``driver IN OUT`` (raw float64 rows) in ``directory``."""
    return compile_c([directory / "tpm_2ppa.c", BATCH], directory / "driver", directory, ["-DTPM_DRIVER", *extra])


def with_margin(rows: np.ndarray, margin: tuple[float, float] = NO_MARGIN) -> np.ndarray:
    """``rows`` of 27 columns (parameters to ``tau_in``) with the margin columns appended: ``(n, IN_COLS)``."""
    rows = np.asarray(rows, dtype=np.float64)
    if rows.shape[1] == IN_COLS:
        return rows
    return np.concatenate([rows, np.broadcast_to(np.asarray(margin, dtype=np.float64), (len(rows), 2))], axis=1)


def run_batch(dll: ctypes.CDLL, rows: np.ndarray, margin: tuple[float, float] = NO_MARGIN) -> np.ndarray:
    """Every function on ``rows`` (``(n, IN_COLS)``, or 27 columns and ``margin``); returns ``(n, OUT_COLS)``
    (sentinel where nothing was written)."""
    rows = np.ascontiguousarray(with_margin(rows, margin))
    out = np.full((len(rows), OUT_COLS), SENTINEL)
    dll.batch_all(len(rows), rows.ctypes.data, out.ctypes.data)
    return out


def params_row(params: Params) -> list[float]:
    """The ``tpm_params`` fields in struct order."""
    return [params.a, params.b, params.l_a, params.m_a, params.m_b, params.m_p, params.stroke]


def random_params(rng: np.random.Generator) -> Params:
    """A seeded random valid parameter set (lengths 0.5x-2x the paper's, masses 0.05-10 kg)."""
    while True:
        try:
            la = rng.uniform(0.12, 0.5)
            return Params(
                a=rng.uniform(0.2, 1.0),
                b=rng.uniform(0.02, 0.2),
                l_a=la,
                stroke=rng.uniform(0.1, 0.8),
                pivot_spacing=0.2 * la,
                m_a=rng.uniform(0.05, 10),
                m_b=rng.uniform(0.05, 10),
                m_p=rng.uniform(0.05, 10),
            )
        except InvalidParametersError:
            continue
