"""PyRep's robots on gantry: joint vectors, arms (IK, paths), grippers, suction cups,
mobile bases and configuration paths, on PyRep's test scene and the robot models PyRep
ships (`PyRep__*.ttm`).

Tests of arms need the model's IK group (`<Name>_ik`) imported from the CoppeliaSim
file; until gantry reads IK groups from .ttt/.ttm files they fail at
`sim.getIkGroupHandle` (not skipped)."""

import numpy as np
import pytest

from conftest import model_path

from pyrep.backend import sim
from pyrep.const import JointType
from pyrep.errors import ConfigurationError, ConfigurationPathError, IKError
from pyrep.objects.dummy import Dummy
from pyrep.objects.shape import Shape
from pyrep.const import PrimitiveShape
from pyrep.robots.robot_component import RobotComponent
from pyrep.robots.configuration_paths.arm_configuration_path import ArmConfigurationPath

PANDA_JOINTS = ["Panda_joint%d" % i for i in range(1, 8)]


# --- joint vectors (no IK needed) --------------------------------------------------------


def test_joint_vectors_of_the_scene_panda(pr_scene):
    panda = RobotComponent(0, "Panda", PANDA_JOINTS)
    assert panda.get_joint_count() == 7
    assert panda.get_joint_types() == [JointType.REVOLUTE] * 7
    targets = (np.array(panda.get_joint_positions()) + 0.05).tolist()
    panda.set_joint_target_positions(targets)
    assert np.allclose(panda.get_joint_target_positions(), targets)
    panda.set_joint_target_velocities([0.2] * 7)
    assert np.allclose(panda.get_joint_target_velocities(), [0.2] * 7)
    cyclic, intervals = panda.get_joint_intervals()
    assert len(cyclic) == 7 and all(len(i) == 2 for i in intervals)
    assert len(panda.get_joint_upper_velocity_limits()) == 7
    assert len(panda.get_joint_forces()) == 7
    assert len(panda.get_joint_velocities()) == 7
    assert len(panda.get_visuals()) == 10


def test_joint_positions_with_and_without_dynamics(pr_scene):
    panda = RobotComponent(0, "Panda", PANDA_JOINTS)
    config = [0.1, 0.2, -0.1, -1.5, 0.05, 1.6, 0.7]
    panda.set_joint_positions(config, disable_dynamics=True)
    assert np.allclose(panda.get_joint_positions(), config, atol=1e-3)
    assert np.allclose(panda.get_joint_target_positions(), config, atol=1e-6)
    # Held by its motors there.
    for _ in range(10):
        pr_scene.step()
    assert np.allclose(panda.get_joint_positions(), config, atol=0.01)


def test_wrong_lengths_are_refused(pr_scene):
    panda = RobotComponent(0, "Panda", PANDA_JOINTS)
    with pytest.raises(RuntimeError, match="7 joints"):
        panda.set_joint_positions([0.0] * 6)
    with pytest.raises(RuntimeError, match="7 joints"):
        panda.set_joint_target_velocities([0.0] * 8)


def test_missing_copy_is_an_error(pr_scene):
    with pytest.raises(RuntimeError):
        RobotComponent(3, "Panda", PANDA_JOINTS)
    with pytest.raises(ValueError):
        RobotComponent(-1, "Panda", PANDA_JOINTS)


# --- configuration paths (no IK needed) ---------------------------------------------------


class _JointArm(RobotComponent):
    """The scene's Panda as an arm without IK: what ArmConfigurationPath uses."""

    def __init__(self):
        super().__init__(0, "Panda", PANDA_JOINTS)
        self.max_velocity, self.max_acceleration, self.max_jerk = 1.0, 4.0, 1000
        self._tip = Dummy("Panda_tip")

    def get_tip(self):
        return self._tip


def _settle(pr, steps=20):
    for _ in range(steps):
        pr.step()


