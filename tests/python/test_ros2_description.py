"""Issue 29, item 4: a URDF robot on the ROS 2 graph as robot_state_publisher presents it,
checked by an independent DDS implementation (Cyclone DDS from PyPI, as in
test_ros2.py), so that rviz2's RobotModel display can place the robot's links:

- ``/robot_description`` (``std_msgs/String``) is the URDF file's text, unchanged, and a
  subscriber that joins after gantry published it still gets it: the writer is
  transient local (a volatile writer would not even match a transient-local reader);
- the TF frames of the robot's links are the URDF link names, each link's parent is its
  parent link, and every one resolves to ``world``;
- ``/joint_states`` names the joints by their URDF names.

The scene is the bundled ``fk_arm.toml`` (arm6's URDF on a floor); ``gantry run`` starts
the simulation by itself, so no remote API client is needed. Without gantry's
description nothing arrives and the test times out.
"""

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import pytest
from cyclonedds.idl import IdlStruct

from gantry_proc import REPO, GantryProcess
from ros2_peer import LATCHED, Clock, JointState, Peer, TFMessage, take_until

SCENE = "assets/scenes/fk_arm.toml"
URDF = REPO / "assets/robots/arm6/arm6.urdf"


@dataclass
class String(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


def urdf_names(tag: str) -> list[str]:
    """The names of the URDF's ``<link>`` or ``<joint>`` elements, in file order."""
    return [e.get("name") for e in ET.parse(URDF).getroot().findall(tag)]


def parents(messages) -> dict[str, str]:
    """Child frame -> parent frame over ``TFMessage`` samples, the latest of each."""
    out: dict[str, str] = {}
    for m in messages:
        for t in m.transforms:
            out[t.child_frame_id] = t.header.frame_id
    return out


def chain(tree: dict[str, str], frame: str) -> list[str] | None:
    """``frame``'s parents up to ``world``, or ``None`` when the chain breaks or loops."""
    seen = [frame]
    while seen[-1] != "world":
        parent = tree.get(seen[-1])
        if parent is None or parent in seen:
            return None
        seen.append(parent)
    return seen


def test_a_late_subscriber_gets_the_urdf_and_link_frames(domain, procs):
    peer = Peer(domain)
    clock = peer.reader("rt/clock", Clock)
    procs.append(GantryProcess(SCENE, fast=False, extra=["--ros2"]))
    # gantry publishes the description with its first step; a few clock ticks later
    # it has been out on the graph for a while.
    take_until(clock, lambda s: len(s) >= 3, timeout=60, what="/clock")

    # Late readers: they join after the description was written.
    description = peer.reader("rt/robot_description", String, LATCHED)
    tf_static = peer.reader("rt/tf_static", TFMessage, LATCHED)
    tf = peer.reader("rt/tf", TFMessage)
    joints = peer.reader("rt/joint_states", JointState)

    got = take_until(description, bool, what="/robot_description")
    assert len(got) == 1, "one robot, one description"
    assert got[0].data == URDF.read_text(encoding="utf-8")

    links = urdf_names("link")
    assert "base_link" in links and "tip" in links
    seen: list = []

    def every_link_resolves(samples) -> bool:
        seen.extend(tf.take(N=1000))
        tree = parents(samples + seen)
        return all(chain(tree, link) for link in links)

    statics = take_until(tf_static, every_link_resolves, what="every URDF link's frame on /tf")
    tree = parents(statics + seen)
    assert tree["base_link"] == "arm6", "the root link hangs from the robot's model base"
    for joint in ET.parse(URDF).getroot().findall("joint"):
        child, parent = joint.find("child").get("link"), joint.find("parent").get("link")
        assert tree[child] == parent, f"{child}'s TF parent is its parent link"
    assert not set(urdf_names("joint")) & set(tree), "URDF joints are not TF frames"

    movable = [
        e.get("name") for e in ET.parse(URDF).getroot().findall("joint") if e.get("type") != "fixed"
    ]
    states = take_until(joints, bool, what="/joint_states")
    assert list(states[-1].name) == movable
