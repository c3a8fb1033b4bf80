#!/usr/bin/env python3
"""PyRep on gantry: seconds per `pr.step()` (issue 50, item 4).

Two figures, each the median of `--repeat` runs of `--steps` steps, in this process:
  * `panda`: PyRep's own example scene `scene_panda_reach_target.ttt` (a Panda, its
    gripper and a target; no cameras), stepped with `pr.step()` while the arm follows a
    joint-velocity command, as PyRep's reach example does. Users report 0.0055-0.008 s
    per step on CoppeliaSim 4.1; the issue's bar is 20x faster (0.000275 s).
  * `rlbench_obs`: the same scene with RLBench's default observation added: five
    cameras (left and right shoulder, overhead, wrist, front) and their five mask twins,
    128 x 128, explicitly handled as RLBench does; each step renders and reads RGB and
    depth of the five and the colour-coded masks of the twins (handle = R + 256 G +
    65536 B), and reads the Panda's joint positions, velocities and forces. The bar is
    10 ms per step (users report about 0.12 s on CoppeliaSim).

    .venv/bin/python tools/bench/pyrep_bench.py [--steps 2000] [--repeat 3] [--json out.json]
Needs the `gantry` wheel and the `pyrep` package (python/gantry-pyrep) installed, and
PyRep's scene in ../shared/coppelia-files/.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO.parent / "shared" / "coppelia-files" / "PyRep__scene_panda_reach_target.ttt"
CAMERAS = {
    # name: (position m, orientation rad), placed around the table as RLBench's are.
    "left_shoulder": ([0.3, 0.6, 1.5], [2.4, 0.0, -2.6]),
    "right_shoulder": ([0.3, -0.6, 1.5], [-2.4, 0.0, -0.5]),
    "overhead": ([0.9, 0.0, 2.0], [3.14, 0.0, 1.57]),
    "front": ([1.8, 0.0, 1.4], [2.2, 1.57, 0.0]),
    "wrist": None,  # on the gripper
}


def panda_joints():
    from pyrep.objects.joint import Joint

    return [Joint(f"Panda_joint{k}") for k in range(1, 8)]


def run_panda(steps: int) -> float:
    from pyrep import PyRep

    pr = PyRep()
    pr.launch(str(SCENE), headless=True)
    pr.start()
    joints = panda_joints()
    for j in joints:
        j.set_joint_target_velocity(0.1)
    t0 = time.perf_counter()
    for _ in range(steps):
        pr.step()
    dt = (time.perf_counter() - t0) / steps
    pr.stop()
    pr.shutdown()
    return dt


def run_rlbench_obs(steps: int) -> float:
    from pyrep import PyRep
    from pyrep.const import RenderMode
    from pyrep.objects.dummy import Dummy
    from pyrep.objects.vision_sensor import VisionSensor

    pr = PyRep()
    pr.launch(str(SCENE), headless=True)
    tip = Dummy("Panda_tip")
    sensors = []
    for name, pose in CAMERAS.items():
        pair = []
        for mode in (RenderMode.OPENGL3, RenderMode.OPENGL_COLOR_CODED):
            cam = VisionSensor.create([128, 128], explicit_handling=True, view_angle=60.0,
                                      near_clipping_plane=0.01, far_clipping_plane=4.5, render_mode=mode)
            if pose is None:
                cam.set_parent(tip, keep_in_place=False)
                cam.set_position([0.0, 0.0, -0.05], relative_to=tip)
            else:
                cam.set_position(pose[0])
                cam.set_orientation(pose[1])
            pair.append(cam)
        sensors.append(pair)
    pr.start()
    joints = panda_joints()
    for j in joints:
        j.set_joint_target_velocity(0.1)
    t0 = time.perf_counter()
    for _ in range(steps):
        pr.step()
        for cam, mask_cam in sensors:
            cam.handle_explicitly()
            rgb = cam.capture_rgb()
            depth = cam.capture_depth()
            mask_cam.handle_explicitly()
            coded = (mask_cam.capture_rgb() * 255.0 + 0.5).astype(np.uint32)
            mask = coded[..., 0] + 256 * coded[..., 1] + 65536 * coded[..., 2]
            assert rgb.shape == (128, 128, 3) and depth.shape == (128, 128) and mask.shape == (128, 128)
        state = [(j.get_joint_position(), j.get_joint_velocity(), j.get_joint_force()) for j in joints]
        assert len(state) == 7
    dt = (time.perf_counter() - t0) / steps
    pr.stop()
    pr.shutdown()
    return dt


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=2000)
    p.add_argument("--obs-steps", type=int, default=300)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--json", type=Path)
    a = p.parse_args()
    if not SCENE.is_file():
        print(f"pyrep_bench: PyRep's scene is not at {SCENE}", file=sys.stderr)
        return 1
    panda = [run_panda(a.steps) for _ in range(a.repeat)]
    obs = [run_rlbench_obs(a.obs_steps) for _ in range(a.repeat)]
    out = {
        "panda_s_per_step": statistics.median(panda),
        "panda_runs": panda,
        "rlbench_obs_s_per_step": statistics.median(obs),
        "rlbench_obs_runs": obs,
    }
    print(f"| figure | gantry (median of {a.repeat}) | CoppeliaSim 4.1 as users report | bar |")
    print("|---|---|---|---|")
    print(f"| `pr.step()`, Panda, no cameras | {out['panda_s_per_step'] * 1e6:.0f} us "
          f"({0.0055 / out['panda_s_per_step']:.0f}x faster than 5.5 ms) | 5.5-8 ms | 275 us (20x) |")
    print(f"| step + RLBench's default observation (5 cameras + 5 masks, 128 x 128) | "
          f"{out['rlbench_obs_s_per_step'] * 1e3:.2f} ms | about 120 ms | 10 ms |")
    if a.json:
        a.json.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
