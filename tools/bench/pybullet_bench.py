#!/usr/bin/env python3
"""The PyBullet side of gantry's benchmark (issue 8), on the same robot files.

1. Arm: assets/robots/arm6/arm6.urdf, fixed base, dt = 1/240 s, one substep, a new
   position target for every joint every step (setJointMotorControlArray, DIRECT mode),
   10,000 steps. The trajectory is scripts/bench/arm_tracking.lua's: joint i follows
   A_i sin(2 pi f_i t); the target sent before a step is the trajectory at the step's end
   and the error is read after it. Reports steps/s and the RMS and largest joint error.
2. Rovers: assets/robots/bubble_rob/bubble_rob.urdf, 1, 10, 50 and 100 of them on the
   grid benches/sim.rs builds for gantry (2 m cells, two cylinder obstacles each),
   dt = 0.05 s with 10 substeps, each rover running scripts/bench/rover_controller.lua's
   logic with one ray test per rover per step. Reports steps/s and real-time factor.

Prints one JSON object on stdout; tools/bench/report.py puts it beside gantry's figures.
    .venv/bin/python tools/bench/pybullet_bench.py [--seconds 3] [--arm-steps 10000]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import pybullet as p

ROOT = Path(__file__).resolve().parents[2]
ARM = ROOT / "assets/robots/arm6/arm6.urdf"
ROVER = ROOT / "assets/robots/bubble_rob/bubble_rob.urdf"

# scripts/bench/arm_tracking.lua
AMPLITUDE = [0.6, 0.5, 0.4, 0.8, 0.6, 1.0]  # rad
FREQUENCY = [0.25, 0.3, 0.35, 0.4, 0.45, 0.5]  # Hz

# scripts/bench/rover_controller.lua and assets/scenes/bubble_rob.toml
SPEED = 175 * math.pi / 180  # rad/s
WHEEL_FORCE = 2.5  # N·m
NOSE = (0.1, 0.0, 0.0)  # sensor origin in the body frame, m
SENSOR_RANGE = 0.005 + 0.15  # offset + range, m


def arm(steps: int) -> dict:
    client = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    dt = 1.0 / 240.0
    p.setTimeStep(dt, physicsClientId=client)
    # The URDF's inertials, as gantry uses them (PyBullet's default recomputes them from
    # the collision shapes).
    robot = p.loadURDF(str(ARM), useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
    joints, efforts = [], []
    for j in range(p.getNumJoints(robot, physicsClientId=client)):
        info = p.getJointInfo(robot, j, physicsClientId=client)
        if info[2] == p.JOINT_REVOLUTE:
            joints.append(j)
            efforts.append(info[10])
    assert len(joints) == 6, f"arm6 has six revolute joints, found {len(joints)}"
    sum_sq, count, max_err = 0.0, 0, 0.0
    t0 = time.perf_counter()
    for k in range(steps):
        t = (k + 1) * dt
        targets = [a * math.sin(2 * math.pi * f * t) for a, f in zip(AMPLITUDE, FREQUENCY)]
        p.setJointMotorControlArray(
            robot, joints, p.POSITION_CONTROL, targetPositions=targets, forces=efforts, physicsClientId=client
        )
        p.stepSimulation(physicsClientId=client)
        for (q, *_), target in zip(p.getJointStates(robot, joints, physicsClientId=client), targets):
            e = abs(q - target)
            sum_sq += e * e
            count += 1
            max_err = max(max_err, e)
    wall = time.perf_counter() - t0
    p.disconnect(client)
    return {
        "steps": steps,
        "steps_per_s": steps / wall,
        "rms_error_rad": math.sqrt(sum_sq / count),
        "max_error_rad": max_err,
    }


def rover_world(n: int, client: int) -> list[tuple[int, int, int]]:
    """n rovers on benches/sim.rs's grid; returns (rover, left joint, right joint)."""
    side = math.ceil(math.sqrt(n))
    cell = 2.0
    extent = side * cell + 1.0
    floor = p.createCollisionShape(p.GEOM_BOX, halfExtents=[extent / 2, extent / 2, 0.05], physicsClientId=client)
    p.createMultiBody(0, floor, basePosition=[0, 0, -0.05], physicsClientId=client)
    post = p.createCollisionShape(p.GEOM_CYLINDER, radius=0.05, height=0.2, physicsClientId=client)
    # Walls along the floor's edges, 0.1 m thick and 0.2 m high, as in benches/sim.rs.
    h = extent / 2
    for x, y, sx, sy in [(0, h, extent, 0.1), (0, -h, extent, 0.1), (h, 0, 0.1, extent), (-h, 0, 0.1, extent)]:
        wall = p.createCollisionShape(p.GEOM_BOX, halfExtents=[sx / 2, sy / 2, 0.1], physicsClientId=client)
        p.createMultiBody(0, wall, basePosition=[x, y, 0.1], physicsClientId=client)
    rovers = []
    for i in range(n):
        cx = (i % side) * cell - extent / 2 + 1.5
        cy = (i // side) * cell - extent / 2 + 1.5
        robot = p.loadURDF(str(ROVER), [cx, cy, 0.12], flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        names = {p.getJointInfo(robot, j, physicsClientId=client)[1].decode(): j for j in range(p.getNumJoints(robot, physicsClientId=client))}
        rovers.append((robot, names["leftMotor"], names["rightMotor"]))
        for dx, dy in [(0.7, 0.1), (-0.2, 0.75)]:
            p.createMultiBody(0, post, basePosition=[cx + dx, cy + dy, 0.1], physicsClientId=client)
    return rovers


def rovers(n: int, seconds: float) -> dict:
    client = p.connect(p.DIRECT)
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    dt = 0.05
    p.setTimeStep(dt, physicsClientId=client)
    p.setPhysicsEngineParameter(numSubSteps=10, physicsClientId=client)
    fleet = rover_world(n, client)
    back_until = [-1.0] * n
    steps, sim_time = 0, 0.0

    def step() -> None:
        nonlocal steps, sim_time
        for i, (robot, left, right) in enumerate(fleet):
            pos, orn = p.getBasePositionAndOrientation(robot, physicsClientId=client)
            rot = p.getMatrixFromQuaternion(orn)
            heading = (rot[0], rot[3], rot[6])  # body +X in the world
            start = [pos[k] + rot[3 * k] * NOSE[0] for k in range(3)]
            end = [start[k] + heading[k] * SENSOR_RANGE for k in range(3)]
            hit = p.rayTest(start, end, physicsClientId=client)[0]
            if hit[0] >= 0 and hit[0] != robot:
                back_until[i] = sim_time + 4
            if back_until[i] < sim_time:
                v = (SPEED, SPEED)
            else:
                v = (-SPEED / 2, -SPEED / 8)
            p.setJointMotorControlArray(
                robot, [left, right], p.VELOCITY_CONTROL, targetVelocities=v, forces=[WHEEL_FORCE] * 2, physicsClientId=client
            )
        p.stepSimulation(physicsClientId=client)
        steps += 1
        sim_time = steps * dt

    for _ in range(10):
        step()
    t0 = time.perf_counter()
    counted = 0
    while time.perf_counter() - t0 < seconds:
        step()
        counted += 1
    wall = time.perf_counter() - t0
    p.disconnect(client)
    rate = counted / wall
    return {"rovers": n, "steps_per_s": rate, "rtf": rate * dt}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=3.0, help="measuring time per rover figure")
    ap.add_argument("--arm-steps", type=int, default=10_000)
    args = ap.parse_args()
    out = {
        "pybullet": p.getAPIVersion(),
        "arm": arm(args.arm_steps),
        "rovers": [rovers(n, args.seconds) for n in (1, 10, 50, 100)],
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
