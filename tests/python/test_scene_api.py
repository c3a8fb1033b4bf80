"""The scene as data from Python, in the style of CoppeliaSim's simpleTest.py: create
dummies and shapes, place them (both argument orders), step, read back, remove, stop;
math and packing helpers and the 4.0-4.2 names, through the real ZMQ client."""

import struct

import pytest


def test_create_step_remove_stop(gantry):
    g = gantry("assets/scenes/bubble_rob.toml")
    client = g.client()
    sim = client.require("sim")

    # As simpleTest.py: a few dummies (4.x signature with a colour), placed with the
    # pre-4.6 argument order.
    handles = [sim.createDummy(0.01, 12 * [0]) for _ in range(5)]
    assert len(set(handles)) == 5
    for i, h in enumerate(handles):
        sim.setObjectPosition(h, -1, [0.01 * i, 0.02 * i, 0.5 + 0.03 * i])
    assert sim.getObjectPosition(handles[3], sim.handle_world) == pytest.approx([0.03, 0.06, 0.59])

    # A cuboid made dynamic and respondable falls onto the floor.
    box = sim.createPrimitiveShape(sim.primitiveshape_cuboid, [0.1, 0.1, 0.1])
    sim.setObjectPosition(box, [1.5, 1.5, 1.0], sim.handle_world)
    sim.setObjectInt32Param(box, sim.shapeintparam_static, 0)
    sim.setObjectInt32Param(box, sim.shapeintparam_respondable, 1)
    sim.resetDynamicObject(box)

    client.setStepping(True)
    sim.startSimulation()  # gantry runs the scene from launch: this one is a no-op
    t0 = sim.getSimulationTime()
    for _ in range(40):  # 2 s
        client.step()
    z = sim.getObjectPosition(box, sim.handle_world)[2]
    assert z == pytest.approx(0.05, abs=0.01), f"the box rests on the floor, z = {z}"
    assert sim.getSimulationTime() == pytest.approx(t0 + 2.0)

    sim.removeObjects(handles[:4])
    sim.removeObject(handles[4])
    with pytest.raises(Exception, match="object does not exist"):
        sim.getObjectPosition(handles[0], sim.handle_world)
    sim.stopSimulation()
    assert sim.getSimulationState() == sim.simulation_stopped
    # Stopping restores the scene: the created objects are gone.
    with pytest.raises(Exception, match="object does not exist"):
        sim.getObjectPosition(box, sim.handle_world)


def test_math_packing_and_old_names(gantry):
    g = gantry("assets/scenes/bubble_rob.toml")
    sim = g.client().require("sim")

    # A quarter turn about z maps x to y; the inverse maps it back.
    m = sim.buildMatrix([1, 2, 3], [0, 0, 3.141592653589793 / 2])
    assert sim.multiplyVector(m, [1, 0, 0]) == pytest.approx([1, 3, 3], abs=1e-12)
    inv = sim.getMatrixInverse(m)
    assert sim.multiplyVector(inv, [1, 3, 3]) == pytest.approx([1, 0, 0], abs=1e-12)

    data = sim.packFloatTable([1.5, -2.0, 3.25])
    assert isinstance(data, bytes) and struct.unpack("<3f", data) == (1.5, -2.0, 3.25)
    assert sim.unpackFloatTable(data) == [1.5, -2.0, 3.25]
    assert sim.unpackTable(sim.packTable({"a": [1, 2], "b": "x"})) == {"a": [1, 2], "b": "x"}

    rob = sim.getObject("/bubbleRob")
    assert sim.getObjectHandle("bubbleRob") == rob
    assert sim.getObjectHandle("nothing@silentError") == -1
    # The rover carries a script, whose handle is the rover's.
    assert sim.getScriptAssociatedWithObject(rob) == rob
    sim.setIntegerSignal("n", 4)
    assert sim.getInt32Signal("n") == 4


def test_load_scene_and_close_scene(gantry, tmp_path):
    from gantry_proc import REPO

    g = gantry("assets/scenes/bubble_rob.toml")
    sim = g.client().require("sim")
    assert sim.getObject("/bubbleRob") >= 0

    # As CoppeliaSim's examples begin: load the scene to work on.
    sim.loadScene(str(REPO / "assets/scenes/fk_arm.toml"))
    assert sim.getSimulationState() == sim.simulation_stopped
    assert sim.getObject("/arm6") >= 0
    with pytest.raises(Exception, match="object does not exist"):
        sim.getObject("/bubbleRob")
    sim.startSimulation()
    # 16 until the first step is done, 17 after (CoppeliaSim's advancing passes).
    assert sim.getSimulationState() in (sim.simulation_advancing_firstafterstop, sim.simulation_advancing_running)

    # A file that is not what its name says is refused with the reader's reason; a
    # missing file names the file; the scene stays as it was.
    bad = tmp_path / "scene.ttt"
    bad.write_bytes(b"not a scene")
    with pytest.raises(Exception, match=r"scene\.ttt: not a CoppeliaSim scene or model file"):
        sim.loadScene(str(bad))
    with pytest.raises(Exception, match="no-such-scene.toml"):
        sim.loadScene(str(REPO / "no-such-scene.toml"))
    assert sim.getObject("/arm6") >= 0

    sim.closeScene()
    with pytest.raises(Exception, match="object does not exist"):
        sim.getObject("/arm6")


def test_load_model_adds_a_public_robot_to_the_running_scene(gantry):
    """sim.loadModel with a URDF from pybullet_data (not ours): the robot joins the
    scene beside BubbleRob, with PyBullet's joints and, at a random configuration,
    PyBullet's forward kinematics."""
    import math
    import os
    import random

    import pybullet as pb
    import pybullet_data

    urdf = os.path.join(pybullet_data.getDataPath(), "kuka_iiwa", "model.urdf")
    g = gantry("assets/scenes/bubble_rob.toml")
    client = g.client()
    sim = client.require("sim")
    client.setStepping(True)
    base = sim.loadModel(urdf)
    assert sim.getObjectAlias(base) == "lbr_iiwa"
    assert sim.getObject("/bubbleRob") >= 0  # the scene is still there
    joints = sim.getObjectsInTree(base, sim.object_joint_type, 0)

    cid = pb.connect(pb.DIRECT)
    try:
        body = pb.loadURDF(urdf, useFixedBase=True, physicsClientId=cid)
        info = [pb.getJointInfo(body, i, physicsClientId=cid) for i in range(pb.getNumJoints(body, physicsClientId=cid))]
        revolute = [i for i in info if i[2] == pb.JOINT_REVOLUTE]
        assert len(joints) == len(revolute) == 7
        rng = random.Random(18)
        for j, i in zip(joints, revolute):
            q = rng.uniform(max(i[8], -2.0), min(i[9], 2.0))
            sim.setJointPosition(j, q)
            pb.resetJointState(body, i[0], q, physicsClientId=cid)
        tip = pb.getLinkState(body, revolute[-1][0], computeForwardKinematics=True, physicsClientId=cid)[4]
        got = sim.getObjectPosition(sim.getObject("/lbr_iiwa/lbr_iiwa_link_7"), sim.handle_world)
        assert math.dist(got, tip) < 1e-5, (got, tip)
    finally:
        pb.disconnect(cid)

    # Bad files are refused by name, and the scene is unchanged.
    with pytest.raises(Exception, match=r"robot\.ttm: cannot read.*\(in function 'sim.loadModel'\)"):
        sim.loadModel("/tmp/no-such-dir/robot.ttm")
    sim.stopSimulation()
    assert sim.getObject("/lbr_iiwa") == base  # a loaded model stays in the scene
