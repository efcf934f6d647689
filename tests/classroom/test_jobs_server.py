"""The fair worker in a served app, through the websocket protocol (``tests/support/protocol.py``): ten tabs flood
the control lab and the planner while another tab asks for a floor map; the map of its new parameters arrives, every
flooder ends on the plan of the last value it sent (latest wins, nothing lost), and a flooder that closes mid-flood
leaves nothing pending behind (the dropping itself: ``test_jobs.py``). Correctness only: how long the map waits
is measured by ``python benchmarks/bench_worker_flood.py``."""

from __future__ import annotations

import pytest

from tests.support.fixtures import app, open_tab  # noqa: F401 - the app fixture
from tests.support.protocol import wait_for
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.app.paths import path_for
from tpm_viz.app.planner import Limits, plan_cycle

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

FLOODERS = 10
PRESSES = 4  # per flooder: control lab presses and force-slider moves


@pytest.fixture
def tabs(app):  # noqa: F811 - the app fixture
    opened: list = []
    yield lambda: open_tab(app, opened)
    for client in opened:
        client.close()


def test_ten_flooding_tabs_do_not_stop_another_tabs_map(app, tabs):  # noqa: F811
    flooders = [tabs() for _ in range(FLOODERS)]
    client, view = tabs()
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: not view.session.shared, what="the own copy")
    explorer = view.teaching.explorer
    client.set_value(explorer.map_kind, MAP_KINDS["cond"])
    wait_for(lambda: explorer.kind == "cond", what="the map kind")

    last = {}
    for k in range(PRESSES):  # every flooder: the control lab and the planner, as fast as the socket takes them
        for i, (c, v) in enumerate(flooders):
            c.click(v.teaching.control.lesson)
            last[i] = 150.0 + 10.0 * k + i
            c.set_value(v.teaching.planner.force, last[i])
    client.enter(view.panel.params, {"l_a": "257.5"})  # new parameters: a map nobody has computed
    leaver_client, leaver = flooders.pop()
    leaver_client.click(leaver.teaching.control.lesson)
    leaver_client.close()
    wait_for(lambda: leaver.closed, what="the leaver's tab closed")

    def drawn() -> bool:
        params = view.session.state.params
        return params.l_a == pytest.approx(0.2575) and explorer._map_drawn == (params, "cond")

    wait_for(drawn, timeout=120, what="the other tab's map")
    owner = str(view.client.client_id)
    wait_for(lambda: ("/explorer/map", owner) in client.nodes, what="the map image at the tab")
    assert explorer.status.content == ""  # no "computing", no "unavailable"

    worker = view.teaching.services.worker
    wait_for(worker.idle, timeout=120, what="the flood worked off")
    assert worker.jobs.pending(leaver) == 0
    params = flooders[0][1].session.state.params
    for i, (_c, v) in enumerate(flooders):  # latest wins: the plan shown is the library's at the last value sent
        result = v.teaching.planner.result
        assert result is not None and result.plan.limits.force == last[i]
        expected = plan_cycle(params, path_for(params, "pick"), Limits(last[i]))  # the library, not the tab's cache
        assert result.plan.duration == pytest.approx(expected.duration, rel=1e-9)
        assert v.teaching.control.busy == ""  # each flooder's last simulation arrived
