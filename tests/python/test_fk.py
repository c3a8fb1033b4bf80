"""(2) Forward kinematics: gantry's arm6 against PyBullet's FK of the same URDF.

Every link frame (the URDF link frame: for a child link, its joint's frame) is compared
in position (1e-5 m) and orientation (quaternion, up to sign) at 25 random joint
configurations inside the joint limits. PyBullet loads the URDF on its own, in DIRECT
mode with a fixed base, so the two implementations share nothing but the file.
"""

import math
import random

import pybullet as pb
import pytest

from gantry_proc import REPO

URDF = REPO / "assets" / "robots" / "arm6" / "arm6.urdf"
TOL_M = 1e-5
TOL_Q = 1e-5
N_CONFIGS = 25


@pytest.fixture(scope="module")
def bullet():
    cid = pb.connect(pb.DIRECT)
    try:
        # The scene puts arm6's base at the world origin, unrotated.
        robot = pb.loadURDF(str(URDF), [0, 0, 0], [0, 0, 0, 1], useFixedBase=True,
                            physicsClientId=cid)
        joints = {}
        for i in range(pb.getNumJoints(robot, physicsClientId=cid)):
            info = pb.getJointInfo(robot, i, physicsClientId=cid)
            joints[info[1].decode()] = {
                "index": i,
                "type": info[2],
                "lower": info[8],
                "upper": info[9],
                "link": info[12].decode(),
            }
        yield cid, robot, joints
    finally:
        pb.disconnect(cid)


def limits(j):
    # Continuous joints report lower > upper in PyBullet; use one turn. Stay a little
    # inside the limits so no implementation's clamping can differ.
    if j["type"] != pb.JOINT_REVOLUTE or j["lower"] >= j["upper"]:
        return -math.pi + 1e-3, math.pi - 1e-3
    return j["lower"] + 1e-3, j["upper"] - 1e-3


def quat_distance(a, b):
    return min(max(abs(x - y) for x, y in zip(a, b)), max(abs(x + y) for x, y in zip(a, b)))


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_fk_matches_pybullet(client, bullet):
    cid, robot, joints = bullet
    sim = client.require("sim")
    # Hold the simulation so nothing moves between setting and reading.
    client.setStepping(True)

    movable = [n for n, j in joints.items() if j["type"] == pb.JOINT_REVOLUTE]
    assert movable == [f"joint{i}" for i in range(1, 7)]
    links = [j["link"] for j in joints.values()]
    assert links == [f"link{i}" for i in range(1, 7)] + ["tip"]
    joint_h = {n: sim.getObject(f"/arm6/{n}") for n in movable}
    link_h = {n: sim.getObject(f"/arm6/{n}") for n in links}

    rng = random.Random(6)
    worst_p = worst_q = 0.0
    for k in range(N_CONFIGS):
        q = {n: rng.uniform(*limits(joints[n])) for n in movable}
        if k == 0:
            q = {n: 0.0 for n in movable}
        for n, v in q.items():
            sim.setJointPosition(joint_h[n], v)
            pb.resetJointState(robot, joints[n]["index"], v, physicsClientId=cid)
        for n, v in q.items():
            assert sim.getJointPosition(joint_h[n]) == pytest.approx(v, abs=1e-9)
        for name, j in joints.items():
            state = pb.getLinkState(robot, j["index"], computeForwardKinematics=True,
                                    physicsClientId=cid)
            want_p, want_q = state[4], state[5]  # world link frame: the URDF link frame
            got_p = sim.getObjectPosition(link_h[j["link"]], sim.handle_world)
            got_q = sim.getObjectQuaternion(link_h[j["link"]], sim.handle_world)
            dp = max(abs(a - b) for a, b in zip(got_p, want_p))
            dq = quat_distance(got_q, want_q)
            worst_p, worst_q = max(worst_p, dp), max(worst_q, dq)
            assert dp < TOL_M, f"config {k} {j['link']}: position {got_p} vs {want_p} ({q})"
            assert dq < TOL_Q, f"config {k} {j['link']}: quaternion {got_q} vs {want_q} ({q})"
    print(f"worst position error {worst_p:.2e} m, worst quaternion component error {worst_q:.2e}")
