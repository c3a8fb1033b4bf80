"""``gantry replay`` (issue 31) in headless chromium: a real recording of the showroom
(``gantry run --record ... --fast --no-listen``), replayed by a real ``gantry replay``;
the page is scrubbed through its slider as a user would, and what it then shows (the
3-D view's poses, the graph cursor) is checked against the file as the independent
``mcap`` + ``mcap-ros2-support`` readers decode it.

Run with ``bash tools/browser-test.sh`` (it runs every test in tests/browser). The
tests share one recording, one ``gantry replay`` and one page, in file order.
"""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap.writer import Writer
from mcap_ros2.decoder import DecoderFactory

from viewer_util import Gantry, Replay, gantry_bin, viewer_page, wait_for

# 10 simulated seconds of the showroom (dt 50 ms): bubbleRob drives, its script plots
# its clearance in the graph `bubbleRob/graph`.
STEPS = 200
# Between two snapshots (6.35 s and 6.40 s): the replay shows the one at or before it.
SCRUB_TO = 6.37
MOVING = "bubbleRob"
CHILD = "bubbleRob/leftMotor/leftWheel"
GRAPH = "bubbleRob/graph"
GRAPH_TOPIC = "/graph/bubbleRob_graph/bubbleRob_clearance"
# bubbleRob's camera, recorded at 10 Hz (`--record-image`).
CAMERA = "bubbleRob/sensingNose/visionSensor"


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("replay") / "showroom.mcap"
    subprocess.run([str(gantry_bin()), "run", "--record", str(path), "--record-image", "/" + CAMERA, "--steps",
                    str(STEPS), "--fast", "--no-listen"], check=True, timeout=300, stdout=subprocess.DEVNULL,
                   stderr=subprocess.PIPE)
    return path


class Recorded:
    """The recording as the ``mcap`` readers decode it: /tf, /tf_static and graph samples."""

    def __init__(self, path: Path):
        self.tf: list[tuple[int, dict]] = []
        self.tf_static: list[tuple[int, dict]] = []
        self.graphs: dict[str, list[tuple[int, float]]] = {}
        self.images: list[tuple[int, object]] = []
        self.metadata: dict[str, str] = {}
        with open(path, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for m in reader.iter_metadata():
                if m.name == "gantry":
                    self.metadata = dict(m.metadata)
            for _schema, channel, message, msg in reader.iter_decoded_messages():
                if channel.topic in ("/tf", "/tf_static"):
                    frames = {}
                    for t in msg.transforms:
                        tr, q = t.transform.translation, t.transform.rotation
                        frames[t.child_frame_id] = (t.header.frame_id, [tr.x, tr.y, tr.z, q.x, q.y, q.z, q.w])
                    (self.tf if channel.topic == "/tf" else self.tf_static).append((message.log_time, frames))
                elif channel.topic.startswith("/graph/"):
                    self.graphs.setdefault(channel.topic, []).append((message.log_time, msg.data))
                elif channel.topic.startswith("/vision/"):
                    self.images.append((message.log_time, msg))

    @staticmethod
    def _latest(entries, t_ns):
        found = None
        for t, value in entries:
            if t <= t_ns:
                found = value
        return found

    def tree_at(self, t_ns: int) -> dict:
        """The latest /tf_static at or before t, overlaid with the latest /tf."""
        tree = dict(self._latest(self.tf_static, t_ns) or {})
        tree.update(self._latest(self.tf, t_ns) or {})
        return tree

    def world_pose(self, frame: str, t_ns: int) -> list[float]:
        """``frame``'s pose in ``world``, composing the tree from the root down."""
        tree = self.tree_at(t_ns)
        chain = []
        while frame != "world":
            parent, pose = tree[frame]
            chain.append(pose)
            frame = parent
        world = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
        for pose in reversed(chain):
            world = compose(world, pose)
        return world

    def graph_value(self, topic: str, t_ns: int) -> float:
        return self._latest(self.graphs[topic], t_ns)


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz]


def rotate(q, v):
    x, y, z, _ = quat_mul(quat_mul(q, [*v, 0.0]), [-q[0], -q[1], -q[2], q[3]])
    return [x, y, z]


def compose(parent, child):
    """``parent * child`` for poses ``[x, y, z, qx, qy, qz, qw]``."""
    t = rotate(parent[3:], child[:3])
    return [parent[0] + t[0], parent[1] + t[1], parent[2] + t[2], *quat_mul(parent[3:], child[3:])]


