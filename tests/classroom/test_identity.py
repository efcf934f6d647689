"""Identities the server issues (tpm_viz.classroom.identity, .away): signed cookies, hashed keys, bounds per source
address against the self-made-cookie eviction, the presenter's right tied to the address and two minutes."""

from __future__ import annotations

import hashlib
import hmac
import logging
import stat

import pytest

from tpm_viz.app.state import AppState
from tpm_viz.classroom.away import MAX_PER_ADDRESS, PRESENTER_SECONDS, Away
from tpm_viz.classroom.identity import SECRET_FILE, Keys
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.ui.classroom import identity


class Headers(dict):
    def get_all(self, name):
        return [self[name]] if name in self else []


def test_a_cookie_is_the_servers_only_if_it_signed_it(tmp_path):
    keys, notice = Keys.in_folder(tmp_path)
    assert notice is None
    secret = (tmp_path / SECRET_FILE).read_bytes()
    assert stat.S_IMODE((tmp_path / SECRET_FILE).stat().st_mode) == 0o600 and len(secret) == 32
    value = keys.mint()
    ident, mac = value.split(".")
    assert mac == hmac.new(secret, ident.encode(), hashlib.sha256).hexdigest()[:32]  # HMAC-SHA256, recomputed
    assert keys.verify(value) == ident and Keys.in_folder(tmp_path)[0].verify(value) == ident  # kept across starts
    assert keys.verify("ab" * 16) is None  # yesterday's self-made 32-hex cookie
    assert keys.verify(f"{ident}.{'0' * 32}") is None and keys.verify(f"{'0' * 32}.{mac}") is None
    assert Keys().verify(value) is None and keys.verify(None) is None and keys.verify(value + "0") is None


def test_the_stored_identity_is_a_hash_and_a_self_made_cookie_owns_nothing():
    keys = Keys()
    value = keys.mint()
    headers = Headers(Cookie=f"tpmviz_id={value}", Origin="http://x")
    key = identity(("10.0.0.5", 1), headers, keys)
    assert key == "c:" + hashlib.sha256(value.split(".")[0].encode()).hexdigest() and value.split(".")[0] not in key
    forged = identity(("10.0.0.5", 1), Headers(Cookie="tpmviz_id=" + "ab" * 16, Origin="http://x"), keys)
    assert forged.startswith("a:") and "ab" * 16 not in forged  # known by address only: offered back, never restored
    assert identity(("10.0.0.5", 1), Headers(Cookie="tpmviz_id=" + "ab" * 16), keys) is None  # not a browser


def test_2400_self_made_identities_from_one_address_evict_only_that_addresses_own(caplog):
    """The attack: open and close 2,400 tabs with self-chosen cookies (each a new identity). Students who dropped
    before keep their copies; the attacker's address keeps at most its share."""
    keys, away, saved = Keys(), Away(log_clock=lambda: 0.0), Saved(AppState.initial())  # all within a minute
    students = {}
    for k in range(30):
        students[f"10.0.0.{k + 10}"] = key = identity(
            (f"10.0.0.{k + 10}", 1), Headers(Cookie=f"tpmviz_id={keys.mint()}"), keys
        )
        away.park(key, True, saved, address=f"10.0.0.{k + 10}")
    with caplog.at_level(logging.WARNING, logger="tpm_viz.classroom"):
        for k in range(2400):
            forged = Headers(Cookie=f"tpmviz_id={k:032x}", Origin="http://x", **{"User-Agent": f"bot {k}"})
            away.park(identity(("10.0.0.66", 1), forged, keys), True, saved, address="10.0.0.66")
    assert all(away.offer(key) is not None for key in students.values())  # every student's copy is still there
    assert len(away) == len(students) + MAX_PER_ADDRESS
    assert sum("10.0.0.66" in r.message for r in caplog.records) == 1  # one line a minute (test_eviction_log.py)
    assert not any("10.0.0.1" in r.message and "10.0.0.66" not in r.message for r in caplog.records)


def test_when_everything_is_full_the_address_with_the_most_gives_way(monkeypatch):
    monkeypatch.setattr("tpm_viz.classroom.away.MAX_AWAY", 10)
    away, saved = Away(), Saved(AppState.initial())
    for k in range(6):
        away.park(f"hog{k}", True, saved, address="10.0.0.66")
    for k in range(4):
        away.park(f"s{k}", True, saved, address=f"10.0.0.{k}")
    away.park("late", True, saved, address="10.0.0.99")  # a student arriving: the hog's oldest goes
    assert away.offer("hog0") is None and all(away.offer(f"s{k}") for k in range(4)) and away.offer("late")


@pytest.mark.parametrize(
    ("address", "after", "presenter"),
    [("127.0.0.1", 5.0, True), ("127.0.0.2", 5.0, False), ("127.0.0.1", PRESENTER_SECONDS + 1, False)],
)
def test_the_presenters_right_comes_back_only_from_its_address_within_two_minutes(address, after, presenter):
    now = [1000.0]
    away = Away(clock=lambda: now[0])
    away.park("c:p", False, Saved(AppState.initial()), presenter=True, address="127.0.0.1")
    now[0] += after
    record = away.take("c:p")
    assert record is not None and away.presenter(record, address) is presenter


def test_a_new_login_ends_every_dropped_presenters_right():
    away = Away()
    away.park("c:p", False, None, presenter=True, address="127.0.0.1")
    away.end_presenters()
    assert not away.presenter(away.take("c:p"), "127.0.0.1")
