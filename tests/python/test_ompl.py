"""simOMPL from Python, as the public planning clients use it: the nested constants
(``simOMPL.StateSpaceType.joint_position``) over ZMQ and in-process, a plan for the
paper's arm around a box, and the plan replayed without collision."""

import pytest


@pytest.mark.scene("assets/scenes/fk_arm.toml")
def test_a_plan_for_the_arm_avoids_a_box(client):
    sim = client.require("sim")
    ompl = client.require("simOMPL")
    assert isinstance(ompl.StateSpaceType.joint_position, int)
    assert isinstance(ompl.Algorithm.RRTConnect, int)

    client.setStepping(True)
    sim.startSimulation()
    joints = [sim.getObject(f"/arm6/joint{i}") for i in (1, 2, 3)]
    box = sim.createPrimitiveShape(sim.primitiveshape_cuboid, [0.2, 0.2, 0.2])
    sim.setObjectPosition(box, [0, 0.45, 0.65], sim.handle_world)
    arm = sim.createCollection(0)
    sim.addItemToCollection(arm, sim.handle_tree, sim.getObject("/arm6"), 0)

    spaces = [
        ompl.createStateSpace("j1", ompl.StateSpaceType.cyclic_joint_position, joints[0], [], [], 1),
        ompl.createStateSpace("j2", ompl.StateSpaceType.joint_position, joints[1], [-1.9], [1.5], 1),
        ompl.createStateSpace("j3", ompl.StateSpaceType.joint_position, joints[2], [-0.8], [3.1], 1),
    ]
    task = ompl.createTask("arm")
    ompl.setStateSpace(task, spaces)
    ompl.setAlgorithm(task, ompl.Algorithm.RRTConnect)
    ompl.setCollisionPairs(task, [arm, box])
    start = ompl.readState(task)
    goal = [2.5, start[1], start[2]]
    ompl.setStartState(task, start)
    ompl.setGoalState(task, goal)
    assert not ompl.isStateValid(task, [1.5, start[1], start[2]]), "turning the base alone hits the box"

    solved, path = ompl.compute(task, 10, -1, 40)
    assert solved
    states = [path[k : k + 3] for k in range(0, len(path), 3)]
    assert len(states) == 40
    assert states[0] == pytest.approx(start) and states[-1] == pytest.approx(goal)
    for s in states:
        ompl.writeState(task, s)
        hit, _ = sim.checkCollision(arm, box)
        assert hit == 0, f"state {s} collides"
    sim.stopSimulation()
