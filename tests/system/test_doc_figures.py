"""Figures the docs print come from commands a test runs (issue 27), here the ones of the model page
(``docs/model.md``):

- the ``tpm-viz crosscheck`` block is the command's output, so it cannot drift from the code again (the published
  random case read 7.13e-14 after the code had moved to 2.16e-13). Words, integers and statuses must match exactly.
  The figures are round-off (1e-13 N, 1e-12 m) and the last digits of round-off legitimately differ between CPUs and
  numpy builds, so each printed float must be within a factor of 1.5 of the command's; a stale page (the factor 3
  above) fails. To refresh it, paste the command's output.
- ``docs/fig4_line.png`` and ``docs/fig5_circle.png`` are ``tpm-viz figures``' output at its defaults (line
  T = 0.2 s, circle T = 0.5 s, 201 samples): the force panel is the same picture; the panel of the difference
  below it plots round-off (1e-13 N) and may differ;
- the control page's figures (``docs/control.md``), each named RMS or maximum, are ``tpm-viz control``'s summary
  lines (issue 35).

Elsewhere: the design tables (``tests/cli/test_design.py``), the clip (``tests/cli/test_outputs_clip.py``), the
stage screenshots (``tests/e2e/test_browser_stage.py``), the app's and the teaching demo's screenshots
(``tests/e2e/test_browser_docs_figures.py``), the examples' figures (``test_examples.py``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from tests.support.docs import ROOT, block_after
from tpm_viz.cli import main

MODEL = ROOT / "docs" / "model.md"
FORCE_PANEL = 0.55
"""The top share of the figures' height that holds the force curves (the round-off difference is below it)."""


def same_table(printed: str, actual: str, factor: float = 1.5) -> list[str]:
    """The differences between two tables (empty: the same words, integers and floats within ``factor``)."""
    problems = []
    lines_p, lines_a = printed.strip().splitlines(), actual.strip().splitlines()
    if len(lines_p) != len(lines_a):
        return [f"{len(lines_p)} lines in the docs, {len(lines_a)} from the command"]
    for lp, la in zip(lines_p, lines_a, strict=True):
        tp, ta = lp.split(), la.split()
        if len(tp) != len(ta):
            problems.append(f"docs {lp!r} / command {la!r}")
            continue
        for a, b in zip(tp, ta, strict=True):
            if re.fullmatch(r"-?\d+\.\d*e[-+]\d+", a) and re.fullmatch(r"-?\d+\.\d*e[-+]\d+", b):
                x, y = float(a), float(b)
                if not (x == y or (x * y > 0 and max(x / y, y / x) <= factor)):
                    problems.append(f"{a} printed, {b} now, in {la!r}")
            elif a != b:
                problems.append(f"{a!r} printed, {b!r} now, in {la!r}")
    return problems


def test_the_comparison_catches_a_stale_figure():
    good = "random, seed 0  200  1.012e-11  2.16e-13  -  -  ok"
    assert same_table(good, good.replace("2.16e-13", "1.9e-13")) == []
    assert same_table(good.replace("2.16e-13", "7.13e-14"), good)
    assert same_table(good, good.replace("ok", "FAIL"))


def test_the_model_page_states_the_commands_of_its_figures():
    text = MODEL.read_text()
    assert "`tpm-viz crosscheck`" in text and "`tpm-viz figures --output-dir D`" in text
    assert "(fig5_circle.png)" in text and "fig4_line.png" in text


@pytest.mark.slow
def test_the_crosscheck_table_is_the_commands_output():
    done = subprocess.run(
        [sys.executable, "-m", "tpm_viz", "crosscheck"], capture_output=True, text=True, timeout=600, cwd=ROOT
    )
    assert done.returncode == 0, done.stderr
    problems = same_table(block_after(MODEL, "`tpm-viz crosscheck`").text, done.stdout)
    assert not problems, (
        "the crosscheck block of docs/model.md is stale:\n" + "\n".join(problems) + "\nnow:\n" + done.stdout
    )


@pytest.mark.slow
def test_the_papers_figures_are_the_figures_commands_output(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "tpm_viz", "figures", "--output-dir", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert done.returncode == 0, done.stderr
    for name in ("fig4_line.png", "fig5_circle.png"):
        made = np.asarray(Image.open(tmp_path / name).convert("RGB"), dtype=int)
        shown = np.asarray(Image.open(ROOT / "docs" / name).convert("RGB"), dtype=int)
        assert made.shape == shown.shape, name
        top = int(made.shape[0] * FORCE_PANEL)
        differ = (np.abs(made[:top] - shown[:top]).max(axis=2) > 16).mean()
        assert differ < 0.002, f"docs/{name}: {differ:.1%} of the force panel's pixels differ from the command's"


def _control(capsys, *options: str) -> tuple[float, float]:
    """RMS and maximum tracking error [mm] of ``tpm-viz control --trajectory circle`` (its summary line)."""
    assert main(["control", "--trajectory", "circle", *options, "--output", "-"]) in (0, None)
    err = capsys.readouterr().err
    found = re.search(r"RMS error ([\d.e+-]+) mm, max error ([\d.e+-]+) mm", err)
    assert found, err
    return float(found.group(1)), float(found.group(2))


def test_the_control_figures_say_rms_or_maximum_and_are_the_commands(capsys):
    """Issue 35: the control section mixed maxima with RMS figures; each is now named and is the summary line of
    ``tpm-viz control`` at the stated settings (10 Hz, ζ = 1, 1 kHz unless said)."""
    text = " ".join((ROOT / "docs" / "control.md").read_text(encoding="utf-8").split())
    payload = {c: _control(capsys, "--controller", c, "--payload", "1") for c in ("pd", "pdff", "ctc")}
    names = {"pd": "PD", "pdff": "PD + feedforward", "ctc": "computed torque"}
    for c, (rms, top) in payload.items():
        assert f"{rms:.2f} mm ({top:.3g} mm) with {names[c]}" in text, c
    rms, top = _control(capsys, "--controller", "ctc")
    assert f"RMS {rms:.2g} mm (maximum {top:.2g} mm), half that at 2 kHz" in text
    fast = _control(capsys, "--controller", "ctc", "--rate", "2000")
    assert 0.45 < fast[0] / rms < 0.55 and 0.45 < fast[1] / top < 0.55
    mid = _control(capsys, "--controller", "ctc", "--feedforward-at", "mid")
    assert f"{top / mid[1]:.2g} x for computed torque (to {mid[1] * 1e3:.2g} µm; RMS {mid[0] * 1e3:.2g} µm)" in text
    pdff = _control(capsys, "--controller", "pdff")
    pdff_mid = _control(capsys, "--controller", "pdff", "--feedforward-at", "mid")
    assert (
        f"{pdff[1] / pdff_mid[1]:.2g} x for PD + feedforward (to {pdff_mid[1] * 1e3:.2g} µm from {pdff[1]:.2g} mm; "
        f"RMS {pdff_mid[0] * 1e3:.2g} µm)"
    ) in text
