#!/usr/bin/env python3
"""Writes bubble_rob.toml and showroom.toml, so the rover, obstacles and walls are defined once.

Run from anywhere: python3 assets/scenes/generate.py
"""
import math
from pathlib import Path

HERE = Path(__file__).resolve().parent

# Contact friction. The tutorial sets a material only on the caster (noFrictionMaterial,
# 0); every other shape keeps CoppeliaSim's default material (Bullet friction 0.71). Bullet
# multiplies the two coefficients of a contact, so the tutorial's contacts have these
# coefficients:
TUTORIAL_CONTACTS = {
    ("wheel", "floor"): 0.5,        # 0.71 * 0.71
    ("body", "obstacle"): 0.5,
    ("wheel", "obstacle"): 0.5,
    ("body", "floor"): 0.5,
    ("caster", "floor"): 0.0,       # 0 * 0.71: the caster only carries weight
    ("caster", "obstacle"): 0.0,
}
# gantry (rapier) takes the mean of the two coefficients instead. With per-shape values
# read as in CoppeliaSim (caster 0, floor and wheels 1, body and obstacles 0.5), the
# "frictionless" caster rubs the floor at (0 + 1) / 2 = 0.5 and the wheels grip obstacles
# at 0.75: a rover that meets a cylinder side-on, where its nose sensor cannot see it, then
# pivots into it and stays pinned with its wheels turning. Under the mean rule these are
# the only values that give every contact in the table its tutorial coefficient (a
# frictionless caster needs a frictionless floor, and the wheels then need 1 to grip it at
# 0.5); walls count as obstacles. check_friction() holds them to the table.
FRICTION = {"floor": 0.0, "obstacle": 0.0, "caster": 0.0, "wheel": 1.0, "body": 1.0}

ROVER = '''
# BubbleRob, with the exact sizes of CoppeliaSim's tutorial.
[[object]]
name = "{p}bubbleRob"
alias = "bubbleRob"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [{x}, {y}, 0.12]
dynamic = true
mass = 1.0
friction = {body_friction}                  # see FRICTION in generate.py
color = [0.2, 0.5, 0.9]
model_base = true
collision_group = 2
collision_mask = 0xFFFFFFFE   # never collides with its own caster (group 1)
{script}
[[object]]
name = "{p}leftMotor"
alias = "leftMotor"
kind = "joint"
joint = "revolute"
parent = "{p}bubbleRob"
position = [0.05, 0.1, -0.08]
orientation_deg = [-90, 0, 0]   # axis along +Y: a positive speed drives towards +X
mode = "velocity"
max_force = 2.5                 # N·m
kd = 20.0                       # N·m·s/rad: a stiff velocity servo

[[object]]
name = "{p}leftWheel"
alias = "leftWheel"
kind = "shape"
shape = "cylinder"
radius = 0.04
length = 0.02
parent = "{p}leftMotor"
dynamic = true
mass = 0.8                      # x8, as in the tutorial, for stability
friction = {wheel_friction}
color = [0.1, 0.1, 0.1]

[[object]]
name = "{p}rightMotor"
alias = "rightMotor"
kind = "joint"
joint = "revolute"
parent = "{p}bubbleRob"
position = [0.05, -0.1, -0.08]
orientation_deg = [-90, 0, 0]
mode = "velocity"
max_force = 2.5
kd = 20.0

[[object]]
name = "{p}rightWheel"
alias = "rightWheel"
kind = "shape"
shape = "cylinder"
radius = 0.04
length = 0.02
parent = "{p}rightMotor"
dynamic = true
mass = 0.8
friction = {wheel_friction}
color = [0.1, 0.1, 0.1]

[[object]]
name = "{p}connection"
alias = "connection"
kind = "force_sensor"
parent = "{p}bubbleRob"
position = [-0.07, 0, -0.07]

[[object]]
name = "{p}slider"
alias = "slider"
kind = "shape"
shape = "sphere"
radius = 0.025
parent = "{p}connection"
position = [0, 0, -0.025]
dynamic = true
mass = 0.5
friction = {caster_friction}                  # no-friction caster (on a no-friction floor)
color = [0.1, 0.1, 0.1]
collision_group = 1
collision_mask = 0xFFFFFFFD     # never collides with the body (group 2)

[[object]]
name = "{p}sensingNose"
alias = "sensingNose"
kind = "proximity_sensor"
sensor = "cone"
parent = "{p}bubbleRob"
position = [0.1, 0, 0]
orientation_deg = [0, 90, 90]   # detection axis (local +Z) along the body's +X
range = 0.15
angle_deg = 30
offset = 0.005

[[object]]
name = "{p}visionSensor"
alias = "visionSensor"
kind = "vision_sensor"
parent = "{p}sensingNose"
{vision_script}
resolution = [256, 256]
fov_deg = 60
near = 0.01
far = 1.0

[[object]]
name = "{p}graph"
alias = "graph"
kind = "graph"
parent = "{p}bubbleRob"
position = [0, 0, -0.115]
'''

OBSTACLE_RADIUS = 0.05
# Obstacle centres (m, from the arena centre); the tutorial leaves the number and places to
# the user. None is nearer than MIN_GAP to a wall or to another obstacle.
OBSTACLES = [(1.0, 0.3), (1.2, -0.9), (0.2, 1.3), (-1.1, 0.9), (-1.4, -0.6),
             (-0.3, -1.5), (1.8, 1.6), (-1.8, 1.8), (0.7, -1.8), (1.8, -0.4)]
