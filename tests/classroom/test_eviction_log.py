"""The log of browsers forgotten over the per-address cap (issue 35, item 8): 400 minted cookies from one address
wrote 248 WARNING lines. Now one line per address per minute, and the next line says how many were not said."""

from __future__ import annotations

import logging

from tpm_viz.app.state import AppState
from tpm_viz.classroom.away import EVICTION_LOG_SECONDS, MAX_PER_ADDRESS, Away
from tpm_viz.classroom.identity import Keys, hashed
from tpm_viz.classroom.sessionfile import Saved


def _lines(caplog, address: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING and address in r.getMessage()]


def test_400_minted_cookies_from_one_address_are_one_line_a_minute_with_the_count(caplog):
    now = [100.0]
    keys, away, saved = Keys(), Away(log_clock=lambda: now[0]), Saved(AppState.initial())
    away.park(hashed("c", "a student"), True, saved, address="10.0.0.7")
    with caplog.at_level(logging.WARNING, logger="tpm_viz.classroom"):
        for _ in range(400):  # a student's script: a new signed cookie per tab, each tab opened and closed
            away.park(hashed("c", keys.mint()), True, saved, address="10.0.0.66")
            now[0] += 0.1  # 40 s in all: within the minute
        assert _lines(caplog, "10.0.0.66") == [
            f"browsers from 10.0.0.66: forgot the oldest one's remembered tabs (over its {MAX_PER_ADDRESS} "
            "remembered browsers)"
        ]
        now[0] += EVICTION_LOG_SECONDS  # a minute later, one more: it says how many were not said meanwhile
        away.park(hashed("c", keys.mint()), True, saved, address="10.0.0.66")
    lines = _lines(caplog, "10.0.0.66")
    evicted, first = 400 + 1 - MAX_PER_ADDRESS, 100.0 + 0.1 * MAX_PER_ADDRESS  # the 151st browser: the first said
    assert len(lines) == 2 and lines[1].endswith(f"(+{evicted - 2} more in the last {now[0] - first:.1f} s)"), lines
    assert away.offer(hashed("c", "a student")) is not None and not _lines(caplog, "10.0.0.7")


def test_each_address_has_its_own_minute(caplog):
    now = [0.0]
    away, saved = Away(log_clock=lambda: now[0]), Saved(AppState.initial())
    with caplog.at_level(logging.WARNING, logger="tpm_viz.classroom"):
        for address in ("10.0.0.66", "10.0.0.67"):
            for k in range(MAX_PER_ADDRESS + 5):
                away.park(f"c:{address}:{k}", True, saved, address=address)
    assert len(_lines(caplog, "10.0.0.66")) == 1 and len(_lines(caplog, "10.0.0.67")) == 1
