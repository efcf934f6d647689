"""Grades back (AGS): a score at the test platform's line item with the right values, the token cached, the attempt
rule, the platform down then up, an answer lost, slow, a restart and a kill -9 with a score waiting: each score in
the gradebook exactly once, none lost. The platform keeps the latest result by timestamp and refuses an older or
equal one (409; or 200 without change when not strict), as AGS 2.0 §3.4 lets it."""

from __future__ import annotations

import datetime
import os
import signal
import subprocess
import sys
import time

import pytest

from tests.lti.conftest import EXERCISES, launch, ref_of, until
from tpm_viz.classroom.launches import News, Rule
from tpm_viz.core.errors import InputError
from tpm_viz.lti import ledger as ledger_module
from tpm_viz.lti.grades import Backoff, GradeSender, scores_url
from tpm_viz.lti.ledger import Ledger

FAST = Backoff(first=0.05, factor=2.0, most=0.2, jitter=0.1)


def _sender(running, ledger=None, timeout: float = 5.0) -> GradeSender:
    sender = GradeSender(
        ledger or running.ledger, running.tool.config, running.tool.key, lambda: list(EXERCISES), backoff=FAST,
        seed=7, timeout=timeout,
    )  # fmt: skip
    sender.start()
    return sender


@pytest.fixture
def sender(running):
    found = _sender(running)
    yield found
    found.stop()


def _graded(running, platform, hint: str = "student", link: str = "graded"):
    with running.client() as browser:
        return ref_of(launch(browser, running, platform, hint, link), running.tickets)


def test_a_score_arrives_at_the_line_item_with_the_right_values(running, platform, sender):
    found = _graded(running, platform)
    before = time.time()
    assert sender.submit(found.ref, "ex1", 0.7, Rule.BEST) is News.QUEUED
    until(lambda: platform.result("li-1", "student-sub"), "the score at the platform")
    (score,) = platform.posts
    stamp = datetime.datetime.fromisoformat(score.pop("timestamp").replace("Z", "+00:00"))
    assert stamp.utcoffset() == datetime.timedelta(0) and before - 1 <= stamp.timestamp() <= time.time() + 1
    assert score == {
        "userId": "student-sub",
        "scoreGiven": 7.0,  # 0.7 of the line item's 10 points (read from the line item: the launch may read it)
        "scoreMaximum": 10.0,
        "activityProgress": "Completed",
        "gradingProgress": "FullyGraded",
    }
    request = platform.token_requests[0]
    assert set(request["scope"].split()) == {
        "https://purl.imsglobal.org/spec/lti-ags/scope/score",
        "https://purl.imsglobal.org/spec/lti-ags/scope/lineitem.readonly",
    }
    assert len(platform.assertions) == 1  # the platform checked the assertion against /lti/jwks and kept its jti
    until(lambda: running.ledger.outbox() == [], "the acknowledged score out of the outbox (after the answer)")


def test_without_reading_the_line_item_the_exercise_s_maximum_is_used(running, platform, sender):
    found = _graded(running, platform, link="graded-noread")
    sender.submit(found.ref, "ex1", 0.7, Rule.LATEST)
    until(lambda: platform.result("li-2", "student-sub"), "the score")
    assert (platform.posts[0]["scoreGiven"], platform.posts[0]["scoreMaximum"]) == (3.5, 5.0)  # 0.7 x 5 points


def test_the_token_is_cached_and_the_best_rule_sends_only_improvements(running, platform, sender):
    found = _graded(running, platform)
    results = []
    for fraction, news in ((0.5, News.QUEUED), (0.4, News.UNCHANGED), (0.9, News.QUEUED)):
        assert sender.submit(found.ref, "ex1", fraction, Rule.BEST) is news
        if news is News.QUEUED:
            until(lambda f=fraction: (platform.result("li-1", "student-sub") or {}).get("scoreGiven") == 10 * f, "it")
        results.append(platform.result("li-1", "student-sub")["scoreGiven"])
    assert results == [5.0, 5.0, 9.0] and len(platform.posts) == 2 and len(platform.token_requests) == 1
    assert sender.submit(found.ref, "ex1", 0.2, Rule.LATEST) is News.QUEUED  # latest: a worse score is sent too
    until(lambda: platform.result("li-1", "student-sub")["scoreGiven"] == 2.0, "the latest score")
    stamps = [p["timestamp"] for p in platform.posts]
    assert stamps == sorted(stamps) and len(set(stamps)) == 3  # strictly increasing


