"""The texts the teaching tabs write themselves (the control lab's run, table and lesson; the planner's result and
sizing table; the explorer's legend) follow the tab's language: written in Korean after a switch, with the same
numbers, and in English again after a switch back (issue 13)."""

from __future__ import annotations

import re

import pytest

from tests.support.protocol import wait_for
from tpm_viz.classroom.text import LEGEND
from tpm_viz.core.words import Lang, catalogue

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

HANGUL = re.compile("[\uac00-\ud7a3]")


def _text(markup: str) -> str:
    """The words of some HTML (tags removed)."""
    return re.sub(r"<[^>]+>", " ", markup)


def _numbers(markup: str) -> list[str]:
    return re.findall(r"\d+\.\d+", _text(markup))


def _texts(cv, pv) -> dict[str, str]:
    """What the control and planner tabs show now."""
    return {
        "lesson": cv.lesson_text.content,
        "table": cv.table_html.content,
        "summary": cv.summary.content,
        "plan": pv.result_html.content,
        "sizing": pv.sizing.content,
    }


def _switch(view, lang: Lang) -> None:
    view.words.set(lang)
    assert view.lang is lang


def test_the_control_and_planner_texts_are_rewritten_in_the_new_language(connect):
    client, view = connect()
    cv, pv = view.teaching.control, view.teaching.planner
    client.set_value(cv.wn, 10.0)
    wait_for(lambda: cv.wn.value == 10.0, what="ω_n")
    client.click(cv.lesson)
    wait_for(
        lambda: len(cv.table) == 3 and not cv.busy and cv.lesson_text.content and "run-rms" in cv.summary.content,
        timeout=30,
        what="the lesson",
    )
    wait_for(lambda: pv.result is not None and pv.sizing.content, timeout=30, what="the first plan")
    with view.hub.lock:  # a consistent picture: the worker's callbacks write under this lock
        english = _texts(cv, pv)
    assert "Smallest error here" in english["lesson"] and "cycle" in english["plan"]

    _switch(view, Lang.KO)
    with view.hub.lock:
        korean = _texts(cv, pv)
    for name, markup in korean.items():
        assert HANGUL.search(_text(markup)), name
        assert _numbers(markup) == _numbers(english[name]), name  # the same figures, in the same order
    assert "Smallest error here" not in korean["lesson"] and "계산 토크" in korean["lesson"]
    assert "Motor sizing" not in korean["sizing"] and "최대 힘" in korean["sizing"]

    _switch(view, Lang.EN)
    assert cv.lesson_text.content == english["lesson"] and cv.table_html.content == english["table"]
    assert pv.sizing.content == english["sizing"]


def test_the_explorer_legend_follows_the_language(connect):
    _client, view = connect()
    ev = view.teaching.explorer
    with view.hub.lock:
        ev.set(kind="cond")
    assert "condition number of J (log scale)" in ev.legend.content
    _switch(view, Lang.KO)
    assert "J의 조건수 (로그 눈금)" in ev.legend.content and "100" in ev.legend.content
    _switch(view, Lang.EN)
    assert "condition number of J (log scale)" in ev.legend.content


def test_the_scene_labels_are_symbols_and_the_legend_says_what_they_mean_in_both_languages(connect):
    """The 3D labels are drawn once for every tab (broadcast), so they carry no words a Korean tab would read in
    English; the legend, a per-tab text, names P′ in each language."""
    _client, view = connect()
    texts = sorted(label.text for label in view.hub.shared.scene.labels)
    assert texts == sorted(["O", "A₁", "A₂", "B₁", "B₂", "P", "P′"])
    entry = next(text for _colour, text in LEGEND if "P′" in text)
    assert "other assembly mode" in entry
    korean = catalogue(Lang.KO)[entry]
    assert "P′" in korean and "조립 모드" in korean
