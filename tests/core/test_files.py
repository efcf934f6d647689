"""The one file reader (tpm_viz/core/files.py) against the files that stopped, hung or leaked through the old readers:
/dev/zero, a FIFO, /proc/self/environ, a symlink out of the folder, 200 kB of ``[``, a deeply nested TOML."""

from __future__ import annotations

import json
import os
import threading

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.core import files
from tpm_viz.core.errors import FileRefusedError, InputError

SECRET = "TOP-SECRET-LINE"


def _one_line(exc: pytest.ExceptionInfo[FileRefusedError], path: object) -> str:
    text = str(exc.value)
    assert "\n" not in text and str(path) in text, text
    assert SECRET not in text and "root:" not in text
    return text


def test_a_regular_file_inside_its_folder_is_read(tmp_path):
    (tmp_path / "a.txt").write_bytes(b"\xef\xbb\xbfhello")
    assert files.read_text(tmp_path / "a.txt", 100, root=tmp_path) == "hello"
    assert files.read_text("a.txt", 100, root=tmp_path) == "hello"  # relative to the root
    assert files.read_bytes(tmp_path / "a.txt", 8) == b"\xef\xbb\xbfhello"  # exactly the limit


def test_the_size_limit_is_checked_before_reading_and_while_reading(tmp_path):
    big = tmp_path / "big.bin"
    big.write_bytes(b"x" * 1001)
    with pytest.raises(FileRefusedError) as exc:
        files.read_bytes(big, 1000)
    assert "larger than 1000 bytes" in _one_line(exc, big)


def test_dev_zero_is_refused_at_once():
    with pytest.raises(FileRefusedError) as exc:
        files.read_bytes("/dev/zero", 1 << 20)
    _one_line(exc, "/dev/zero")


def test_a_symlink_to_a_device_is_refused(tmp_path):
    (tmp_path / "zero").symlink_to("/dev/zero")
    with pytest.raises(FileRefusedError):
        files.read_bytes(tmp_path / "zero", 1 << 20, root=tmp_path)
    with pytest.raises(FileRefusedError):
        files.read_bytes(tmp_path / "zero", 1 << 20)


def test_a_fifo_without_a_writer_is_refused_and_does_not_hang(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    outcome: list[BaseException] = []

    def read() -> None:
        try:
            files.read_bytes(fifo, 1000, root=tmp_path)
        except BaseException as exc:
            outcome.append(exc)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(60.0)  # a hang would leave the thread blocked in open(); generous bound for a loaded machine
    if reader.is_alive():  # unblock it before failing, so the test run does not hang either
        with open(fifo, "wb"):
            pass
        pytest.fail("reading a FIFO hung")
    assert len(outcome) == 1 and isinstance(outcome[0], FileRefusedError)
    assert "pipe (FIFO)" in str(outcome[0]) and str(fifo) in str(outcome[0])


def test_a_folder_is_refused(tmp_path):
    with pytest.raises(FileRefusedError) as exc:
        files.read_bytes(tmp_path, 1000)
    assert "folder" in _one_line(exc, tmp_path)


def test_proc_self_environ_is_refused_without_quoting_it(monkeypatch):
    monkeypatch.setenv("TPM_VIZ_TEST_SECRET", SECRET)
    with pytest.raises(FileRefusedError) as exc:
        files.read_bytes("/proc/self/environ", 1 << 20)
    _one_line(exc, "/proc/self/environ")


def test_a_symlink_out_of_the_folder_is_refused(tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text(SECRET)
    lessons = tmp_path / "lessons"
    lessons.mkdir()
    (lessons / "link.toml").symlink_to(outside)
    (lessons / "passwd").symlink_to("/etc/passwd")
    for name in ("link.toml", "passwd", "../outside.txt", "/etc/passwd", str(outside)):
        with pytest.raises(FileRefusedError) as exc:
            files.read_bytes(name if name.startswith("/") else lessons / name, 1 << 20, root=lessons)
        assert "outside the folder" in str(exc.value) and SECRET not in str(exc.value)
    (lessons / "inner").symlink_to(lessons / "link.toml")  # a link to a link out is still out
    with pytest.raises(FileRefusedError):
        files.read_bytes(lessons / "inner", 1 << 20, root=lessons)


def test_a_missing_file_is_one_line(tmp_path):
    with pytest.raises(FileRefusedError) as exc:
        files.read_bytes(tmp_path / "nope.toml", 1000)
    assert "cannot open" in _one_line(exc, tmp_path / "nope.toml")


def test_200_kb_of_brackets_is_refused_not_a_recursion_error(tmp_path):
    path = tmp_path / "session.json"
    path.write_text("[" * 200_000)
    with pytest.raises(FileRefusedError) as exc:
        files.read_json(path, 1 << 20)
    assert "nested deeper than" in _one_line(exc, path) or "not valid JSON" in str(exc.value)
    closed = "[" * 200 + "]" * 200  # valid JSON, deeper than the limit
    with pytest.raises(FileRefusedError, match="nested deeper than 32 levels"):
        files.loads_json(closed, "x.json")
    assert files.depth_of(json.loads("[" * 32 + "]" * 32)) == 32
    assert files.loads_json("[" * 32 + "]" * 32) is not None


def test_deep_toml_is_refused_not_a_recursion_error(tmp_path):
    path = tmp_path / "lesson.toml"
    path.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(FileRefusedError) as exc:
        files.read_toml(path, 1 << 20)
    assert "nested deeper" in _one_line(exc, path)
    inline = "a = " + "{b = " * 50 + "1" + "}" * 50 + "\n"
    with pytest.raises(FileRefusedError, match="nested deeper than 32"):
        files.loads_toml(inline, "x.toml")
    dotted = "a" + ".a" * 40 + " = 1\n"  # no bracket at all, still 41 levels of tables
    with pytest.raises(FileRefusedError, match="nested deeper than 32"):
        files.loads_toml(dotted, "x.toml")


def test_syntax_errors_name_the_line_and_quote_nothing(tmp_path):
    with pytest.raises(FileRefusedError) as exc:
        files.loads_toml(f"title = 1\n{SECRET} here\n", "l.toml")
    assert "line 2" in str(exc.value) and SECRET not in str(exc.value)
    with pytest.raises(FileRefusedError) as exc:
        files.loads_json(f'{{"a": 1}}\n{SECRET}', "s.json")
    assert "line 2" in str(exc.value) and SECRET not in str(exc.value)
    with pytest.raises(FileRefusedError) as exc:
        files.loads_json(b"\n\n\xff" + SECRET.encode(), "s.json")
    assert "line 3" in str(exc.value) and "0xff" not in str(exc.value)


def test_the_refusal_is_an_input_error_of_the_hierarchy():
    assert issubclass(FileRefusedError, InputError)


@settings(max_examples=examples(60), deadline=None)
@given(st.text(alphabet='[]{}"ab,:= \n1.', max_size=400))
def test_no_text_escapes_as_anything_but_a_refusal(text):
    for loads in (files.loads_json, files.loads_toml):
        try:
            loads(text, "fuzz")
        except FileRefusedError as exc:
            assert "\n" not in str(exc)