def test_arm_configuration_path_steps_to_its_end(pr_scene):
    arm = _JointArm()
    start = np.array(arm.get_joint_positions())
    goal = start + np.array([0.3, -0.2, 0.2, 0.3, -0.2, 0.2, 0.4])
    points = np.linspace(start, goal, 20).ravel()
    path = ArmConfigurationPath(arm, points)
    assert len(path) == 20
    done, steps = False, 0
    while not done:
        done = path.step()
        pr_scene.step()
        steps += 1
        assert steps < 500, "the path never ends"
    # Timed by the trajectory generator: more than one step, and ends at the goal.
    assert steps > 5
    assert np.allclose(path.get_executed_joint_position_action(), goal)
    assert np.allclose(arm.get_joint_target_positions(), goal)
    _settle(pr_scene)
    assert np.allclose(arm.get_joint_positions(), goal, atol=0.01)
    with pytest.raises(RuntimeError, match="completed"):
        path.step()
    path.set_to_start()
    assert np.allclose(arm.get_joint_positions(), start, atol=1e-6)
    assert path.step() is False


def test_arm_configuration_path_respects_joint_velocity_limits(pr_scene):
    arm = _JointArm()
    arm.max_velocity, arm.max_acceleration = 100.0, 1000.0
    start = np.array(arm.get_joint_positions())
    goal = start.copy()
    goal[0] += 1.0
    path = ArmConfigurationPath(arm, np.linspace(start, goal, 10).ravel())
    dt = pr_scene.get_simulation_timestep()
    limit = arm.get_joint_upper_velocity_limits()[0]
    previous = start
    done = False
    while not done:
        done = path.step()
        action = path.get_executed_joint_position_action()
        assert abs(action[0] - previous[0]) / dt <= limit * 1.01
        previous = action


def test_set_to_end_and_visualize(pr_scene):
    arm = _JointArm()
    start = np.array(arm.get_joint_positions())
    goal = start + 0.2
    path = ArmConfigurationPath(arm, np.linspace(start, goal, 5).ravel())
    path.set_to_end()
    assert np.allclose(arm.get_joint_positions(), goal, atol=1e-6)
    path.set_to_start()
    path.visualize()
    assert np.allclose(arm.get_joint_positions(), start, atol=1e-6)
    path.clear_visualization()
    assert len(path[1:3]) == 2


def test_path_of_partial_configurations_is_refused(pr_scene):
    with pytest.raises(ValueError):
        ArmConfigurationPath(_JointArm(), [0.0] * 10)


# --- grippers and suction cups ------------------------------------------------------------


def _gripper(pr, dynamic=True):
    """The Panda's gripper alone (falling freely when dynamic: its fingers are
    velocity-driven joints, which only move in a dynamic model)."""
    from pyrep.robots.end_effectors.panda_gripper import PandaGripper

    base = pr.import_model(model_path("PandaGripper"))
    base.set_position([0.0, 0.0, 0.5])
    base.set_model_dynamic(dynamic)
    return PandaGripper()


def _actuate(pr, gripper, amount, velocity=0.04, limit=400):
    steps = 0
    while not gripper.actuate(amount, velocity):
        pr.step()
        steps += 1
        assert steps < limit, f"actuate({amount}) never finished: open amount {gripper.get_open_amount()}"
    return steps


def test_panda_gripper_closes_and_opens(pr_empty):
    gripper = _gripper(pr_empty)
    assert gripper.get_joint_count() == 2
    start = gripper.get_open_amount()
    assert all(0.0 <= a <= 1.0 for a in start)
    steps = _actuate(pr_empty, gripper, 0.0)
    assert steps > 1
    closed = gripper.get_open_amount()
    assert all(a < 0.1 for a in closed), closed
    _actuate(pr_empty, gripper, 1.0)
    opened = gripper.get_open_amount()
    assert all(a > 0.9 for a in opened), opened
    with pytest.raises(ValueError):
        gripper.actuate(1.5, 0.04)


def test_gripper_grasp_and_release(pr_empty):
    gripper = _gripper(pr_empty, dynamic=False)
    sensor = gripper._proximity_sensor
    cube = Shape.create(PrimitiveShape.CUBOID, [0.02, 0.02, 0.02], static=True)
    far = Shape.create(PrimitiveShape.CUBOID, [0.02, 0.02, 0.02], static=True, position=[1.0, 1.0, 1.0])
    # Put the cube on the sensor's axis, just in front of it.
    cube.set_position([0.0, 0.0, 0.01], relative_to=sensor)
    assert not gripper.grasp(far)
    assert gripper.get_grasped_objects() == []
    assert gripper.grasp(cube)
    assert gripper.get_grasped_objects() == [cube]
    assert cube.get_parent() == gripper._attach_point
    pose = cube.get_pose()
    gripper.release()
    assert gripper.get_grasped_objects() == []
    assert cube.get_parent() is None
    assert np.allclose(cube.get_pose()[:3], pose[:3], atol=1e-6)


