"""The UFactory xArm gripper (xarm_gripper), six joints."""

from pyrep.robots.end_effectors.gripper import Gripper

_JOINTS = ["xarm_left_inner_knuckle_joint", "xarm_right_inner_knuckle_joint", "xarm_drive_joint",
           "xarm_left_finger_joint", "xarm_right_outer_knuckle_joint", "xarm_right_finger_joint"]


class XArmGripper(Gripper):
    def __init__(self, count: int = 0):
        super().__init__(count, "xarm_gripper", _JOINTS)