def assert_pose_close(got, want, what, tol=1e-4):
    """Positions within ``tol`` m, quaternions within ``tol`` up to sign (the page has f32)."""
    assert all(abs(g - w) <= tol for g, w in zip(got[:3], want[:3])), f"{what}: {got} vs {want}"
    sign = 1.0 if sum(g * w for g, w in zip(got[3:], want[3:])) >= 0 else -1.0
    assert all(abs(g - sign * w) <= tol for g, w in zip(got[3:], want[3:])), f"{what}: {got} vs {want}"


@pytest.fixture(scope="module")
def recorded(recording) -> Recorded:
    return Recorded(recording)


@pytest.fixture(scope="module")
def replay(recording):
    r = Replay(recording)
    yield r
    r.close()
    print(f"--- gantry replay stderr ---\n{r.stderr()}")


@pytest.fixture(scope="module")
def page(replay):
    ready = ("window.gantry && gantry.objects.length > 0 && gantry.replay !== null "
             "&& gantry.frameMessages > 0 && gantry.tick !== null")
    with viewer_page(replay.url, ready) as pg:
        yield pg


def page_pose(page, frame: str) -> list[float]:
    return page.evaluate("(path) => gantry.objects.find(o => o.path === path).pose", "/" + frame)


def test_the_page_is_in_replay_mode_at_the_start(page, recorded):
    state = page.evaluate("""() => ({
        replayShown: !document.getElementById('replay').hidden,
        controlsShown: !document.getElementById('controls').hidden,
        start: gantry.replay.start, end: gantry.replay.end, frames: gantry.replay.frames,
    })""")
    assert state["replayShown"] and not state["controlsShown"]
    assert state["frames"] == len(recorded.tf) == STEPS + 1
    assert math.isclose(state["end"], recorded.tf[-1][0] * 1e-9, abs_tol=1e-9)
    assert math.isclose(state["start"], 0.0, abs_tol=1e-9)