def test_baxter_suction_cup(pr_empty):
    from pyrep.robots.end_effectors.baxter_suction_cup import BaxterSuctionCup

    base = pr_empty.import_model(model_path("BaxterSuctionCup"))
    base.set_model_dynamic(False)
    cup = BaxterSuctionCup()
    assert cup.get_grasped_objects() == []
    far = Shape.create(PrimitiveShape.CUBOID, [0.02, 0.02, 0.02], static=True, position=[2.0, 2.0, 2.0])
    assert not cup.grasp(far)
    cup.release()


def test_gripper_copies(pr_empty):
    from pyrep.robots.end_effectors.panda_gripper import PandaGripper

    pr_empty.import_model(model_path("PandaGripper"))
    first = PandaGripper()
    second = first.copy()
    assert isinstance(second, PandaGripper)
    assert second != first
    assert second.get_handle() == PandaGripper(1).get_handle()


# --- arms (need the IK group imported from the file) ---------------------------------------


def test_scene_panda_is_an_arm(pr_scene):
    from pyrep.robots.arms.panda import Panda

    arm = Panda()
    assert len(arm.joints) == 7
    assert arm.get_jacobian().shape == (7, 6)


ARM_MODELS = [("Panda", "pyrep.robots.arms.panda", "Panda"), ("UR5", "pyrep.robots.arms.ur5", "UR5"),
              ("UR3", "pyrep.robots.arms.ur3", "UR3"), ("UR10", "pyrep.robots.arms.ur10", "UR10"),
              ("Sawyer", "pyrep.robots.arms.sawyer", "Sawyer"), ("Jaco", "pyrep.robots.arms.jaco", "Jaco"),
              ("Mico", "pyrep.robots.arms.mico", "Mico"),
              ("LBR_iiwa_7_R800", "pyrep.robots.arms.lbr_iiwa_7_r800", "LBRIwaa7R800"),
              ("LBR_iiwa_14_R820", "pyrep.robots.arms.lbr_iiwa_14_r820", "LBRIwaa14R820"),
              ("XArm7", "pyrep.robots.arms.xarm7", "XArm7"), ("Dobot", "pyrep.robots.arms.dobot", "Dobot"),
              ("Baxter", "pyrep.robots.arms.baxter", "BaxterLeft"),
              ("Baxter", "pyrep.robots.arms.baxter", "BaxterRight")]


@pytest.mark.parametrize("model,module,cls", ARM_MODELS, ids=[m[2] for m in ARM_MODELS])
def test_arm_models_load(pr_empty, model, module, cls):
    import importlib

    pr_empty.import_model(model_path(model))
    arm = getattr(importlib.import_module(module), cls)()
    assert arm.get_joint_count() == len(arm.get_joint_positions())
    assert isinstance(arm.get_tip(), Dummy)


# Dobot's fourth joint drives the tip through a parallel linkage whose motors
# (`Dobot_auxMotor1/2`) follow it by script; its IK chain holds those motors, not
# `Dobot_joint3`, so a pose made by moving the arm's joints is not one its group solves
# for with them (as in CoppeliaSim).
IK_ARMS = [m for m in ARM_MODELS if m[0] != "Dobot"]


@pytest.mark.parametrize("model,module,cls", IK_ARMS, ids=[m[2] for m in IK_ARMS])
def test_arm_models_find_their_ik_group_and_collection_and_solve_ik(pr_empty, model, module, cls):
    """Issue 50: every arm of PyRep's models finds `<name>_ik` and `<name>_arm` in the
    file and solves IK to a pose it can reach within 1 mm."""
    import importlib

    pr_empty.import_model(model_path(model))
    arm = getattr(importlib.import_module(module), cls)()
    assert arm._ik_group >= 0 and arm._collision_collection >= 0
    assert arm.check_arm_collision() in (True, False)
    cyclic, intervals = arm.get_joint_intervals()
    # From a bent configuration (the middle of each joint's range: a model's zero
    # configuration is often a stretched, singular arm), 0.1 rad (or m) along each joint.
    start = np.array([0.0 if c else lo + span / 2 for c, (lo, span) in zip(cyclic, intervals)])
    arm.set_joint_positions(start, disable_dynamics=True)
    goal = start + 0.1
    position, orientation = _reachable_pose(arm, goal - start)
    config = arm.solve_ik_via_jacobian(position, orientation)
    arm.set_joint_positions(config)
    assert np.linalg.norm(arm.get_tip().get_position() - position) < 0.001


