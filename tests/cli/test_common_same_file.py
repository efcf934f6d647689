"""Every command that reads a file refuses to write its output over it (issue 12), and leaves it intact."""

from __future__ import annotations

import pytest

from tpm_viz.cli import main

CSV = "t,p1,p2\n0,0,0\n0.1,0.01,0\n0.2,0.02,0.01\n0.3,0.03,0.01\n0.4,0.03,0.02\n"


@pytest.mark.parametrize(
    "argv",
    [
        ["control", "--controller", "pd", "--trajectory", "{f}", "--output", "{f}"],
        ["plan", "--path", "{f}", "--force-limit", "100", "--output", "{f}"],
        ["size", "--input", "{f}", "--output", "{f}"],
    ],
)
def test_output_over_the_input_is_refused_and_the_input_is_kept(tmp_path, capsys, argv):
    f = tmp_path / "in.csv"
    f.write_text(CSV)
    assert main([a.format(f=f) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "input" in err
    assert f.read_text() == CSV