def test_a_launch_that_cannot_be_graded_is_told_so(running, platform, sender):
    plain = _graded(running, platform, link="plain")
    graded = _graded(running, platform)
    assert sender.submit(plain.ref, "ex1", 1.0, Rule.BEST) is News.NOT_GRADED  # no AGS claim
    assert sender.submit(graded.ref, "ex2", 1.0, Rule.BEST) is News.NOT_GRADED  # not this link's exercise
    assert sender.submit("no-such-ref", "ex1", 1.0, Rule.BEST) is News.NOT_GRADED
    for bad in (-0.1, 1.5, float("nan"), float("inf")):
        with pytest.raises(InputError, match="fraction from 0 to 1"):
            sender.submit(graded.ref, "ex1", bad, Rule.BEST)
    assert running.ledger.outbox() == []


def test_the_platform_down_then_up_gets_the_score_once_and_the_student_is_told_once(running, platform, sender):
    found = _graded(running, platform)
    heard = []
    platform.mode = "down"
    sender.submit(found.ref, "ex1", 0.6, Rule.BEST, tell=heard.append)
    until(lambda: running.ledger.outbox() and running.ledger.outbox()[0][1] >= 3, "three tries while down")
    assert heard == [News.ON_ITS_WAY]  # once, however many tries
    platform.mode = "up"
    until(lambda: heard[-1] is News.SENT, "the score sent")
    assert heard == [News.ON_ITS_WAY, News.SENT]
    assert [a["scoreGiven"] for a in platform.applied] == [6.0] and running.ledger.outbox() == []


@pytest.mark.parametrize("strict", [True, False])
def test_an_answer_lost_after_the_platform_applied_the_score_leaves_it_once(running, platform, sender, strict):
    """The POST reached the platform, which kept the score, but the answer was lost (here a 500 after applying):
    the tool sends the identical score again, which the platform does not apply twice (not newer)."""
    found = _graded(running, platform)
    platform.mode, platform.lose, platform.strict = "lose", 1, strict
    sender.submit(found.ref, "ex1", 0.8, Rule.BEST)
    until(lambda: running.ledger.outbox() == [] and len(platform.posts) == 2, "the resend, accepted")
    assert platform.posts[0] == platform.posts[1]  # the very same score, timestamp included
    assert len(platform.applied) == 1 and platform.result("li-1", "student-sub")["scoreGiven"] == 8.0


def test_a_slow_platform_gets_the_score_once(running, platform):
    sender = _sender(running, timeout=0.3)
    try:
        found = _graded(running, platform)
        platform.mode = "slow"  # the token comes at once; the POST does not answer within the tool's 0.3 s
        sender.submit(found.ref, "ex1", 0.4, Rule.BEST)
        until(lambda: len(platform.posts) >= 2, "a retry after a timeout")
        platform.mode = "up"
        platform.released.set()  # the late answers come now: the first applies, the others are not newer
        until(lambda: running.ledger.outbox() == [], "the score delivered")
        until(lambda: platform.result("li-1", "student-sub"), "the result")
        assert len(platform.applied) == 1 and len({str(p) for p in platform.posts}) == 1
    finally:
        sender.stop()


def test_a_newer_score_replaces_the_waiting_one(running, platform):
    """Both queued before the sender runs (a score already being sent may still go: it is older, and the newer
    one follows it, so the gradebook ends with the newer)."""
    found = _graded(running, platform)
    sender = GradeSender(running.ledger, running.tool.config, running.tool.key, lambda: list(EXERCISES), backoff=FAST)
    sender.submit(found.ref, "ex1", 0.3, Rule.LATEST)
    sender.submit(found.ref, "ex1", 0.8, Rule.LATEST)
    assert len(running.ledger.outbox()) == 1
    sender.start()
    try:
        until(lambda: running.ledger.outbox() == [], "sent")
        assert [a["scoreGiven"] for a in platform.applied] == [8.0]
    finally:
        sender.stop()


def test_a_score_the_platform_refuses_is_kept_as_failed_with_its_reason(running, platform, sender):
    platform.links["gone"] = platform.links["graded"].__class__(custom={"exercise": "ex1"}, lineitem="li-deleted")
    found = _graded(running, platform, link="gone")
    heard = []
    sender.submit(found.ref, "ex1", 0.5, Rule.BEST, tell=heard.append)
    until(lambda: heard == [News.REFUSED], "the refusal")
    assert running.ledger.outbox() == [("failed", 0, "the platform refused the score (HTTP 404)")]


