"""``examples/ctc_loop.c``: the generated computed-torque law in a 1 kHz loop against the generated forward dynamics
(issue 27), built with the strict flags and run; and ``tpm-viz export --format c`` end to end."""

from __future__ import annotations

import pathlib
import re
import subprocess

import pytest

from tests.support import cbuild
from tests.support.cli import parser_for
from tpm_viz.cli import export as cli_export
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.exchange.c.code import c_files

EXAMPLE = pathlib.Path(__file__).resolve().parents[3] / "examples" / "ctc_loop.c"


def run_example(directory: pathlib.Path, rate: float) -> dict[str, float]:
    exe = cbuild.compile_c(
        [EXAMPLE, directory / "tpm_2ppa.c"], directory / f"ctc_{rate:.0f}", directory, [f"-DRATE={rate:.1f}"]
    )
    done = subprocess.run([str(exe)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    numbers = dict(refused=r"refused: (\d+)", error=r"largest error after 1 s: ([\d.]+) um", worst=r"worst ([\d.]+) us")
    return {k: float(re.search(v, done.stdout).group(1)) for k, v in numbers.items()}


def test_the_example_tracks_and_its_hold_error_halves_with_twice_the_rate(tmp_path):
    assert cbuild.cc() is not None, "needs a C compiler: Debian packages gcc and libc6-dev"
    directory = cbuild.export(tmp_path)
    slow, fast = run_example(directory, 1000.0), run_example(directory, 2000.0)
    assert slow["refused"] == fast["refused"] == 0
    assert slow["error"] < 10.0  # µm, from a 5 mm initial offset: the exact model converges
    # the remaining error is the zero-order hold's, proportional to the sample period
    assert 1.7 < slow["error"] / fast["error"] < 2.3
    assert slow["worst"] > 0.0 and fast["worst"] > 0.0


def test_export_format_c_writes_both_files_into_a_new_directory(tmp_path):
    out = tmp_path / "new" / "gen"
    args = parser_for(cli_export).parse_args(["export", "--format", "c", "--output", str(out), "--set", "m_p=4.42"])
    assert args.func(args) == 0
    assert sorted(p.name for p in out.iterdir()) == ["tpm_2ppa.c", "tpm_2ppa.h"]
    assert (out / "tpm_2ppa.c").read_text() == c_files(Params.paper(m_p=4.42))["tpm_2ppa.c"]
    assert (
        "{ 0.482, 0.092, 0.26, 0.95, 0.84, 4.42, 0.3, TPM_MIN_COS_APP, TPM_MIN_DET_APP }"
        in (out / "tpm_2ppa.h").read_text()
    )
    for bad in ("-", str(out / "tpm_2ppa.c")):
        args = parser_for(cli_export).parse_args(["export", "--format", "c", "--output", bad])
        with pytest.raises(InputError, match="directory"):
            args.func(args)