def test_scrubbing_shows_that_times_poses_and_graph_cursor(page, recorded):
    t_ns = round(SCRUB_TO * 1e9)
    # The object must have moved, or the check below proves nothing.
    assert recorded.world_pose(MOVING, t_ns)[:3] != recorded.world_pose(MOVING, 0)[:3]
    page.locator("#replay-slider").fill(str(SCRUB_TO))
    page.wait_for_function("(t) => Math.abs(gantry.replay.time - t) < 1e-9 && Math.abs(gantry.tick.time - t) < 1e-6 "
                           "&& !gantry.replay.playing", arg=SCRUB_TO, timeout=20_000)
    for frame in (MOVING, CHILD):
        assert_pose_close(page_pose(page, frame), recorded.world_pose(frame, t_ns), frame)
    # The graph's cursor: at the scrubbed time, showing the stream's latest sample at or
    # before it, at that time's place on the plot's axis.
    handle = page.evaluate("(p) => gantry.objects.find(o => o.path === p).handle", "/" + GRAPH)
    cursor = wait_for(lambda: page.evaluate("(h) => gantry.graphCursor[h] || null", handle), what="graph cursor")
    wait_for(lambda: abs(page.evaluate("(h) => gantry.graphCursor[h].time", handle) - SCRUB_TO) < 1e-9,
             what="the cursor at the scrubbed time")
    cursor = page.evaluate("(h) => gantry.graphCursor[h]", handle)
    samples = recorded.graphs[GRAPH_TOPIC]
    t0, t1 = samples[0][0] * 1e-9, samples[-1][0] * 1e-9
    assert math.isclose(cursor["t0"], t0, abs_tol=1e-9) and math.isclose(cursor["t1"], t1, abs_tol=1e-9)
    assert math.isclose(cursor["x"], cursor["left"] + (SCRUB_TO - t0) / (t1 - t0) * cursor["width"], abs_tol=1e-6)
    label = GRAPH_TOPIC.rsplit("/", 1)[1]
    assert cursor["values"][label] == recorded.graph_value(GRAPH_TOPIC, t_ns)
    # The server shows the same time.
    assert math.isclose(page.evaluate("gantry.replay.time"), SCRUB_TO, abs_tol=1e-9)
    # The camera's panel shows the recorded image at or before that time (top row first
    # in the file and on the canvas).
    image = Recorded._latest(recorded.images, t_ns)
    assert image is not None and image.encoding == "rgb8"
    w, h, step = image.width, image.height, image.step
    expected = [list(image.data[y * step + 3 * x: y * step + 3 * x + 3]) for x, y in ((0, 0), (w // 2, h // 2),
                                                                                    (w - 1, h - 1))]
    assert len({tuple(p) for p in expected}) > 1 or any(expected[0]), "a blank image proves nothing"
    cam = page.evaluate("(p) => gantry.objects.find(o => o.path === p).handle", "/" + CAMERA)
    js = """([h, pts]) => {
        const cv = document.querySelector(`figure.vision[data-sensor="${h}"] canvas`);
        const ctx = cv.getContext('2d');
        return pts.map(([x, y]) => Array.from(ctx.getImageData(x, y, 1, 1).data.slice(0, 3)));
    }"""
    points = [[0, 0], [w // 2, h // 2], [w - 1, h - 1]]
    wait_for(lambda: page.evaluate(js, [cam, points]) == expected, what="the recorded image on the page")


def test_stepping_moves_one_snapshot(page, recorded):
    before = page.evaluate("gantry.replay.frame")
    page.click("#replay-forward")
    page.wait_for_function("(f) => gantry.replay.frame === f", arg=before + 1, timeout=20_000)
    t_ns = recorded.tf[before + 1][0]
    page.wait_for_function("(t) => Math.abs(gantry.tick.time - t) < 1e-6", arg=t_ns * 1e-9, timeout=20_000)
    assert_pose_close(page_pose(page, MOVING), recorded.world_pose(MOVING, t_ns), MOVING)
    page.click("#replay-back")
    page.wait_for_function("(f) => gantry.replay.frame === f", arg=before, timeout=20_000)


def test_playing_advances_the_time_and_pause_stops_it(page, replay):
    start = page.evaluate("gantry.replay.time")
    page.click("#replay-play")
    page.wait_for_function("(t) => gantry.replay.playing && gantry.replay.time > t + 0.3", arg=start, timeout=20_000)
    page.click("#replay-play")
    page.wait_for_function("() => !gantry.replay.playing", timeout=20_000)
    stopped = page.evaluate("gantry.replay.time")
    assert stopped > start
    assert replay.status()["time"] == pytest.approx(stopped, abs=1e-9)


def ws_reply(page, command: dict) -> dict:
    """The reply to ``command`` sent on a WebSocket of its own from ``page``."""
    return page.evaluate("""(cmd) => new Promise((ok) => {
        const ws = new WebSocket(`ws://${location.host}/ws`);
        ws.onmessage = (ev) => {
            if (typeof ev.data !== 'string') return;
            const m = JSON.parse(ev.data);
            if (m.t === 'scene') ws.send(JSON.stringify({id: 1, ...cmd}));
            if (m.t === 'reply' && m.id === 1) { ok(m); ws.close(); }
        };
    })""", command)


def test_simulation_commands_are_refused_in_a_replay(page):
    for command in ({"op": "control", "action": "start"}, {"op": "packet", "text": "<JOINTS#>"},
                    {"op": "ui", "ui": 1, "widget": 1, "value": 1}):
        reply = ws_reply(page, command)
        assert reply["ok"] is False and "replay of a recording" in reply["text"], (command, reply)


def test_a_live_run_refuses_replay_commands(page):
    live = Gantry(fast=True)
    try:
        # A second tab of the same browser, on a live run's viewer.
        pg = page.context.browser.new_page()
        pg.goto(live.url)
        reply = ws_reply(pg, {"op": "replay", "action": "seek", "time": 1.0})
        pg.close()
    finally:
        live.close()
    assert reply["ok"] is False and "no recording is being replayed" in reply["text"], reply


def replay_fails(path: Path) -> str:
    r = subprocess.run([str(gantry_bin()), "replay", str(path), "--http-port", "0"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode != 0, r.stderr
    assert "panicked" not in r.stderr, r.stderr
    return r.stderr


def test_bad_files_make_replay_exit_with_the_readers_error(tmp_path, recording, recorded):
    foreign = tmp_path / "run.json"
    foreign.write_text('{"tf": []}')
    assert "is not an MCAP file" in replay_fails(foreign)

    cut = tmp_path / "cut.mcap"
    cut.write_bytes(recording.read_bytes()[:2000])
    assert "cannot be replayed" in replay_fails(cut)

    newer = tmp_path / "newer.mcap"
    with open(newer, "wb") as f:
        w = Writer(f)
        w.start(profile="ros2", library="test")
        w.add_metadata("gantry", {**recorded.metadata, "format_version": "99"})
        w.finish()
    text = replay_fails(newer)
    assert "newer gantry" in text and "version 99" in text and "up to 1" in text, text

    assert "cannot read" in replay_fails(tmp_path / "missing.mcap")