def test_an_expired_token_is_renewed(running, platform, sender):
    found = _graded(running, platform)
    sender.submit(found.ref, "ex1", 0.5, Rule.LATEST)
    until(lambda: platform.applied, "the first score")
    platform.tokens.clear()  # the platform forgets every token: the next POST is a 401
    sender.submit(found.ref, "ex1", 0.6, Rule.LATEST)
    until(lambda: len(platform.applied) == 2, "the second score, with a new token")
    assert len(platform.token_requests) == 2


def test_a_restart_sends_the_waiting_score_once(running, platform):
    found = _graded(running, platform)
    first = _sender(running)
    platform.mode = "down"
    first.submit(found.ref, "ex1", 0.9, Rule.BEST)
    until(lambda: running.ledger.outbox()[0][1] >= 1, "a failed try")
    first.stop()
    path = running.ledger.path
    platform.mode = "up"
    again = Ledger(path)  # the process that restarts: a new connection to the same store
    second = _sender(running, ledger=again)
    try:
        until(lambda: again.outbox() == [], "sent after the restart")
        assert [a["scoreGiven"] for a in platform.applied] == [9.0]
    finally:
        second.stop()
        again.close()


KILLED = """
import sys
from tpm_viz.classroom.launches import Rule
from tpm_viz.lti.config import read_config
from tpm_viz.lti.grades import GradeSender
from tpm_viz.lti.keys import ToolKey
from tpm_viz.lti.ledger import Ledger
config = read_config(sys.argv[1])
sender = GradeSender(Ledger(sys.argv[2]), config, ToolKey.read(config.private_key))
print(sender.submit(sys.argv[3], "ex1", 0.55, Rule.BEST).value, flush=True)  # queued, never sent: no thread
sys.stdin.read()  # wait to be killed
"""


def test_a_kill_9_after_submit_loses_nothing(running, platform, tmp_path):
    found = _graded(running, platform)
    env = {**os.environ, "PYTHONPATH": os.getcwd()}
    child = subprocess.Popen(
        [sys.executable, "-c", KILLED, str(tmp_path / "lti.toml"), str(running.ledger.path), found.ref],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    try:
        assert child.stdout.readline().strip() == "queued"
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait(10)
    sender = _sender(running)
    try:
        until(lambda: running.ledger.outbox() == [], "the score the killed process queued, sent")
        assert [a["scoreGiven"] for a in platform.applied] == [5.5]
    finally:
        sender.stop()


def test_the_outbox_is_bounded(running, monkeypatch):
    monkeypatch.setattr(ledger_module, "MAX_OUTBOX", 2)
    for n in range(2):
        assert running.ledger.queue(f"g{n}", 0.5, False, lambda f, t: {"fraction": f})
    with pytest.raises(InputError, match="2 grades are waiting"):
        running.ledger.queue("g3", 0.5, False, lambda f, t: {"fraction": f})
    assert running.ledger.queue("g0", 0.6, False, lambda f, t: {"fraction": f})  # a newer one of a waiting grade


def test_scores_url_inserts_before_the_query():
    assert scores_url("https://lms.example/li/7?type=x&a=1") == "https://lms.example/li/7/scores?type=x&a=1"
    assert scores_url("https://lms.example/li/7/") == "https://lms.example/li/7/scores"


def test_each_submission_hears_on_its_way_once_even_when_a_newer_one_joins(running, platform, sender):
    found = _graded(running, platform)
    first, second = [], []
    platform.mode = "down"
    sender.submit(found.ref, "ex1", 0.3, Rule.LATEST, tell=first.append)
    until(lambda: first == [News.ON_ITS_WAY], "the first told")
    sender.submit(found.ref, "ex1", 0.7, Rule.LATEST, tell=second.append)
    until(lambda: running.ledger.outbox()[0][1] >= 2, "two tries of the newer score")
    platform.mode = "up"
    until(lambda: second and second[-1] is News.SENT, "sent")
    assert first == [News.ON_ITS_WAY, News.SENT] and second == [News.ON_ITS_WAY, News.SENT]
    assert [a["scoreGiven"] for a in platform.applied] == [7.0]
