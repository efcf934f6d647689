"""Feeding the reference forward at the middle of the hold interval (issue 27): the zero-order hold's error of an
exact model, ∝ 1/rate when the feedforward is taken at the sample instant, mostly goes; scaling laws in the rate."""

from __future__ import annotations

import pytest

from tests.support.cli import parser_for
from tpm_viz.cli import control as cli_control
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.paper.control import Gains

P = Params.paper()
GAINS = Gains(10.0, 1.0)  # the settings of docs/control.md: ω_n = 10 Hz, ζ = 1


def max_error(controller: str, rate: float, at: str) -> float:
    setup = ControlSetup(controller=controller, gains=GAINS, rate=rate, feedforward_at=at)
    return simulate(P, "circle", setup).max_error


def test_computed_torque_mid_interval_feedforward_cuts_the_hold_error():
    sample = [max_error("ctc", rate, "sample") for rate in (1000.0, 2000.0)]
    mid = [max_error("ctc", rate, "mid") for rate in (1000.0, 2000.0)]
    assert 80e-6 < sample[0] < 150e-6  # ~0.1 mm at 1 kHz: the hold, not the model (exact here)
    assert 1.7 < sample[0] / sample[1] < 2.3  # ∝ 1/rate
    assert mid[0] < 0.35 * sample[0] and mid[1] < 0.35 * sample[1]
    assert 1.7 < mid[0] / mid[1] < 2.3  # what is left is the feedback's own lag, still ∝ 1/rate


def test_pd_feedforward_at_mid_interval_leaves_a_second_order_error():
    sample = max_error("pdff", 1000.0, "sample")
    mid = [max_error("pdff", rate, "mid") for rate in (1000.0, 2000.0)]
    assert mid[0] < 0.05 * sample
    assert 3.4 < mid[0] / mid[1] < 4.6  # ∝ 1/rate²: the midpoint rule


def test_feedforward_at_is_validated():
    with pytest.raises(InputError, match="feedforward_at"):
        ControlSetup(feedforward_at="end")


def test_the_command_line_option_feeds_forward_at_mid_interval(tmp_path, capsys):
    errors = {}
    for at in ("sample", "mid"):
        out = tmp_path / f"{at}.csv"
        argv = ["control", "--trajectory", "circle", "--controller", "pdff", "--feedforward-at", at]
        args = parser_for(cli_control).parse_args([*argv, "--output", str(out)])
        assert args.func(args) == 0
        errors[at] = float(capsys.readouterr().err.split("max error ")[1].split(" mm")[0])
    assert errors["mid"] < 0.05 * errors["sample"]  # the same runs as above, through the CLI
