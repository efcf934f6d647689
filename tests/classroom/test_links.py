"""Share-link tokens (tpm_viz.classroom.links): the state round trip, a large upload kept by content hash, and one-line
refusals of damaged, forged, foreign-version and bomb tokens (built here by hand, not by the code under test)."""

from __future__ import annotations

import base64
import hashlib
import json
import zlib

import numpy as np
import pytest

from tpm_viz import InputError
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load
from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState, TrajectorySample
from tpm_viz.classroom.links import LINK_VERSION, MAX_TOKEN_CHARS, decode_link, encode_link
from tpm_viz.classroom.sessionfile import Saved, encode_saved
from tpm_viz.core.params import Params
from tpm_viz.paper.trajectories import Trajectory


def _source(n: int) -> Source:
    t = np.linspace(0.0, 0.4, n)
    p = np.column_stack([0.05 * np.sin(5 * t), 0.03 * t])
    return Source.from_trajectory(Trajectory("mine", t, p, np.zeros_like(p), np.zeros_like(p)))


def _saved(n: int = 9) -> Saved:
    params = Params.paper(l_a=0.28)
    state = AppState(params, Pose.working(params, (0.02, -0.01)), Load("static", f_ext=(5.0, -3.0)),
                     TrajectorySample("csv", 0.4, 0.1))  # fmt: skip
    return Saved(state, _source(n), 0.25, {"labels": False, "trace": True}, "ko")


def _token(raw, version: int = LINK_VERSION) -> str:
    """A token made by hand from the documented layout: version.base64url(deflate(json)).sha256[:16]."""
    payload = zlib.compress(json.dumps(raw).encode())
    body = base64.urlsafe_b64encode(payload).decode().rstrip("=")
    return f"{version}.{body}.{hashlib.sha256(payload).hexdigest()[:16]}"


def _refused(token: str, match: str, get_blob=None) -> str:
    with pytest.raises(InputError, match=match) as info:
        decode_link(token, get_blob)
    text = str(info.value)
    assert "\n" not in text
    return text


def test_round_trip_keeps_parameters_pose_load_trajectory_time_view_and_language():
    saved = _saved()
    token = encode_link(saved)
    assert len(token) < 1500 and all(c.isalnum() or c in "._-" for c in token)  # fits a URL as it is
    back = decode_link(token)
    s = back.state
    assert s.params == saved.state.params and s.load == saved.state.load and s.trajectory == saved.state.trajectory
    np.testing.assert_allclose(s.pose.p, (0.02, -0.01))
    np.testing.assert_allclose(back.source.knots[1], saved.source.knots[1])
    assert (back.playing_t, back.show, back.lang) == (0.25, {"labels": False, "trace": True}, "ko")
    again = decode_link(_token(encode_saved(saved))).state  # the layout as documented
    assert again.params == s.params and np.array_equal(again.pose.p, s.pose.p) and again.load == s.load


def test_a_large_upload_is_kept_by_content_hash_and_refused_elsewhere_in_one_line():
    blobs: dict[str, bytes] = {}

    def put(data: bytes) -> str:
        digest = hashlib.sha256(data).hexdigest()
        blobs[digest] = data
        return digest

    saved = _saved(2000)
    token = encode_link(saved, put)
    assert len(token) <= MAX_TOKEN_CHARS and len(blobs) == 1
    back = decode_link(token, blobs.get)
    np.testing.assert_allclose(back.source.knots[1], saved.source.knots[1])
    text = _refused(token, "kept on the server that made the link", lambda d: None)  # another server
    assert "upload the CSV here" in text
    (digest,) = blobs
    blobs[digest] = blobs[digest].replace(b"0", b"1", 1)  # the store's copy damaged
    _refused(token, "damaged on this server", blobs.get)
    with pytest.raises(InputError, match="too large for a link"):
        encode_link(saved)


def test_damaged_tokens_are_refused_in_one_line():
    token = encode_link(_saved())
    version, body, checksum = token.split(".")
    flipped = body[:40] + ("A" if body[40] != "A" else "B") + body[41:]
    for bad in (
        f"{version}.{flipped}.{checksum}",
        token[:-1],
        token + "x",
        "",
        "garbage",
        f"{version}.{body}.{'0' * 16}",
    ):
        _refused(bad, "damaged")


def test_forged_states_are_refused_field_by_field():
    raw = encode_saved(_saved())
    for edit, why in (
        (lambda r: r["params"].update(l_a=-1.0), "positive"),
        (lambda r: r["params"].update(zz=1.0), "unknown parameter"),
        (lambda r: r.update(p=[0.05, 0.05]), "does not close the legs"),
        (lambda r: r["load"].update(mode="teleport"), "mode|load"),
        (lambda r: r["trajectory"].update(t=[0, 1, 1, 2], p=[[0, 0]] * 4), "increase"),
    ):
        forged = json.loads(json.dumps(raw))
        edit(forged)
        text = _refused(_token(forged), "share link's state is refused")  # before or after the session checks
        assert why.split("|")[0] in text or why.split("|")[-1] in text, text
    _refused(_token([1, 2, 3]), "damaged")  # not an object
    _refused(_token({"trajectory": {"stored": "../../etc/passwd"}}), "damaged")


def test_another_version_and_a_bomb_are_refused():
    _refused(_token(encode_saved(_saved()), version=LINK_VERSION + 1), f"version {LINK_VERSION + 1}")
    bomb = zlib.compress(b"[" * 20_000_000)
    body = base64.urlsafe_b64encode(bomb).decode().rstrip("=")
    _refused(f"{LINK_VERSION}.{body}.{hashlib.sha256(bomb).hexdigest()[:16]}", "damaged")


def test_with_a_store_an_upload_is_kept_by_hash_and_the_link_fits_a_qr_code():
    """Issue 40, item 8: a 400-row CSV made a 2,690-character link, too long for a QR code. With a store (the class
    served) the upload is kept by its SHA-256 and the link names only that; it fits a QR code of version 17 at error
    level M (segno's own count; 85 modules a side, as a link without an upload), and reads back to the same knots."""
    segno = pytest.importorskip("segno")
    blobs: dict[str, bytes] = {}

    def put(data: bytes) -> str:
        digest = hashlib.sha256(data).hexdigest()
        blobs[digest] = data
        return digest

    saved = _saved(400)
    assert len(encode_link(_saved(100))) > 2600  # no store: the knots go in the link (a QR code's worth and more)
    token = encode_link(saved, put)
    url = f"http://192.0.2.7:8080/?share={token}"
    (digest,) = blobs
    body = token.split(".")[1]
    raw = json.loads(zlib.decompress(base64.urlsafe_b64decode(body + "=" * (-len(body) % 4))))
    assert raw["trajectory"] == {"stored": digest} and len(url) < 600  # the link names the upload by its hash only
    assert segno.make(url, error="m").version <= 17
    back = decode_link(token, blobs.get)
    np.testing.assert_allclose(back.source.knots[1], saved.source.knots[1])
    assert back.state.params == saved.state.params and back.playing_t == saved.playing_t


def test_a_link_naming_an_unknown_upload_quotes_nothing_of_it():
    """A hand-made link that names a digest this server lacks, with markup in every text field it could carry: one
    line, and no character of the link's own text in it."""
    raw = encode_saved(_saved())
    hostile = "<img src=x onerror=alert(1)>**bold**"
    raw["trajectory"] = {"stored": "ab" * 32, "label": hostile, "name": hostile}
    text = _refused(_token(raw), "kept on the server that made the link", lambda d: None)
    assert "<" not in text and "img" not in text and "bold" not in text and "ab" * 32 not in text
