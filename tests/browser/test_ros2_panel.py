"""The viewer's ROS 2 panel (issue 29): with ``--ros2``, the page lists every topic
gantry has on the ROS 2 graph with its type, direction and rate, read from
``GET /api/ros2``. BubbleRob on ROS 2 runs in real time (dt 0.05 s), so ``/clock``
comes at 20 Hz; its script subscribes to ``/cmd_vel``.

Run with the others by ``bash tools/browser-test.sh``, or alone with
``bash tools/browser-test.sh -k ros2``.
"""

from __future__ import annotations

import json
import os
import random
import time
import urllib.request

import pytest

from viewer_util import REPO, Gantry, viewer_page

ROW_RATE = """(topic) => {
    const row = document.querySelector(`#ros2-table tr[data-topic="${topic}"]`);
    return row ? row.children[3].textContent : null;
}"""


@pytest.fixture(scope="module")
def gantry():
    # A domain of its own: other runs on this host do not show up in the list.
    os.environ["ROS_DOMAIN_ID"] = str(random.randrange(100, 230))
    g = Gantry(extra=[str(REPO / "assets/scenes/bubble_rob_ros2.toml"), "--ros2"])
    yield g
    g.close()


def ros2_topics(g) -> dict:
    with urllib.request.urlopen(g.url + "api/ros2", timeout=10) as r:
        return {t["topic"]: t for t in json.load(r)["topics"]}


def test_the_panel_lists_the_topics_with_their_rates(gantry):
    # The listeners answer before the simulation thread has opened its topics.
    deadline = time.monotonic() + 20
    while "/cmd_vel" not in (topics := ros2_topics(gantry)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert topics["/clock"]["type"] == "rosgraph_msgs/msg/Clock"
    assert topics["/clock"]["direction"] == "publish"
    assert topics["/cmd_vel"]["direction"] == "subscribe"
    ready = "() => { const r = document.querySelector('#ros2-table tr[data-topic=\"/clock\"]');" \
            " return r && !document.getElementById('ros2').hidden && r.children[3].textContent.includes('Hz'); }"
    with viewer_page(gantry.url, ready) as page:
        clock = page.evaluate(ROW_RATE, "/clock")
        rate = float(clock.split()[0])
        assert 10 <= rate <= 30, f"/clock at {clock}: the simulation runs 20 steps a second"
        assert page.evaluate(ROW_RATE, "/cmd_vel") is not None
        rows = page.locator("#ros2-table tr").all_inner_texts()
        assert any("/joint_states" in r and "sensor_msgs/msg/JointState" in r for r in rows), rows
        assert any("/cmd_vel" in r and "\tin\t" in r for r in rows), rows
