"""``tpm-viz export --format c`` and what is already in its folder (issue 35, item 2, the C export's part): an edited
file is not replaced without ``--force``, a symbolic link (the folder or a file) is never written through, a FIFO or
a device of a file's name is refused without hanging, and a refusal writes nothing."""

from __future__ import annotations

import os
import stat

import numpy as np
import pytest

from tpm_viz.cli import main
from tpm_viz.core.params import Params
from tpm_viz.exchange.c.code import FILES, c_files
from tpm_viz.exchange.c.stamp import stamped, untouched


def export(folder, *extra: str) -> int:
    return main(["export", "--format", "c", "--output", str(folder), *extra])


def snapshot(folder) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file() and not p.is_symlink()}


def test_every_generated_file_carries_its_hash_and_any_changed_byte_breaks_it():
    rng = np.random.default_rng(35)
    for name, text in c_files().items():
        data = text.encode()
        assert untouched(data), name
        assert text.splitlines()[-1].startswith("/* tpm-viz-sha256 ")
        for k in rng.choice(len(data), 300, replace=False):  # a changed byte anywhere, the stamp included
            changed = bytearray(data)
            changed[k] = (changed[k] + 1 + rng.integers(254)) % 256
            assert not untouched(bytes(changed)), (name, k)
        assert not untouched(data.replace(b"\n", b"\r\n"))  # other line endings
        assert not untouched(data[: data.rstrip(b"\n").rfind(b"\n") + 1])  # the stamp removed
        assert not untouched(data + b"/* more */\n")  # a line after the stamp
        assert untouched(stamped("int x;\n").encode()) and untouched(stamped("").encode())


def test_an_untouched_export_is_replaced_and_an_edited_one_needs_force(tmp_path, capsys):
    folder = tmp_path / "gen"
    assert export(folder) == 0
    assert snapshot(folder) == {n: t.encode() for n, t in c_files().items()}
    assert export(folder, "--set", "m_p=4.42") == 0  # untouched: replaced by the new parameters
    assert snapshot(folder)["tpm_2ppa.h"] == c_files(Params.paper(m_p=4.42))["tpm_2ppa.h"].encode()
    header = folder / "tpm_2ppa.h"
    header.write_text(header.read_text().replace("#define TPM_OK 0", "#define TPM_OK 0 /* my note */"))
    before = snapshot(folder)
    capsys.readouterr()
    assert export(folder) == 2
    err = capsys.readouterr().err
    assert err.startswith("tpm-viz: error: ") and err.count("\n") == 1
    assert "tpm_2ppa.h" in err and "--force" in err and "changed after it was exported" in err
    assert snapshot(folder) == before  # nothing written, tpm_2ppa.c (untouched) included
    assert export(folder, "--force") == 0
    assert snapshot(folder) == {n: t.encode() for n, t in c_files().items()}


def test_a_file_of_that_name_that_tpm_viz_did_not_write_counts_as_edited(tmp_path, capsys):
    folder = tmp_path / "gen"
    folder.mkdir()
    (folder / "tpm_2ppa.c").write_text("/* my own controller */\n")
    assert export(folder) == 2
    assert "tpm_2ppa.c" in capsys.readouterr().err
    assert snapshot(folder) == {"tpm_2ppa.c": b"/* my own controller */\n"}


def test_a_replaced_file_keeps_its_permissions(tmp_path):
    folder = tmp_path / "gen"
    assert export(folder) == 0
    os.chmod(folder / "tpm_2ppa.c", 0o640)
    assert export(folder, "--set", "m_p=3") == 0
    assert stat.S_IMODE(os.stat(folder / "tpm_2ppa.c").st_mode) == 0o640
    assert sorted(p.name for p in folder.iterdir()) == sorted(FILES)  # no temporary file left


def test_a_symlinked_output_folder_is_not_followed(tmp_path, capsys):
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    for given in (str(link), f"{link}/", f"{link}//"):  # a trailing slash would resolve the link
        for extra in ((), ("--force",)):
            assert export(given, *extra) == 2
            assert "symbolic link" in capsys.readouterr().err
    assert list(real.iterdir()) == []
    dangling = tmp_path / "dangling"
    dangling.symlink_to(tmp_path / "nowhere")
    assert export(dangling) == 2 and not (tmp_path / "nowhere").exists()


def test_a_symlinked_file_is_not_written_through_even_with_force(tmp_path, capsys):
    folder, elsewhere = tmp_path / "gen", tmp_path / "precious.c"
    folder.mkdir()
    elsewhere.write_text("keep me\n")
    (folder / "tpm_2ppa.c").symlink_to(elsewhere)
    for extra in ((), ("--force",)):
        assert export(folder, *extra) == 2
        err = capsys.readouterr().err
        assert "symbolic link, not a regular file" in err and "tpm_2ppa.c" in err
    assert elsewhere.read_text() == "keep me\n" and (folder / "tpm_2ppa.c").is_symlink()
    assert not (folder / "tpm_2ppa.h").exists()  # the refusal came before any write


def test_a_fifo_or_a_device_of_a_files_name_is_refused_without_hanging(tmp_path, capsys):
    folder = tmp_path / "gen"
    folder.mkdir()
    os.mkfifo(folder / "tpm_2ppa.h")
    for extra in ((), ("--force",)):
        assert export(folder, *extra) == 2
        assert "pipe (FIFO), not a regular file" in capsys.readouterr().err
    assert stat.S_ISFIFO(os.lstat(folder / "tpm_2ppa.h").st_mode)
    os.unlink(folder / "tpm_2ppa.h")
    try:
        os.mknod(folder / "tpm_2ppa.c", stat.S_IFCHR | 0o600, os.makedev(1, 7))  # /dev/full's numbers
    except PermissionError:
        pytest.skip("mknod needs root here; the FIFO case above ran")
    assert export(folder, "--force") == 2
    assert "device, not a regular file" in capsys.readouterr().err
    assert stat.S_ISCHR(os.lstat(folder / "tpm_2ppa.c").st_mode)


def test_an_output_that_is_a_file_or_stdout_is_refused(tmp_path, capsys):
    plain = tmp_path / "plain"
    plain.write_text("x")
    assert export(plain) == 2 and "not a directory" in capsys.readouterr().err
    assert export("-") == 2 and "not '-'" in capsys.readouterr().err
    assert main(["export", "--format", "urdf", "--output", "-", "--force"]) == 2
    assert "--force applies to --format c only" in capsys.readouterr().err