WALLS = [(0, 2.45, 5, 0.1), (0, -2.45, 5, 0.1), (2.45, 0, 0.1, 4.8), (-2.45, 0, 0.1, 4.8)]

# Narrowest free gap the rover can always leave. In a narrower one it can back into one
# side while its nose still sees the other, and re-arm the back-up forever: 0.2 m of body,
# 0.155 m of sensor reach (offset + range), and the 0.15 m one 4 s back-up covers (the
# wheel rims at -speed/2 and -speed/8 of 0.122 m/s average 0.038 m/s).
MIN_GAP = 0.2 + 0.155 + 0.15


def arena(cx, cy, p):
    out = []
    for i, (x, y) in enumerate(OBSTACLES):
        out.append(f'''
[[object]]
name = "{p}obstacle{i}"
alias = "obstacle"
kind = "shape"
shape = "cylinder"
radius = {OBSTACLE_RADIUS:g}
length = 0.2
position = [{cx + x:g}, {cy + y:g}, 0.1]
friction = {FRICTION["obstacle"]!r}
color = [0.85, 0.85, 0.85]
''')
    for i, (x, y, sx, sy) in enumerate(WALLS):
        out.append(f'''
[[object]]
name = "{p}wall{i}"
alias = "wall"
kind = "shape"
shape = "box"
size = [{sx:g}, {sy:g}, 0.2]
position = [{cx + x:g}, {cy + y:g}, 0.1]
friction = {FRICTION["obstacle"]!r}
color = [0.6, 0.6, 0.65]
''')
    return "".join(out)


HEADER = '''# {title}
# Generated by assets/scenes/generate.py: edit that script and re-run it.
# Angles in this file are in degrees; the sim API uses radians.

[simulation]
dt = 0.05        # s, CoppeliaSim's default step
substeps = 10    # physics substeps per step

[floor]
size = {floor}   # m
friction = {floor_friction}   # so that the caster slides: see FRICTION in generate.py
'''

ROVER_SCRIPT = 'script = "../../scripts/{name}"\n'


def rover(p, x, y, script, vision_script="edge_detect.lua"):
    s = ROVER_SCRIPT.format(name=script) if script else ""
    v = ROVER_SCRIPT.format(name=vision_script) if vision_script else ""
    return ROVER.format(p=p, x=x, y=y, script=s, vision_script=v,
                        body_friction=FRICTION["body"], wheel_friction=FRICTION["wheel"],
                        caster_friction=FRICTION["caster"])


ARM = '''
[[robot]]
name = "arm6"
urdf = "../robots/arm6/arm6.urdf"
position = [{x}, {y}, 0]
joint_mode = "kinematic"
initial = {{ joint5 = -90 }}   # the paper's start pose: tool pointing down
{script}
[[object]]
name = "tip_frame"
alias = "tip"
kind = "dummy"
parent = "arm6/tip"

[[object]]
name = "target"
kind = "dummy"
position = [{tx}, {y}, 0.652]
orientation_deg = [0, 90, 0]
'''


def check_friction():
    """Every contact gets the tutorial's coefficient under gantry's mean rule."""
    for (a, b), tutorial in TUTORIAL_CONTACTS.items():
        mean = (FRICTION[a] + FRICTION[b]) / 2
        assert abs(mean - tutorial) < 1e-9, f"{a}-{b} friction {mean}, the tutorial's is {tutorial}"


def check_spacing():
    """No obstacle leaves a gap narrower than MIN_GAP to a wall or another obstacle."""
    for i, (x, y) in enumerate(OBSTACLES):
        for wx, wy, sx, sy in WALLS:
            gap = math.hypot(max(abs(x - wx) - sx / 2, 0), max(abs(y - wy) - sy / 2, 0)) - OBSTACLE_RADIUS
            assert gap >= MIN_GAP, f"obstacle {i} is {gap:.3f} m from a wall (< {MIN_GAP:.3f} m)"
        for j, (x2, y2) in enumerate(OBSTACLES[:i]):
            gap = math.hypot(x - x2, y - y2) - 2 * OBSTACLE_RADIUS
            assert gap >= MIN_GAP, f"obstacles {j} and {i} are {gap:.3f} m apart (< {MIN_GAP:.3f} m)"


def main():
    check_friction()
    check_spacing()
    bubble = HEADER.format(title="BubbleRob in a 5 x 5 m arena with cylinder obstacles.", floor="[5, 5]",
                           floor_friction=FRICTION["floor"])
    bubble += rover("", 0, 0, "bubble_rob.lua") + arena(0, 0, "")
    (HERE / "bubble_rob.toml").write_text(bubble)
    show = HEADER.format(title="The showroom: the paper's arm beside the BubbleRob arena.", floor="[9, 6]",
                         floor_friction=FRICTION["floor"])
    show += ARM.format(x=-3.2, y=0, tx=-3.2 + 0.45, script='script = "../../scripts/fk_server.lua"\n')
    show += rover("", 1.3, 0, "bubble_rob.lua") + arena(1.3, 0, "")
    (HERE / "showroom.toml").write_text(show)
    ros = HEADER.format(title="BubbleRob driven over ROS 2: /cmd_vel in, its sensor and pose out (docs/ros2.md).",
                        floor="[5, 5]", floor_friction=FRICTION["floor"])
    ros += rover("", 0, 0, "bubble_rob_ros2.lua", vision_script="") + arena(0, 0, "")
    (HERE / "bubble_rob_ros2.toml").write_text(ros)


if __name__ == "__main__":
    main()
