"""A refused upload is told in the tab's language (issue 13), with the same numbers as the English line.

Two routes, both through the websocket as a browser sends an upload:

- the transport's refusal of a file larger than the limit (``tpm_viz.viserkit.transport.harden``, before any byte is
  buffered), on a bare viser server whose tab is Korean or English (``harden(client, lang=...)``): the notification
  the page receives (``NotificationShowMessage``) is read from the wire;
- the player's refusal of a file it reads (``tpm_viz.app.inputs.read_upload``), in a tab of the app switched to
  Korean: the note under the upload button.

The English lines are written here by hand from the limits.
"""

from __future__ import annotations

import re
import uuid

import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.app.inputs import MAX_UPLOAD_BYTES
from tpm_viz.core.words import Lang
from tpm_viz.ui.app import build_server
from tpm_viz.viserkit.probe import widget_uuid
from tpm_viz.viserkit.transport import harden

HANGUL = re.compile("[\uac00-\ud7a3]")


def _numbers(text: str) -> list[str]:
    return sorted(re.findall(r"\d+(?:\.\d+)?", text))


class Listener(ProtocolClient):
    """A protocol client that keeps the notifications it is shown (title, body)."""

    def __init__(self, port: int) -> None:
        self.shown: list[tuple[str, str]] = []
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        if m.get("type") == "NotificationShowMessage":
            self.shown.append((m["props"]["title"], m["props"]["body"]))


def _start_upload(client: ProtocolClient, button_uuid: str, size: int, parts: int) -> None:
    client.send(
        type="FileTransferStartUpload",
        source_component_uuid=button_uuid,
        transfer_uuid=str(uuid.uuid4()),
        filename="big.csv",
        mime_type="text/csv",
        part_count=parts,
        size_bytes=size,
    )


def _send_file(client: ProtocolClient, button_uuid: str, content: bytes) -> None:
    """What viser's upload button sends for a small file: a transfer start, then its one part."""
    transfer = str(uuid.uuid4())
    head = {"source_component_uuid": button_uuid, "transfer_uuid": transfer}
    client.send(
        type="FileTransferStartUpload",
        **head,
        filename="mine.csv",
        mime_type="text/csv",
        part_count=1,
        size_bytes=len(content),
    )
    client.send(type="FileTransferPart", **head, part_index=0, content=content)


@pytest.fixture
def bare():
    """A bare viser server whose tabs are hardened in the language of ``langs`` (one per tab) and get an upload
    button; yields ``(server, buttons)`` (client id -> the button's uuid)."""
    server = build_server("127.0.0.1", 0)
    langs = iter([Lang.KO, Lang.EN])
    buttons: dict[int, str] = {}

    def connected(client) -> None:
        lang = next(langs)
        harden(client, lang=lambda: lang)
        buttons[client.client_id] = widget_uuid(client.gui.add_upload_button("Upload CSV"))

    server.on_client_connect(connected)
    yield server, buttons
    server.stop()


def test_a_file_over_the_limit_is_refused_in_the_tabs_language(bare):
    server, buttons = bare
    size = MAX_UPLOAD_BYTES + 4096
    english_body = f"the file is too large ({size} bytes; at most {MAX_UPLOAD_BYTES} bytes)"
    tabs = []
    for _ in range(2):  # first tab: Korean, second: English
        before = set(buttons)
        tab = Listener(server.get_port())
        tabs.append(tab)
        new = wait_for(lambda before=before: set(buttons) - before, what="the tab's upload button")
        button = buttons[next(iter(new))]
        _start_upload(tab, button, size, 2)
        wait_for(lambda tab=tab: tab.shown, what="the refusal")
    try:
        (ko_title, ko_body), (en_title, en_body) = tabs[0].shown[0], tabs[1].shown[0]
        assert (en_title, en_body) == ("Upload refused", english_body)
        assert HANGUL.search(ko_title) and HANGUL.search(ko_body), (ko_title, ko_body)
        assert not re.search(r"[A-Za-z]{3,}", ko_title + ko_body), (ko_title, ko_body)
        assert _numbers(ko_body) == _numbers(english_body) == sorted([str(size), str(MAX_UPLOAD_BYTES)])
    finally:
        for tab in tabs:
            tab.close()


def test_the_player_refuses_a_file_in_the_tabs_language(connect):
    client, view = connect()
    player = view.teaching.player
    view.words.set(Lang.KO)
    _send_file(client, widget_uuid(player.upload), b"t,p1,p2\n0,0,0\n1,50,0\n2,100,0\n3,150,0\n")  # mm, not m
    wait_for(lambda: HANGUL.search(re.sub("<[^>]+>", " ", player.note.handle.content)), what="the refusal")
    text = re.sub("<[^>]+>", " ", player.note.handle.content)
    assert "10 m" in text and not re.search(r"[A-Za-z]{3,}", text), text
    view.words.set(Lang.EN)
    _send_file(client, widget_uuid(player.upload), b"t,p1,p2\n0,0,0\n2400,0,0\n4800,0,0\n7200,0,0\n")  # 2 h
    wait_for(
        lambda: "the trajectory lasts 7200 s (at most 3600 s)" in player.note.handle.content,
        what="the English refusal",
    )
