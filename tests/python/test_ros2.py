"""Issue 29: gantry on a ROS 2 graph, checked by an independent DDS implementation.

The peer is Eclipse Cyclone DDS from PyPI (``ros2_peer.py``), speaking ROS 2's topic and
type name mangling with ROS's default QoS; nothing of ROS is installed. Each test runs
a real gantry process in its own ROS domain (``ROS_DOMAIN_ID``), holds it with the ZMQ
client's stepping, and compares what arrives on the graph with what the ``sim`` API
says at the same step:

- ``--ros2``: ``/clock``, ``/tf``, ``/tf_static``, ``/joint_states`` and a vision
  sensor's ``image_raw`` and ``camera_info``;
- a ``simROS2.createSubscription`` script (``bubble_rob_ros2.lua``) turns ``/cmd_vel``
  Twists from the peer into BubbleRob's wheel speeds, and the rover moves as commanded;
- the same script serves ``std_srvs/SetBool``, called by the peer with rmw_cyclonedds'
  request header;
- ``--ros2``: ros2_control-style position commands (``Float64MultiArray``) set the
  arm's joint targets, and a command of the wrong length is dropped;
- ``gantry.Client(scene, ros2=True)`` (in process) publishes the same graph;
- a script's ``simROS2`` client calls a service the peer serves (``waitForService``,
  then ``call``);
- a script's ``simROS2`` action server serves the peer's goals (feedback, result,
  rejection, cancel, the status list) and a script's action client gets a goal done by
  the peer's action server, both on rcl_action's topics and types;
- ROS 1's ``simROS`` names publish on the ROS 2 graph;
- malformed samples are dropped with a clear log line and the simulation goes on.

Without gantry's transport nothing arrives and every test times out.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest

from gantry_proc import REPO, GantryProcess
from ros2_peer import (
    LATCHED,
    UUID,
    CancelGoalRequest,
    FibonacciEndpoints,
    FibonacciFeedback,
    FibonacciFeedbackMessage,
    FibonacciGetResultRequest,
    FibonacciGetResultResponse,
    FibonacciGoal,
    FibonacciResult,
    FibonacciSendGoalRequest,
    FibonacciSendGoalResponse,
    GoalInfo,
    Time,
    AddTwoIntsRequest,
    AddTwoIntsResponse,
    Bool,
    CameraInfo,
    Clock,
    Float32,
    Float64MultiArray,
    Image,
    MultiArrayLayout,
    JointState,
    Peer,
    SetBoolRequest,
    SetBoolResponse,
    TFMessage,
    TruncatedTwist,
    Twist,
    Vector3,
    take_until,
)

SCENE = "assets/scenes/bubble_rob_ros2.toml"


def stamp_s(t) -> float:
    return t.sec + t.nanosec * 1e-9


def held(procs, scene=SCENE, extra=None):
    """A gantry process held by a stepping ZMQ client: (process, client, sim)."""
    g = GantryProcess(scene, fast=True, extra=extra)
    procs.append(g)
    client = g.client()
    client.setStepping(True)
    sim = client.require("sim")
    if sim.getSimulationState() == sim.simulation_stopped:
        sim.startSimulation()
    return g, client, sim


def wait_matched(writer, timeout=20.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if writer.get_matched_subscriptions():
            return
        time.sleep(0.02)
    raise AssertionError("gantry's subscription never matched the peer's writer")


def test_graph_topics_match_the_sim_api(domain, procs):
    peer = Peer(domain)
    clock = peer.reader("rt/clock", Clock)
    tf = peer.reader("rt/tf", TFMessage)
    tf_static = peer.reader("rt/tf_static", TFMessage, LATCHED)
    joints = peer.reader("rt/joint_states", JointState)
    image = peer.reader("rt/bubbleRob/sensingNose/visionSensor/image_raw", Image)
    info = peer.reader("rt/bubbleRob/sensingNose/visionSensor/camera_info", CameraInfo)
    g, client, sim = held(procs, extra=["--ros2"])
    # Discovery takes a moment: step until the clock is seen, then a few more.
    take_until(clock, lambda s: s or client.step() and False, what="/clock")
    for _ in range(5):
        client.step()
    t = sim.getSimulationTime()
    robot = sim.getObject("/bubbleRob")
    left, right = sim.getObject("/bubbleRob/leftMotor"), sim.getObject("/bubbleRob/rightMotor")
    sensor = sim.getObject("/bubbleRob/visionSensor")
    position = sim.getObjectPosition(robot, -1)
    quaternion = sim.getObjectQuaternion(robot, -1)
    joint_positions = [sim.getJointPosition(left), sim.getJointPosition(right)]
    rgb, (w, h) = sim.getVisionSensorImg(sensor)

    def at_t(samples, stamp):
        return [s for s in samples if abs(stamp(s) - t) < 1e-6]

    clocks = take_until(clock, lambda s: at_t(s, lambda c: stamp_s(c.clock)), what="/clock at t")
    stamps = [stamp_s(c.clock) for c in clocks]
    assert stamps == sorted(stamps), "simulation time never goes back"

    js = at_t(take_until(joints, lambda s: at_t(s, lambda m: stamp_s(m.header.stamp)), what="/joint_states"),
              lambda m: stamp_s(m.header.stamp))[0]
    assert list(js.name) == ["bubbleRob/leftMotor", "bubbleRob/rightMotor"]
    assert list(js.position) == pytest.approx(joint_positions, abs=1e-12)

    def robot_tf(samples):
        for m in samples:
            for x in m.transforms:
                if x.child_frame_id == "bubbleRob" and abs(stamp_s(x.header.stamp) - t) < 1e-6:
                    return x
        return None

    x = robot_tf(take_until(tf, robot_tf, what="/tf of bubbleRob"))
    assert x.header.frame_id == "world"
    tr, rot = x.transform.translation, x.transform.rotation
    assert [tr.x, tr.y, tr.z] == pytest.approx(position, abs=1e-9)
    # q and -q are one rotation.
    q = [rot.x, rot.y, rot.z, rot.w]
    sign = 1.0 if sum(a * b for a, b in zip(q, quaternion)) >= 0 else -1.0
    assert [sign * v for v in q] == pytest.approx(quaternion, abs=1e-9)

    statics = take_until(tf_static, lambda s: s, what="/tf_static")[-1]
    static_children = {s.child_frame_id: s.header.frame_id for s in statics.transforms}
    # The wheels turn, the sensors do not move on the body.
    assert static_children.get("bubbleRob/sensingNose") == "bubbleRob"
    assert static_children.get("bubbleRob/sensingNose/visionSensor") == "bubbleRob/sensingNose"
    assert "bubbleRob/leftMotor/leftWheel" not in static_children

    img = at_t(take_until(image, lambda s: at_t(s, lambda m: stamp_s(m.header.stamp)), what="an image"),
               lambda m: stamp_s(m.header.stamp))[0]
    assert (img.width, img.height, img.encoding, img.step) == (w, h, "rgb8", 3 * w)
    assert img.header.frame_id == "bubbleRob/sensingNose/visionSensor"
    rows = [rgb[r * 3 * w:(r + 1) * 3 * w] for r in range(h)]
    assert bytes(img.data) == b"".join(reversed(rows)), "ROS images are top row first"

    ci = take_until(info, lambda s: s, what="camera_info")[-1]
    assert (ci.width, ci.height) == (w, h)
    fov = sim.getObjectFloatParam(sensor, sim.visionfloatparam_perspective_angle)
    f = (max(w, h) / 2) / math.tan(fov / 2)
    assert list(ci.k) == pytest.approx([f, 0, (w - 1) / 2, 0, f, (h - 1) / 2, 0, 0, 1])


def drive(client, sim, writer, msg, until, steps=400):
    """Publishes ``msg`` and steps until ``until()`` holds."""
    wait_matched(writer)
    for _ in range(steps):
        writer.write(msg)
        client.step()
        if until():
            return
    raise AssertionError("the script never saw the command")


def test_cmd_vel_drives_bubble_rob(domain, procs):
    peer = Peer(domain)
    cmd = peer.writer("rt/cmd_vel", Twist)
    g, client, sim = held(procs)
    left, right = sim.getObject("/bubbleRob/leftMotor"), sim.getObject("/bubbleRob/rightMotor")
    robot = sim.getObject("/bubbleRob")

    forward = Twist(linear=Vector3(0.1, 0, 0), angular=Vector3(0, 0, 0))
    drive(client, sim, cmd, forward, lambda: sim.getInt32Signal("bubbleRobCommands") > 0)
    client.step()
    # Differential drive: wheel radius 0.04 m, wheels 0.2 m apart.
    assert sim.getJointTargetVelocity(left) == pytest.approx(0.1 / 0.04)
    assert sim.getJointTargetVelocity(right) == pytest.approx(0.1 / 0.04)

    start = sim.getObjectPosition(robot, -1)
    heading = sim.getObjectMatrix(robot, -1)
    ahead = (heading[0], heading[4])
    for _ in range(40):  # 2 s
        client.step()
    end = sim.getObjectPosition(robot, -1)
    moved = ((end[0] - start[0]) * ahead[0] + (end[1] - start[1]) * ahead[1])
    assert 0.1 < moved < 0.3, f"at 0.1 m/s for 2 s the rover moved {moved:.3f} m forward"

    turn = Twist(linear=Vector3(0.1, 0, 0), angular=Vector3(0, 0, 0.5))
    n = sim.getInt32Signal("bubbleRobCommands")
    drive(client, sim, cmd, turn, lambda: sim.getInt32Signal("bubbleRobCommands") > n + 2)
    client.step()
    assert sim.getJointTargetVelocity(left) == pytest.approx((0.1 - 0.05) / 0.04)
    assert sim.getJointTargetVelocity(right) == pytest.approx((0.1 + 0.05) / 0.04)


def test_set_bool_service_served_by_a_script(domain, procs):
    peer = Peer(domain)
    requests = peer.writer("rq/bubbleRob/set_enabledRequest", SetBoolRequest)
    replies = peer.reader("rr/bubbleRob/set_enabledReply", SetBoolResponse)
    g, client, sim = held(procs)
    client.step()
    assert sim.getInt32Signal("bubbleRobEnabled") == 1
    wait_matched(requests)
    requests.write(SetBoolRequest(client_guid=0x1234ABCD, sequence_number=7, data=False))
    got: list = []
    for _ in range(400):
        client.step()
        got.extend(replies.take(N=10))
        if got:
            break
    assert got, "no reply from the script's service"
    r = got[0]
    assert (r.client_guid, r.sequence_number) == (0x1234ABCD, 7), "the reply names the request"
    assert r.success and r.message == "wheels stopped"
    assert sim.getInt32Signal("bubbleRobEnabled") == 0


def test_ros1_simros_publishes_on_the_ros2_graph(domain, procs, tmp_path):
    script = tmp_path / "ros1.lua"
    script.write_text(
        "function sysCall_init()\n"
        "    pub = simROS.advertise('/ros1/flag', 'std_msgs/Bool')\n"
        "    tpub = simROS.advertise('/ros1/time', 'std_msgs/Float32')\n"
        "end\n"
        "function sysCall_sensing()\n"
        "    simROS.publish(pub, {data = true})\n"
        "    simROS.publish(tpub, {data = simROS.getTime()})\n"
        "end\n"
    )
    scene = tmp_path / "ros1.toml"
    scene.write_text(f'[[object]]\nname = "node"\nkind = "dummy"\nscript = "{script.name}"\n')
    peer = Peer(domain)
    flags = peer.reader("rt/ros1/flag", Bool)
    times = peer.reader("rt/ros1/time", Float32)
    g, client, sim = held(procs, scene=scene)
    take_until(flags, lambda s: s or client.step() and False, what="a ROS 1 style message")
    got = take_until(times, lambda s: s or client.step() and False, what="simROS.getTime")
    assert got[-1].data >= 0
    assert "ROS 1 is end-of-life" in g.stderr()


def test_malformed_samples_are_dropped_and_the_run_goes_on(domain, procs):
    peer = Peer(domain)
    bad = peer.writer("rt/cmd_vel", TruncatedTwist)
    good = peer.writer("rt/cmd_vel", Twist)
    g, client, sim = held(procs)
    wait_matched(bad)
    for _ in range(20):
        bad.write(TruncatedTwist(linear_x=1.0))
        client.step()
    assert sim.getInt32Signal("bubbleRobCommands") == 0
    drive(client, sim, good, Twist(linear=Vector3(0.05, 0, 0), angular=Vector3(0, 0, 0)),
          lambda: sim.getInt32Signal("bubbleRobCommands") > 0)
    assert "dropped a malformed geometry_msgs/msg/Twist message" in g.stderr()
    assert sim.getSimulationState() != sim.simulation_stopped


def test_forward_position_commands_set_the_arm_joint_targets(domain, procs):
    peer = Peer(domain)
    commands = peer.writer("rt/arm6/forward_position_controller/commands", Float64MultiArray)
    joints = peer.reader("rt/joint_states", JointState)
    # BubbleRob first, then the arm's scene loaded in its place: the graph's topics
    # follow the new tree (a handle of the old scene may name another object now).
    g, client, sim = held(procs, extra=["--ros2"])
    take_until(joints, lambda s: s or client.step() and False, what="/joint_states")
    sim.stopSimulation()
    sim.loadScene(str(REPO / "assets/scenes/fk_arm.toml"))
    sim.startSimulation()

    def arm_seen(samples) -> bool:
        client.step()
        return bool(samples) and "joint1" in samples[-1].name

    # The arm is a URDF robot: /joint_states names its joints as the URDF does.
    names = take_until(joints, arm_seen, what="/joint_states of the arm")[-1].name
    arm = [n for n in names if n.startswith("joint")]
    assert len(arm) == 6, names
    handles = [sim.getObject("/arm6/" + n) for n in arm]
    target = [0.1, -0.2, 0.3, -0.4, 0.5, -0.6]
    layout = MultiArrayLayout(dim=[], data_offset=0)
    wait_matched(commands)
    # One value short: dropped, with a warning, and the targets do not move. Stepped
    # until the warning shows that the message arrived (under load, delivery can take
    # longer than a few steps, and the targets would not have moved anyway).
    before = [sim.getJointTargetPosition(h) for h in handles]
    commands.write(Float64MultiArray(layout=layout, data=target[:5]))
    for _ in range(400):
        client.step()
        if "5 values for 6 joints" in g.stderr():
            break
    assert "5 values for 6 joints" in g.stderr()
    assert [sim.getJointTargetPosition(h) for h in handles] == before
    for _ in range(200):
        commands.write(Float64MultiArray(layout=layout, data=target))
        client.step()
        if [sim.getJointTargetPosition(h) for h in handles] == pytest.approx(target):
            break
    assert [sim.getJointTargetPosition(h) for h in handles] == pytest.approx(target)


def test_in_process_client_with_ros2_publishes_the_graph(domain):
    import gantry

    peer = Peer(domain)
    clock = peer.reader("rt/clock", Clock)
    joints = peer.reader("rt/joint_states", JointState)
    client = gantry.Client(REPO / SCENE, ros2=True, realtime=False)
    try:
        sim = client.require("sim")
        got = take_until(clock, lambda s: s or client.step() and False, what="/clock from gantry.Client")
        for _ in range(3):
            sim.step()
        t = sim.getSimulationTime()
        seen = take_until(clock, lambda s: any(abs(stamp_s(c.clock) - t) < 1e-6 for c in s), what="/clock at t")
        assert stamp_s(seen[-1].clock) == pytest.approx(t, abs=1e-6)
        js = take_until(joints, lambda s: s, what="/joint_states")[-1]
        assert list(js.name) == ["bubbleRob/leftMotor", "bubbleRob/rightMotor"]
        assert got
    finally:
        client.close()


PEER_THAT_VANISHES = """
import sys, time
sys.path.insert(0, {here!r})
from ros2_peer import Image, Peer
peer = Peer({domain})
images = peer.reader("rt/bubbleRob/sensingNose/visionSensor/image_raw", Image)
while True:
    if images.take(N=10):
        print("got", flush=True)
    time.sleep(0.005)
