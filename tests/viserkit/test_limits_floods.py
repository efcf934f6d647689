"""Quiet, bounded faults (issue 23): a GUI update whose id is a list gave one full traceback per message (2,000
messages: 20,000 log lines) and the tab was never dropped. Malformed ids and fields of any message type are now
refused at the transport check, every unexpected failure of a tab's callback goes through the per-tab log limit,
and a tab that keeps sending malformed messages is dropped (:attr:`~tpm_viz.viserkit.limits.Limits.max_malformed` in
:attr:`~tpm_viz.viserkit.limits.Limits.malformed_window` seconds). Servers on 127.0.0.1, port 0; protocol-level clients.
"""

from __future__ import annotations

import logging

import pytest

from tests.support.fixtures import open_tab
from tests.support.protocol import wait_for
from tpm_viz.classroom import guard
from tpm_viz.classroom.guard import ACTIVITY, report
from tpm_viz.viserkit.limits import guard_of

FLOOD = 2000

MALFORMED = [
    {"type": "GuiUpdateMessage", "uuid": [1, 2], "updates": {"value": 1.0}},
    {"type": "GuiUpdateMessage", "uuid": {"a": 1}, "updates": {"value": 1.0}},
    {"type": "GuiUpdateMessage", "uuid": "x", "updates": [1, 2]},
    {"type": "GuiFormSubmitMessage", "uuid": [1]},
    {"type": "TransformControlsUpdateMessage", "name": [1], "owner": "", "wxyz": (1, 0, 0, 0), "position": (0, 0, 0)},
    {"type": "TransformControlsDragStartMessage", "name": {"x": 1}, "owner": [2]},
    {"type": "SceneNodeClickMessage", "name": [1], "instance_index": "x", "ray_origin": [1], "ray_direction": 2},
    {"type": "FileTransferStartUpload", "source_component_uuid": [1], "transfer_uuid": {}, "filename": 3},
    {"type": "FileTransferPart", "source_component_uuid": [1], "transfer_uuid": [2], "part_index": "0", "content": 5},
    {"type": "GuiUpdateMessage", "uuid": "x" * 5_000, "updates": {"value": 1.0}},
]


def _lines(caplog) -> list[str]:
    return [line for r in caplog.records for line in (r.getMessage() + "\n" + (r.exc_text or "")).splitlines()]


@pytest.fixture
def tabs(app):
    opened: list = []
    yield lambda: open_tab(app, opened)
    for client in opened:
        client.close()


@pytest.mark.parametrize("message", MALFORMED, ids=[f"{m['type']}-{i}" for i, m in enumerate(MALFORMED)])
def test_a_malformed_message_is_refused_at_the_transport_check_with_one_line(app, tabs, caplog, message):
    client, view = tabs()
    errors = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.INFO):
        for _ in range(5):  # under the drop limit: the tab stays
            client.send(**message)
        client.set_value(view.panel.d[0], 160.0)  # a good message after the bad ones is still handled
        wait_for(lambda: abs(view.session.state.pose.d[0] - 0.16) < 1e-9, what="the good update")
    text = "\n".join(_lines(caplog))
    assert "message dropped" in text and "Traceback" not in text and "never retrieved" not in text, text[:2000]
    assert ACTIVITY.snapshot()[1] == errors and view in app.views.values()


def test_a_flood_of_gui_updates_with_a_list_id_is_a_few_lines_and_drops_the_tab(app, tabs, caplog):
    client, view = tabs()
    _other, bystander = tabs()
    limits = guard_of(app.server).limits
    with caplog.at_level(logging.INFO):
        for _ in range(FLOOD):  # before: 20,000 log lines, and the tab stayed
            try:
                client.send(type="GuiUpdateMessage", uuid=[1, 2], updates={"value": 1.0})
            except Exception:
                break
        wait_for(lambda: view not in app.views.values(), timeout=60.0, what="the flooding tab to be dropped")
    lines = _lines(caplog)
    assert len(lines) <= 20, lines  # one line a second per kind, a few kinds, and the drop
    assert not [line for line in lines if "Traceback" in line or "never retrieved" in line]
    assert any(f"over {limits.max_malformed} malformed messages" in line for line in lines)
    assert bystander in app.views.values()  # the other tab is untouched
    _other.set_value(bystander.panel.d[0], 160.0)
    wait_for(lambda: abs(bystander.session.state.pose.d[0] - 0.16) < 1e-9, what="the bystander still served")


def test_a_tabs_repeated_callback_failure_logs_one_traceback_then_rate_limited_lines(caplog, monkeypatch):
    monkeypatch.setattr(guard, "_TRACED", {})
    clock = [1000.0]
    monkeypatch.setattr(guard.time, "monotonic", lambda: clock[0])
    monkeypatch.setattr(guard, "FAULTS", guard.Faults(clock=lambda: clock[0]))
    monkeypatch.setattr(guard, "log_fault", guard.FAULTS)
    with caplog.at_level(logging.INFO, logger="tpm_viz.ui"):
        for _ in range(1000):
            report(ZeroDivisionError("boom"), "a callback", client=7)
        traced = [r for r in caplog.records if r.exc_info]
        assert len(traced) == 1 and len(caplog.records) == 2  # the traceback, then one line for the rest
        clock[0] += guard.TRACEBACK_INTERVAL
        report(ZeroDivisionError("boom"), "a callback", client=7)
        assert len([r for r in caplog.records if r.exc_info]) == 2  # a minute later: the traceback again
        report(ZeroDivisionError("boom"), "a server thread")  # the server's own failures always log it
        report(ZeroDivisionError("boom"), "a server thread")
        assert len([r for r in caplog.records if r.exc_info]) == 4