def _reachable_pose(arm, offset):
    """A pose the tip reaches at the current configuration plus `offset`."""
    saved = arm.get_joint_positions()
    arm.set_joint_positions(np.array(saved) + np.array(offset))
    pose = arm.get_tip().get_position(), arm.get_tip().get_orientation()
    arm.set_joint_positions(saved)
    return pose


def test_panda_ik_and_paths(pr_empty):
    from pyrep.robots.arms.panda import Panda

    pr_empty.import_model(model_path("Panda"))
    arm = Panda()
    tip = arm.get_tip()
    _settle(pr_empty, 5)
    position, orientation = _reachable_pose(arm, [0.1, 0.1, -0.1, 0.1, 0.0, 0.1, 0.1])
    config = arm.solve_ik_via_jacobian(position, orientation)
    saved = arm.get_joint_positions()
    arm.set_joint_positions(config)
    assert np.linalg.norm(tip.get_position() - position) < 0.001
    arm.set_joint_positions(saved)

    configs = arm.solve_ik_via_sampling(position, orientation, max_configs=3)
    assert configs.shape == (3, 7)

    path = arm.get_linear_path(position, orientation)
    path.set_to_end()
    assert np.linalg.norm(tip.get_position() - position) < 0.001
    path.set_to_start()
    done, steps = False, 0
    while not done:
        done = path.step()
        pr_empty.step()
        steps += 1
        assert steps < 500
    _settle(pr_empty, 5)
    assert np.linalg.norm(tip.get_position() - position) < 0.01

    far_position, far_orientation = _reachable_pose(arm, [0.8, 0.3, -0.3, -0.5, 0.3, 0.5, -0.3])
    path = arm.get_nonlinear_path(far_position, far_orientation)
    path.set_to_end()
    assert np.linalg.norm(tip.get_position() - far_position) < 0.001

    with pytest.raises(ConfigurationPathError):
        arm.get_linear_path([99, 99, 99], [0, 0, 0])
    with pytest.raises(ConfigurationPathError):
        arm.get_nonlinear_path([99, 99, 99], [0, 0, 0])
    with pytest.raises(ConfigurationError):
        arm.solve_ik_via_sampling([99, 99, 99], [0, 0, 0])
    with pytest.raises(IKError):
        arm.solve_ik_via_jacobian([99, 99, 99], [0, 0, 0])
    with pytest.raises(ConfigurationPathError):
        arm.get_linear_path(position, orientation, quaternion=[0, 0, 0, 1])
    assert arm.check_arm_collision() in (True, False)


def test_missing_arm_is_an_error(pr_empty):
    from pyrep.robots.arms.ur5 import UR5

    with pytest.raises(RuntimeError):
        UR5()


# --- mobile bases ---------------------------------------------------------------------------


def _floor():
    """A static floor the bases stand on, not collidable (as the floors of PyRep's
    scenes), so that path collision checks ignore it."""
    floor = Shape.create(PrimitiveShape.CUBOID, [10.0, 10.0, 0.1], static=True, position=[0.0, 0.0, -0.05])
    floor.set_collidable(False)
    return floor


