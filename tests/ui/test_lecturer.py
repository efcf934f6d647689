"""The lecturer's join box warns when the students' URL can only be reached from this computer (served on loopback),
and says nothing of it when the URL is on the room's network."""

from __future__ import annotations

from tpm_viz.core.words import Lang, say
from tpm_viz.ui.lecturer import LOOPBACK_ONLY, join_html


def test_a_loopback_only_class_is_warned_in_the_panel():
    assert LOOPBACK_ONLY.template in join_html(["http://127.0.0.1:8080", "http://localhost:8080"])
    assert LOOPBACK_ONLY.template in join_html(["http://[::1]:8080"])


def test_a_room_network_url_gets_no_warning():
    assert LOOPBACK_ONLY.template not in join_html(["http://192.168.1.10:8080"])
    assert LOOPBACK_ONLY.template not in join_html(["http://127.0.0.1:8080", "http://10.0.0.5:8080"])


def test_the_warning_has_korean():
    assert say(Lang.KO, LOOPBACK_ONLY) != LOOPBACK_ONLY.template
