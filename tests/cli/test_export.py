"""``tpm-viz export``: register() on a plain argparse parser (the family is wired into ``tpm-viz`` by the lead)."""

from __future__ import annotations

import argparse
import os
import xml.etree.ElementTree as ET

import pytest

import tpm_viz as tv
from tests.support.cli import parser_for
from tpm_viz.cli import export as cli_export
from tpm_viz.cli.common import common_parent
from tpm_viz.core import files
from tpm_viz.core.errors import InputError, InvalidParametersError
from tpm_viz.exchange.mjcf import DEFAULT_SETTINGS, MjcfSettings, mjcf_text
from tpm_viz.exchange.topology import joint_motion, topology
from tpm_viz.exchange.urdf import urdf_text


def plain_parser() -> argparse.ArgumentParser:
    return parser_for(cli_export)


def run(*argv: str) -> int:
    args = plain_parser().parse_args(list(argv))
    return args.func(args)


def test_mjcf_export_is_the_library_text_and_honours_set(tmp_path):
    out = tmp_path / "tpm.xml"
    assert run("export", "--format", "mjcf", "--output", str(out)) == 0
    assert out.read_text() == mjcf_text(tv.Params.paper())
    assert run("export", "--format", "mjcf", "--output", str(out), "--set", "m_p=4.42", "--set", "l_a=0.3") == 0
    root = ET.fromstring(out.read_text())
    platform = root.find(".//body[@name='platform']/inertial")
    assert float(platform.get("mass")) == 4.42
    assert float(root.find(".//body[@name='link1_0']/site").get("pos").split()[0]) == 0.3
    assert [p.name for p in tmp_path.iterdir()] == ["tpm.xml"]  # no temporary file left behind
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask  # as a plain open() would make it, not mkstemp's 0600


def test_urdf_export_and_replacing_an_existing_file(tmp_path):
    out = tmp_path / "tpm.urdf"
    out.write_text("old content")
    out.chmod(0o640)
    assert run("export", "--format", "urdf", "--output", str(out)) == 0
    assert out.read_text() == urdf_text(tv.Params.paper())
    assert ET.fromstring(out.read_text()).tag == "robot"
    assert out.stat().st_mode & 0o777 == 0o640  # the replaced file keeps its permissions


def test_timestep_option_sets_the_step_and_the_constraint_time_constant(tmp_path):
    out = tmp_path / "fast.xml"
    assert run("export", "--format", "mjcf", "--output", str(out), "--timestep", "0.001") == 0
    root = ET.fromstring(out.read_text())
    assert float(root.find("option").get("timestep")) == 0.001
    assert [float(x) for x in root.find("equality/connect").get("solref").split()] == [
        0.002,
        DEFAULT_SETTINGS.solref[1],
    ]
    with pytest.raises(InputError, match="mjcf only"):
        run("export", "--format", "urdf", "--output", str(out), "--timestep", "0.001")
    with pytest.raises(InputError, match="--timestep"):
        run("export", "--format", "mjcf", "--output", str(out), "--timestep", "-1")


def test_stdout_output(capsys):
    assert run("export", "--format", "urdf", "--output", "-") == 0
    assert capsys.readouterr().out == urdf_text(tv.Params.paper())


def test_bad_input_raises_one_line_errors_and_writes_nothing(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        run("export", "--format", "mjcf", "--output", str(tmp_path / "missing" / "x.xml"))
    with pytest.raises(InvalidParametersError):
        run("export", "--format", "mjcf", "--output", str(tmp_path / "x.xml"), "--set", "l_a=0.01")
    with pytest.raises(SystemExit):
        plain_parser().parse_args(["export", "--format", "sdf", "--output", "x"])
    with pytest.raises(SystemExit):
        plain_parser().parse_args(["export", "--format", "mjcf"])
    assert os.listdir(tmp_path) == []


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    out = tmp_path / "keep.xml"
    out.write_text("previous model")

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(files.os, "replace", broken_replace)
    with pytest.raises(OSError):
        cli_export.write_atomically(str(out), "new model")
    assert out.read_text() == "previous model"
    assert os.listdir(tmp_path) == ["keep.xml"]


def test_register_works_with_the_real_common_parent(tmp_path):
    parser = argparse.ArgumentParser(prog="tpm-viz")
    cli_export.register(parser.add_subparsers(dest="command", required=True), common_parent())
    out = tmp_path / "m.xml"
    args = parser.parse_args(["export", "--format", "mjcf", "--output", str(out), "--set", "m_a=2"])
    assert args.func(args) == 0
    assert float(ET.fromstring(out.read_text()).find(".//body[@name='slider1']/inertial").get("mass")) == 2.0


@pytest.mark.parametrize(
    "change",
    [
        {"timestep": 0.0},
        {"timestep": float("nan")},
        {"solref": (-1.0, 1.0)},
        {"solimp": (0.99, 0.9, 1e-3, 0.5, 2.0)},
        {"solimp": (0.9, 1.0, 1e-3, 0.5, 2.0)},
        {"integrator": "Verlet"},
        {"iterations": 0},
    ],
)
def test_mjcf_settings_are_validated(change):
    with pytest.raises(InputError):
        MjcfSettings(**change)


def test_exchange_rejects_bad_input_with_library_errors():
    with pytest.raises(InputError, match="Params"):
        topology({"a": 0.4})
    with pytest.raises(InputError, match="Params"):
        urdf_text(None)
    with pytest.raises(InputError, match="MjcfSettings"):
        mjcf_text(tv.Params.paper(), settings={"timestep": 1e-3})
    with pytest.raises(InputError, match="one platform state"):
        joint_motion(tv.Params.paper(), [[0.0, 0.0], [0.1, 0.0]])
    with pytest.raises(tv.UnreachablePoseError):
        joint_motion(tv.Params.paper(), (0.3, 0.0))
    p = tv.Params.paper()
    assert topology(p).moving_mass == pytest.approx(2 * p.m_a + 2 * p.m_b + p.m_p, rel=1e-12)