"""


def test_a_peer_killed_mid_transfer_leaves_the_simulation_running(domain, procs):
    import subprocess
    import sys

    g, client, sim = held(procs, extra=["--ros2"])
    code = PEER_THAT_VANISHES.format(here=str(Path(__file__).resolve().parent), domain=domain)
    peer = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        # Step until the peer has images coming, then kill it while more are sent.
        import threading

        lines: list[str] = []
        assert peer.stdout is not None
        threading.Thread(target=lambda: lines.extend(peer.stdout), daemon=True).start()
        deadline = time.monotonic() + 30
        while not lines:
            assert time.monotonic() < deadline, "the peer never received an image"
            client.step()
        client.step()
        peer.kill()
    finally:
        peer.kill()
        peer.wait(10)
    t0 = sim.getSimulationTime()
    for _ in range(40):
        client.step()
    assert sim.getSimulationTime() == pytest.approx(t0 + 40 * 0.05)
    assert g.proc.poll() is None, "gantry is still running"
    assert "panicked" not in g.stderr()


def test_a_script_calls_a_service_the_peer_serves(domain, procs, tmp_path):
    import threading

    script = tmp_path / "client.lua"
    script.write_text(
        "function sysCall_init()\n"
        "    client = simROS2.createClient('/add_two_ints', 'example_interfaces/srv/AddTwoInts')\n"
        "end\n"
        "function sysCall_actuation()\n"
        "    if not done and simROS2.waitForService(client, 1) then\n"
        "        local r = simROS2.call(client, {a = 2, b = 40})\n"
        "        sim.setInt32Signal('sum', r.sum)\n"
        "        done = true\n"
        "    end\n"
        "end\n"
    )
    scene = tmp_path / "client.toml"
    scene.write_text(f'[[object]]\nname = "node"\nkind = "dummy"\nscript = "{script.name}"\n')
    peer = Peer(domain)
    requests = peer.reader("rq/add_two_intsRequest", AddTwoIntsRequest)
    replies = peer.writer("rr/add_two_intsReply", AddTwoIntsResponse)
    seen: list = []
    stop = threading.Event()

    def serve():
        while not stop.is_set():
            for r in requests.take(N=10):
                seen.append(r)
                replies.write(AddTwoIntsResponse(client_guid=r.client_guid, sequence_number=r.sequence_number,
                                                 sum=r.a + r.b))
            time.sleep(0.002)

    server = threading.Thread(target=serve, daemon=True)
    server.start()
    try:
        g, client, sim = held(procs, scene=scene)
        for _ in range(100):
            client.step()
            if sim.getInt32Signal("sum"):
                break
        assert sim.getInt32Signal("sum") == 42, (seen, g.stderr()[-300:])
        assert len(seen) == 1 and seen[0].sequence_number == 1, seen
    finally:
        stop.set()
        server.join(5)


ACTION_SERVER = """
function handle_goal(id, goal)
    if goal.order > 50 then return simROS2.goal_response.reject end
    return simROS2.goal_response.accept_and_execute
