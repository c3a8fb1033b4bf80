"""Building a robot with CoppeliaSim's own ZMQ client (and, the second time, gantry's
in-process client), as the editor and user code do: `sim.createPrimitiveShape`,
`sim.createJoint`, `sim.createProximitySensor`, `sim.setObjectParent`, `sim.setObjectAlias`
while the simulation is stopped, then `sim.saveScene`. The edits survive a run (a stop
restores the scene as it started, not as it was loaded), and the saved file, run by a
second gantry, holds the same objects with the same poses and joints."""

from __future__ import annotations

import math

import pytest

EMPTY = "[simulation]\ndt = 0.05\n\n[floor]\nsize = [4, 4]\n"


def build(sim) -> dict[str, int]:
    """A two-wheeled base: a cuboid body, two wheels on cyclic velocity joints and a cone
    proximity sensor looking forward."""
    made = {}

    def dynamic(shape):
        sim.setObjectInt32Param(shape, sim.shapeintparam_static, 0)
        sim.setObjectInt32Param(shape, sim.shapeintparam_respondable, 1)

    body = sim.createPrimitiveShape(sim.primitiveshape_cuboid, [0.3, 0.2, 0.1])
    dynamic(body)
    sim.setObjectAlias(body, "base")
    sim.setObjectPosition(body, -1, [0.0, 0.0, 0.1])
    made["base"] = body
    for side, y in (("left", 0.13), ("right", -0.13)):
        joint = sim.createJoint(sim.joint_revolute_subtype, sim.jointmode_dynamic, 1)
        sim.setObjectAlias(joint, f"{side}Motor")
        sim.setObjectParent(joint, body, True)
        sim.setObjectPosition(joint, body, [0.05, y, -0.05])
        sim.setObjectOrientation(joint, body, [-math.pi / 2, 0.0, 0.0])
        wheel = sim.createPrimitiveShape(sim.primitiveshape_cylinder, [0.1, 0.1, 0.03])
        sim.setObjectAlias(wheel, f"{side}Wheel")
        sim.setObjectParent(wheel, joint, False)
        dynamic(wheel)
        made[f"{side}Motor"], made[f"{side}Wheel"] = joint, wheel
    floats = [0.0, 0.4] + 7 * [0.0] + [math.radians(50)] + 5 * [0.0]
    nose = sim.createProximitySensor(sim.proximitysensor_cone_subtype, 16, 0, 8 * [0], floats)
    sim.setObjectAlias(nose, "nose")
    sim.setObjectParent(nose, body, True)
    sim.setObjectPosition(nose, body, [0.15, 0.0, 0.0])
    sim.setObjectOrientation(nose, body, [0.0, math.pi / 2, 0.0])
    made["nose"] = nose
    return made


def describe(sim, handles) -> dict[str, tuple]:
    """Each object by alias: its type, parent's alias, pose in the parent's frame, and
    for a joint its type, mode and interval."""
    out = {}
    for h in handles:
        parent = sim.getObjectParent(h)
        pose = sim.getObjectPose(h, parent)
        extra = ()
        if sim.getObjectType(h) == sim.object_joint_type:
            extra = (sim.getJointType(h), sim.getJointMode(h)[0], sim.getJointInterval(h))
        out[sim.getObjectAlias(h)] = (
            sim.getObjectType(h),
            sim.getObjectAlias(parent) if parent != -1 else None,
            pose,
            extra,
        )
    return out


def assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for alias in a:
        (ta, pa, posea, xa), (tb, pb, poseb, xb) = a[alias], b[alias]
        assert (ta, pa) == (tb, pb), alias
        assert posea[:3] == pytest.approx(poseb[:3], abs=1e-9), alias
        # q and -q are the same rotation.
        dot = abs(sum(x * y for x, y in zip(posea[3:], poseb[3:])))
        assert dot == pytest.approx(1.0, abs=1e-9), alias
        assert repr(xa) == repr(xb) or xa == pytest.approx(xb), alias


def test_a_robot_built_while_stopped_survives_a_run_and_saves(gantry, tmp_path):
    scene = tmp_path / "empty.toml"
    scene.write_text(EMPTY)
    client = gantry(scene).client()
    sim = client.require("sim")
    sim.stopSimulation()
    made = build(sim)
    built = describe(sim, made.values())
    assert built["leftMotor"][3][1] == sim.jointmode_dynamic
    assert built["leftWheel"][1] == "leftMotor"

    # A run moves the wheels; the stop brings back the scene as it started.
    client.setStepping(True)
    sim.startSimulation()
    for m in ("leftMotor", "rightMotor"):
        sim.setJointTargetVelocity(made[m], 4.0)
    for _ in range(20):
        client.step()
    assert sim.getJointPosition(made["leftMotor"]) != 0.0
    sim.stopSimulation()
    assert describe(sim, made.values()) == built

    out = tmp_path / "saved" / "base.toml"
    sim.saveScene(str(out))
    assert out.is_file()
    with pytest.raises(Exception, match="never in CoppeliaSim's formats"):
        sim.saveScene(str(tmp_path / "base.ttt"))

    # The saved file, run by a second gantry: the same objects, poses and joints.
    again = gantry(out).client().require("sim")
    loaded = {
        alias: again.getObject(path)
        for alias, path in (
            ("base", "/base"),
            ("leftMotor", "/base/leftMotor"),
            ("rightMotor", "/base/rightMotor"),
            ("leftWheel", "/base/leftMotor/leftWheel"),
            ("rightWheel", "/base/rightMotor/rightWheel"),
            ("nose", "/base/nose"),
        )
    }
    again.stopSimulation()
    assert_same(built, describe(again, loaded.values()))
