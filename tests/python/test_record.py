"""Issue 31: `gantry run --record run.mcap` read back with independent readers from PyPI.

bubble_rob is driven step by step by the ZMQ client (`sim.step()` with stepping on);
after a few steps the client reads every object's world pose, every joint's position
and the simulation time, then gantry stops (SIGTERM: a clean stop, so the file gets
its summary). The recording is then read with

- `mcap` + `mcap-ros2-support`: an indexed summary, every message decodes, log times
  never go back, `/tf` holds every object's frame, and composing `/tf` from `world`
  down gives, at the step the client read, the poses `sim.getObjectPose` returned
  (and `/joint_states` the positions `sim.getJointPosition` returned);
- `rosbags` (`AnyReader`): the file opens as a ROS 2 bag and every message deserializes.
"""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import pytest

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

SCENE = "assets/scenes/bubble_rob.toml"
STEPS = 12


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def rotate(q, v):
    x, y, z, _ = quat_mul(quat_mul(q, (*v, 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


def compose(parent, child):
    """parent * child, poses as ((x, y, z), (qx, qy, qz, qw))."""
    (pt, pq), (ct, cq) = parent, child
    rt = rotate(pq, ct)
    return (tuple(p + r for p, r in zip(pt, rt)), quat_mul(pq, cq))


def world_poses(*tf_msgs):
    """Every frame's world pose, composing the messages' transforms (a `/tf_static` and
    a `/tf` message: later ones win) from `world` down."""
    local = {}
    for t in (t for m in tf_msgs for t in m.transforms):
        tr, rq = t.transform.translation, t.transform.rotation
        local[t.child_frame_id] = (t.header.frame_id, ((tr.x, tr.y, tr.z), (rq.x, rq.y, rq.z, rq.w)))
    out = {}

    def resolve(frame, depth=0):
        assert depth < 100, f"a cycle through {frame}"
        if frame == "world":
            return ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
        if frame not in out:
            parent, pose = local[frame]
            out[frame] = compose(resolve(parent, depth + 1), pose)
        return out[frame]

    for f in local:
        resolve(f)
    return out


def same_rotation(a, b, tol):
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return dot > 1.0 - tol


@pytest.mark.zmq_only
def test_recording_reads_back_and_matches_the_poses_the_client_read(gantry, tmp_path):
    path = tmp_path / "run.mcap"
    g = gantry(SCENE, extra=["--record", str(path), "--http-port", "0"])
    client = g.client()
    sim = client.require("sim")
    client.setStepping(True)
    for _ in range(STEPS):
        client.step()
    t_read = sim.getSimulationTime()
    handles = sim.getObjectsInTree(sim.handle_scene)
    expected = {}
    joints = {}
    for h in handles:
        frame = sim.getObjectAlias(h, 2).lstrip("/")
        expected[frame] = sim.getObjectPose(h, sim.handle_world)
        if sim.getObjectType(h) == sim.object_joint_type:
            joints[frame] = sim.getJointPosition(h)
    # A few more steps, so the step read is not the file's last.
    for _ in range(3):
        client.step()
    g.close()
    assert g.proc.returncode == 0, g.stderr()
    assert path.stat().st_size > 0

    stamp_ns = round(t_read * 1e9)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes, "indexed, chunked"
        assert all(c.compression == "zstd" for c in summary.chunk_indexes)
        topics = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
        assert topics["/tf"] == "tf2_msgs/msg/TFMessage"
        assert topics["/joint_states"] == "sensor_msgs/msg/JointState"
        assert topics["/rosout"] == "rcl_interfaces/msg/Log"
        assert any(t.startswith("/graph/") for t in topics), topics
        assert any(t.startswith("/proximity/") for t in topics), topics
        assert all(s.encoding == "ros2msg" for s in summary.schemas.values())
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        assert metadata["gantry"]["dt"] == "0.05"
        assert "--record" in metadata["gantry"]["command_line"]
        attachments = {a.name: a.data for a in reader.iter_attachments()}
        scene_path = metadata["gantry"]["scene_path"]
        assert attachments[scene_path] == (Path(__file__).resolve().parents[2] / SCENE).read_bytes()
        assert any(name.endswith("bubble_rob.lua") for name in attachments), list(attachments)

        static = None

        count = 0
        last = -1
        at_read = {}
        stamps = []
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
            count += 1
            assert message.log_time >= last, "log times never go back"
            last = message.log_time
            if channel.topic == "/tf_static":
                static = decoded
            elif channel.topic == "/tf":
                assert static is not None, "/tf_static comes first, with the frames that have not moved"
                ts = {t.header.stamp.sec * 10**9 + t.header.stamp.nanosec for t in decoded.transforms}
                assert len(ts) <= 1
                stamps.append(message.log_time)
                if message.log_time == stamp_ns:
                    at_read["tf"] = (static, decoded)
            elif channel.topic == "/joint_states":
                s = decoded.header.stamp
                if s.sec * 10**9 + s.nanosec == stamp_ns:
                    at_read["joints"] = decoded
                for v in list(decoded.position) + list(decoded.velocity) + list(decoded.effort):
                    assert math.isfinite(v)
        assert count == summary.statistics.message_count
        assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)

    assert "tf" in at_read, f"no /tf at {t_read} s among {stamps[:3]}...{stamps[-3:]}"
    recorded = world_poses(*at_read["tf"])
    assert set(expected) <= set(recorded), set(expected) - set(recorded)
    for frame, pose in expected.items():
        (x, y, z), q = recorded[frame]
        assert math.dist((x, y, z), pose[:3]) < 1e-9, (frame, (x, y, z), pose[:3])
        assert same_rotation(q, pose[3:], 1e-9), (frame, q, pose[3:])
    js = at_read["joints"]
    by_name = dict(zip(js.name, js.position))
    assert joints and set(joints) <= set(by_name)
    for name, q in joints.items():
        assert abs(by_name[name] - q) < 1e-12, (name, by_name[name], q)
    # bubbleRob drives: its pose at the step read is not where it started.
    first = world_poses(*first_tree(path))
    assert math.dist(first["bubbleRob"][0], recorded["bubbleRob"][0]) > 1e-4
    # What never moved is on /tf_static only; what moves is on /tf.
    moving = {t.child_frame_id for t in at_read["tf"][1].transforms}
    fixed = {t.child_frame_id for t in at_read["tf"][0].transforms}
    assert "bubbleRob" in moving and not moving & fixed, (moving, fixed)


def first_tree(path):
    """The first `/tf_static` and `/tf` messages: the tree at the start."""
    first = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, _, decoded in reader.iter_decoded_messages(topics=["/tf_static", "/tf"]):
            first.setdefault(channel.topic, decoded)
            if len(first) == 2:
                return first["/tf_static"], first["/tf"]
    raise AssertionError("no /tf_static or /tf")


@pytest.mark.zmq_only
def test_recording_opens_as_a_ros2_bag_with_rosbags(gantry, tmp_path):
    from rosbags.highlevel import AnyReader

    path = tmp_path / "run.mcap"
    g = gantry(SCENE, extra=["--record", str(path), "--steps", "40", "--http-port", "0"])
    g.proc.wait(60)
    assert g.proc.returncode == 0, g.stderr()
    with AnyReader([path]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types["/tf"] == "tf2_msgs/msg/TFMessage"
        assert types["/joint_states"] == "sensor_msgs/msg/JointState"
        n = 0
        tf = 0
        for connection, timestamp, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            n += 1
            if connection.topic == "/tf":
                tf += 1
                frames = {t.child_frame_id for t in msg.transforms}
                if tf > 1:
                    # The rover drives from the first step on; its wheels turn.
                    assert {"bubbleRob", "bubbleRob/leftMotor/leftWheel"} <= frames, frames
        assert n == reader.message_count
        assert tf == 41, "the state at the start and after each of the 40 steps"


@pytest.mark.zmq_only
def test_images_and_signals_are_recorded_as_the_client_read_them(gantry, tmp_path):
    """`--record-image SENSOR=HZ` records the sensor's RGB image as sensor_msgs/Image
    (rgb8, top row first, as ROS has it); signals go to /signal/<type>/<name>."""
    path = tmp_path / "images.mcap"
    # 20 Hz at dt 0.05: an image after every step.
    g = gantry("assets/scenes/showroom.toml",
               extra=["--record", str(path), "--record-image", "visionSensor=20", "--http-port", "0"])
    client = g.client()
    sim = client.require("sim")
    client.setStepping(True)
    sim.setInt32Signal("gear", 3)
    sim.setFloatSignal("speed", 0.25)
    sim.setStringSignal("mode", "explore")
    for _ in range(6):
        client.step()
    sensor = next(h for h in sim.getObjectsInTree(sim.handle_scene) if sim.getObjectAlias(h) == "visionSensor")
    img, (width, height) = sim.getVisionSensorImg(sensor)
    t_read = round(sim.getSimulationTime() * 1e9)
    client.step()
    g.close()
    assert g.proc.returncode == 0, g.stderr()

    images = {}
    signals = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, msg in reader.iter_decoded_messages():
            if channel.topic.startswith("/vision/"):
                assert schema.name == "sensor_msgs/msg/Image"
                images[msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec] = msg
            elif channel.topic.startswith("/signal/"):
                signals[channel.topic] = msg.data
    assert signals == {"/signal/int32/gear": 3, "/signal/float/speed": 0.25, "/signal/string/mode": "explore"}
    msg = images[t_read]
    assert (msg.width, msg.height, msg.encoding, msg.step) == (width, height, "rgb8", 3 * width)
    row = 3 * width
    top_first = b"".join(bytes(img[r * row:(r + 1) * row]) for r in reversed(range(height)))
    assert bytes(msg.data) == top_first, "the image the client read at that step, rows top first"


@pytest.mark.zmq_only
def test_a_killed_run_leaves_a_file_readable_up_to_the_last_second(tmp_path):
    """SIGKILL (no summary, no footer): the chunks written before the kill read with the
    `mcap` stream reader; the recorder closes a chunk at least every second."""
    import signal
    import time

    from mcap.exceptions import McapError
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader

    from gantry_proc import gantry_bin

    path = tmp_path / "killed.mcap"
    proc = subprocess.Popen([str(gantry_bin()), "run", SCENE, "--record", str(path), "--no-listen"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(4.0)  # real time: about 80 steps of 50 ms
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    topics = {}
    tf = 0
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f).records:
                if isinstance(record, Channel):
                    topics[record.id] = record.topic
                elif isinstance(record, Message) and topics.get(record.channel_id) == "/tf":
                    tf += 1
        except (McapError, EOFError, ValueError):
            pass  # the cut-off end: what was read before it stays
    # At least two of the four seconds are on disk (the last second may be lost).
    assert tf >= 40, f"{tf} /tf messages readable after the kill"