end
function handle_cancel(id, goal)
    return simROS2.cancel_response.accept
end
function handle_accepted(id, goal)
    current = {id = id, order = goal.order, seq = {0, 1}}
    sim.setStringSignal('goal', id)
end
function sysCall_init()
    srv = simROS2.createActionServer('/fibonacci', 'example_interfaces/action/Fibonacci',
        handle_goal, handle_cancel, handle_accepted)
end
function sysCall_actuation()
    if not current then return end
    if simROS2.actionServerActionIsCanceling(srv, current.id) then
        simROS2.actionServerActionCanceled(srv, current.id, {sequence = current.seq})
        current = nil
        return
    end
    local n = #current.seq
    current.seq[n + 1] = current.seq[n] + current.seq[n - 1]
    simROS2.actionServerPublishFeedback(srv, current.id, {sequence = current.seq})
    if n + 1 >= current.order then
        simROS2.actionServerActionSucceed(srv, current.id, {sequence = current.seq})
        current = nil
    end
end
"""


def one_script_scene(tmp_path, name, source):
    script = tmp_path / f"{name}.lua"
    script.write_text(source)
    scene = tmp_path / f"{name}.toml"
    scene.write_text(f'[[object]]\nname = "node"\nkind = "dummy"\nscript = "{script.name}"\n')
    return scene


def reply_to(reader, seq, client, sim, steps=200):
    """The reply to request ``seq``, stepping gantry until it comes."""
    for _ in range(steps):
        for r in reader.take(N=100):
            if r.sequence_number == seq:
                return r
        client.step()
        time.sleep(0.002)
    raise AssertionError(f"no reply to request {seq}")


def test_a_script_action_server_serves_the_peer(domain, procs, tmp_path):
    import os

    scene = one_script_scene(tmp_path, "server", ACTION_SERVER)
    peer = Peer(domain)
    act = FibonacciEndpoints(peer, "/fibonacci", serving=False)
    g, client, sim = held(procs, scene=scene)
    for w in act.requests.values():
        wait_matched(w)
    guid = 0xC0FFEE

    def goal(seq, order):
        gid = UUID(uuid=list(os.urandom(16)))
        act.requests["send_goal"].write(
            FibonacciSendGoalRequest(client_guid=guid, sequence_number=seq, goal_id=gid,
                                     goal=FibonacciGoal(order=order)))
        return gid, reply_to(act.replies["send_goal"], seq, client, sim)

    # A goal that runs to the end, with feedback at every step.
    gid, r = goal(1, 6)
    assert r.accepted, g.stderr()[-500:]
    assert sim.getStringSignal("goal") == bytes(gid.uuid).hex().encode()
    act.requests["get_result"].write(FibonacciGetResultRequest(client_guid=guid, sequence_number=2, goal_id=gid))
    res = reply_to(act.replies["get_result"], 2, client, sim)
    assert res.status == 4, "STATUS_SUCCEEDED"
    assert list(res.result.sequence) == [0, 1, 1, 2, 3, 5]
    fb = [f for f in take_until(act.feedback, lambda got: len(got) >= 4, what="feedback")
          if bytes(f.goal_id.uuid) == bytes(gid.uuid)]
    assert [len(f.feedback.sequence) for f in fb] == [3, 4, 5, 6]
    status = take_until(act.status, lambda got: any(
        s.status == 4 for m in got for s in m.status_list), what="a succeeded status")
    assert any(bytes(s.goal_info.goal_id.uuid) == bytes(gid.uuid) for m in status for s in m.status_list)

    # One the server's callback rejects.
    _, r = goal(3, 99)
    assert not r.accepted

    # One canceled while it runs: the cancel reply lists it, the result says canceled.
    gid, r = goal(4, 40)
    assert r.accepted
    for _ in range(3):
        client.step()
    act.requests["cancel_goal"].write(CancelGoalRequest(client_guid=guid, sequence_number=5, goal_info=GoalInfo(
        goal_id=gid, stamp=Time(sec=0, nanosec=0))))
    c = reply_to(act.replies["cancel_goal"], 5, client, sim)
    assert c.return_code == 0
    assert [bytes(i.goal_id.uuid) for i in c.goals_canceling] == [bytes(gid.uuid)]
    act.requests["get_result"].write(FibonacciGetResultRequest(client_guid=guid, sequence_number=6, goal_id=gid))
    res = reply_to(act.replies["get_result"], 6, client, sim)
    assert res.status == 5, "STATUS_CANCELED"
    assert list(res.result.sequence)[:4] == [0, 1, 1, 2]
    assert g.proc.poll() is None and "panicked" not in g.stderr()


ACTION_CLIENT = """
function sysCall_init()
    cli = simROS2.createActionClient('/fibonacci', 'example_interfaces/action/Fibonacci',
        'on_response', 'on_feedback', 'on_result')