def test_turtlebot_turns_to_a_linear_path(pr_empty):
    from pyrep.robots.mobiles.turtlebot import TurtleBot

    _floor()
    pr_empty.import_model(model_path("turtlebot"))
    _settle(pr_empty, 5)
    bot = TurtleBot()
    assert not bot.assess_collision(), "the base collides with the floor, which is not collidable"
    x, y, yaw = bot.get_2d_pose()
    goal = [x + 0.5, y]
    path = bot.get_linear_path(goal, angle=0.0)
    for _ in range(100):
        if path.step():
            break
        pr_empty.step()
    # The PID controller turns the base towards the goal first.
    heading_error = lambda p: abs(np.arctan2(np.sin(np.arctan2(goal[1] - p[1], goal[0] - p[0]) - p[2]),
                                             np.cos(np.arctan2(goal[1] - p[1], goal[0] - p[0]) - p[2])))
    assert heading_error(bot.get_2d_pose()) < heading_error([x, y, yaw]) - 0.5


def test_mobile_2d_pose(pr_empty):
    from pyrep.robots.mobiles.youbot import YouBot

    pr_empty.import_model(model_path("youBot"))
    bot = YouBot()
    bot.set_2d_pose([0.3, -0.2, 0.5])
    assert np.allclose(bot.get_2d_pose(), [0.3, -0.2, 0.5], atol=1e-6)
    with pytest.raises(ValueError):
        bot.set_2d_pose([0.0, 0.0])


GRIPPER_MODELS = [("PandaGripper", "pyrep.robots.end_effectors.panda_gripper", "PandaGripper", 0.04),
                  ("BaxterGripper", "pyrep.robots.end_effectors.baxter_gripper", "BaxterGripper", 0.04),
                  ("MicoHand", "pyrep.robots.end_effectors.mico_gripper", "MicoGripper", 0.2),
                  ("JacoHand", "pyrep.robots.end_effectors.jaco_gripper", "JacoGripper", 0.2),
                  ("Robotiq85", "pyrep.robots.end_effectors.robotiq85_gripper", "Robotiq85Gripper", 0.04)]


@pytest.mark.parametrize("model,module,cls,velocity", GRIPPER_MODELS, ids=[g[2] for g in GRIPPER_MODELS])
def test_gripper_models_close_and_open(pr_empty, model, module, cls, velocity):
    """PyRep's own gripper test (test_grippers.py) on each gripper model alone:
    close fully, then open to 0.8 (Robotiq: fully)."""
    import importlib

    base = pr_empty.import_model(model_path(model))
    base.set_position([0.0, 0.0, 0.5])
    gripper = getattr(importlib.import_module(module), cls)()
    pr_empty.step()
    _actuate(pr_empty, gripper, 0.0, velocity, limit=1000)
    open_amount = 1.0 if cls == "Robotiq85Gripper" else 0.8
    _actuate(pr_empty, gripper, open_amount, velocity, limit=1000)
    assert abs(gripper.get_open_amount()[0] - open_amount) < 0.05, gripper.get_open_amount()


def test_gripper_stops_on_an_object_and_grasps_it(pr_empty):
    gripper = _gripper(pr_empty)
    cube = Shape.create(PrimitiveShape.CUBOID, [0.03, 0.03, 0.03], mass=0.05)
    cube.set_position([0.0, 0.0, 0.0], relative_to=Dummy("Panda_tip"))
    _actuate(pr_empty, gripper, 0.0)
    # Held open by the 3 cm cube: each finger stopped near 1.5 cm of its 4 cm.
    amounts = gripper.get_open_amount()
    assert all(0.2 < a < 0.5 for a in amounts), amounts
    assert gripper.grasp(cube)
    assert cube.get_parent() == gripper._attach_point


def test_mobile_nonlinear_path_plans_to_the_goal(pr_empty):
    from pyrep.robots.mobiles.turtlebot import TurtleBot

    _floor()
    pr_empty.import_model(model_path("turtlebot"))
    bot = TurtleBot()
    x, y, _ = bot.get_2d_pose()
    goal = [x + 0.6, y + 0.3]
    path = bot.get_nonlinear_path(goal, angle=0.5, path_pts=100, ignore_collisions=True)
    states = path._path_points
    assert len(states) == 100 and all(len(s) == 4 for s in states)
    assert np.allclose(states[0][:2], [x, y], atol=1e-3)
    path.set_to_end()
    assert np.allclose(bot.get_2d_pose(), [goal[0], goal[1], 0.5], atol=1e-3)
    path.set_to_start()
    assert np.allclose(bot.get_2d_pose()[:2], [x, y], atol=1e-3)
    path.visualize()
    path.clear_visualization()
    assert path.step() in (True, False)