end
function sysCall_actuation()
    if not sent then
        sent = true
        sim.setInt32Signal('sent', simROS2.sendGoal(cli, {order = 5}) and 1 or 0)
    end
end
function on_response(id, accepted)
    sim.setInt32Signal('accepted', accepted and 1 or 0)
    sim.setStringSignal('goal', id)
end
function on_feedback(id, fb)
    sim.setInt32Signal('feedback', #fb.sequence)
end
function on_result(id, code, result)
    sim.setInt32Signal('code', code)
    sim.setStringSignal('result', table.concat(result.sequence, ','))
end
"""


def test_a_script_action_client_gets_a_goal_done_by_the_peer(domain, procs, tmp_path):
    import threading

    scene = one_script_scene(tmp_path, "client", ACTION_CLIENT)
    peer = Peer(domain)
    act = FibonacciEndpoints(peer, "/fibonacci", serving=True)
    goals: dict = {}
    stop = threading.Event()

    def serve():
        while not stop.is_set():
            for r in act.requests["send_goal"].take(N=10):
                seq = [0, 1]
                while len(seq) < r.goal.order:
                    seq.append(seq[-1] + seq[-2])
                goals[bytes(r.goal_id.uuid)] = seq
                act.replies["send_goal"].write(FibonacciSendGoalResponse(
                    client_guid=r.client_guid, sequence_number=r.sequence_number, accepted=True,
                    stamp=Time(sec=0, nanosec=0)))
                for n in (3, 4):
                    act.feedback.write(FibonacciFeedbackMessage(
                        goal_id=r.goal_id, feedback=FibonacciFeedback(sequence=seq[:n])))
            for r in act.requests["get_result"].take(N=10):
                act.replies["get_result"].write(FibonacciGetResultResponse(
                    client_guid=r.client_guid, sequence_number=r.sequence_number, status=4,
                    result=FibonacciResult(sequence=goals.get(bytes(r.goal_id.uuid), []))))
            time.sleep(0.002)

    server = threading.Thread(target=serve, daemon=True)
    server.start()
    try:
        g, client, sim = held(procs, scene=scene)
        for _ in range(200):
            client.step()
            if sim.getInt32Signal("code"):
                break
        assert sim.getInt32Signal("sent") == 1, g.stderr()[-500:]
        assert sim.getInt32Signal("accepted") == 1
        assert len(goals) == 1 and sim.getStringSignal("goal") == next(iter(goals)).hex().encode()
        assert sim.getInt32Signal("feedback") == 4
        assert sim.getInt32Signal("code") == 8564, "simROS2.action_result_code.succeeded"
        assert sim.getStringSignal("result") == b"0,1,1,2,3"
    finally:
        stop.set()
        server.join(5)
