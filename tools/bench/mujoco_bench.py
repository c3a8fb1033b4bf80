#!/usr/bin/env python3
"""gantry against MuJoCo (and PyBullet) on the public mesh arms and a wheeled robot (issue 33).

The arms, their trajectory and the error measure are tools/bench/public_robots.py's
(imported, not copied): the same URDF files from `pybullet_data` and
`example-robot-data`, fixed base, dt = 1/240 s, gravity on, no floor, every movable joint
following its sinusoid, the target for step k being q(k dt), the error read after the
step. Each round runs every arm in every simulator and mode below, one after another
(`--repeat` rounds; steps/s are medians, ratios the medians of the same round's ratios):

* gantry, Lua loop: the release binary with the generated scene and
  scripts/bench/arm_tracking_any.lua (public_robots.run_gantry; the binary's own steps/s).
* gantry, Python loop: the in-process package (`gantry.Client(scene, realtime=False,
  scripts=False)`), per step `sim.setJointTargetPosition` for every joint,
  `client.advance(1)`, then `sim.getJointPosition` for every joint.
* gantry, engine only: `client.advance(n)` in-process with the Lua script setting the
  targets (gantry has no call that plays a precomputed table of targets, and its Lua
  hooks run inside the step, so this is the nearest to MuJoCo's rollout).
* MuJoCo, Python loop: per step `data.ctrl[:] = controls` (the targets, see the servo
  below), `mujoco.mj_step`, then `data.qpos` read for every joint.
* MuJoCo, engine only: `mujoco.rollout.rollout` over the precomputed table of targets
  (one trajectory, one thread); errors from the states it returns, outside the timing.
* PyBullet: public_robots.run_pybullet, for reference.

The MuJoCo model is the URDF itself, read by MuJoCo's URDF compiler from a copy made in
memory: visual elements dropped, mesh references resolved to absolute paths as gantry
resolves them (`package://`), and `<mujoco><compiler strippath="false"
discardvisual="true" balanceinertia="true"/></mujoco>` added. MuJoCo reads STL, OBJ and
MSH meshes but not COLLADA: the Kinova's DAE collision meshes are converted to STL at
run time with trimesh (and pycollada) into a temporary directory; without trimesh the
arm is skipped with its reason printed. MuJoCo takes a mesh file as one mesh and collides
with its convex hull, where gantry and PyBullet take one hull per OBJ part or DAE
geometry (the xArm6's convex decompositions, the Kinova's multi-part links).

Every joint gets a MuJoCo position actuator (`set_to_position(kp, kv)`, gain kp, bias
-kp q - kv qdot) with gantry's default gains for URDF robots, kp = 2000 N m/rad (N/m) and
kv = 100 N m s/rad (crates/scene/src/scene/urdf.rs, DEFAULT_KP and DEFAULT_KD), its
force clamped to the URDF's effort (`forcelimited`, `forcerange` = +-effort; 100 where
the URDF gives none, as gantry does). gantry's servo also feeds the reference's velocity
forward, force = kp (r - q) + kv (v - qdot) with v = (r_k - r_(k-1)) / dt for a joint
with a <limit velocity> (every joint here; crates/world/src/world/object.rs,
advance_reference). MuJoCo is given the same law through the control: ctrl = r + (kv /
kp) v, so that kp ctrl - kp q - kv qdot is gantry's force (class Servo); without it,
MuJoCo lags the sinusoids and tracks 3-10x worse. MuJoCo's joints start at the
centres moving at the trajectory's initial velocity, gantry's and PyBullet's at rest:
started at rest, the velocity term asks for more than the effort limit at the first
step, and on a light wrist (the xArm7's joint 7, 1.3e-4 kg m^2 against 20 N m) MuJoCo's
clamped actuator, integrated explicitly, then chatters at its limit for the whole run
(0.33 rad RMS on that joint); rapier's motor bounds its impulse inside the solver and
settles. The integrator is `implicitfast`,
MuJoCo's recommendation for position actuators: it integrates the kv term implicitly,
which keeps this stiff servo stable at 1/240 s on light wrist links (rapier's motor
is implicit too). Both errors are reported, and a MuJoCo run is flagged `unstable` when
its RMS error exceeds 1 rad or is not finite (its steps/s then mean nothing).

Contacts: gantry and PyBullet never let links of one robot collide (the default of
both); MuJoCo by default leaves out only parent-child pairs, and the public meshes'
overlapping hulls then press on each other (4 contacts per step on the xArm6 and the
KUKA, 46 on the SO-101; the xArm6 then tracks 50x worse). By default every geom of the
robot gets contype 1 and conaffinity 0, so no pair of them collides, as in the other two
(a wheeled robot's floor, contype 0 and conaffinity 1, still touches them);
`--mujoco-self-collision` keeps MuJoCo's default instead. The mean number of contacts
per step is reported.

The wheeled robot is pybullet_data's Clearpath Husky (box and cylinder collision
shapes, four continuous wheel joints) with a free base, starting at rest at the origin on
a floor (gantry: `[floor]` 20 x 20 m, joint_mode = "velocity", the script
scripts/bench/arm_tracking_any.lua in velocity mode; MuJoCo: a free joint on the root
body and a plane; PyBullet: pybullet_data's plane.urdf). The left wheels' target
velocity is 3 sin(2 pi 0.1 t) rad/s, the right ones' 2 sin(2 pi 0.1 t), so it drives an
arc forth and back; the error is each wheel's velocity error (rad/s) after the step. gantry's velocity
controller is force = kd (target - qdot) with its default kd = 10 N m s/rad in velocity
mode and the URDF's effort (none: 100 N m); MuJoCo gets the same as a velocity actuator
(kv 10, forcerange +-100), PyBullet its VELOCITY_CONTROL with forces 100. Each simulator
keeps its own default friction. MuJoCo's URDF reader refuses the Husky's xacro leftovers
("$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)", the IMU link's origin); they are replaced by
their defaults in the in-memory copy, as xacro would with the variable unset.

Prints one JSON object on stdout (tools/bench/report.py --mujoco-only turns it into
tables) and one progress line per run on stderr. GANTRY_BIN selects the binary (default
target/release/gantry); the in-process package is the installed `gantry` wheel.

    .venv/bin/python tools/bench/mujoco_bench.py [--arms xarm7,ur5] [--mobile husky] [--steps 10000] \\
        [--repeat 3] > target/bench/mujoco.json
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import statistics
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Callable

import numpy as np

import public_robots as pr

KP = 2000.0  # N m/rad: gantry's DEFAULT_KP for URDF joints
KV = 100.0  # N m s/rad: gantry's DEFAULT_KD
UNSTABLE_RMS = 1.0  # rad: a tracking error this large means the simulation diverged
# Lua appended to the generated script: the error sums, for the in-process caller of
# client.advance(n), which does not see the script's printed lines.
SCRIPT_TAIL = """
-- Appended by tools/bench/mujoco_bench.py: the per-joint sums so far, for an in-process
-- caller (client.getScriptFunctions(robot).benchErrors()).
function benchErrors()
    return {sumSq, maxErr, k}
end
"""
# Wheeled robots: name -> (PyPI package, URDF path in its robot folder, what it is).
MOBILE: dict[str, tuple[str, str, str]] = {
    "husky": ("pybullet_data", "husky/husky.urdf", "Clearpath Husky, 4 driven wheels"),
}
WHEEL_SPEED = {"left": 3.0, "right": 2.0}  # rad/s, amplitude of a wheel's target velocity
WHEEL_FREQUENCY = 0.1  # Hz: the robot drives an arc forth and back, within a metre of the start
KV_VELOCITY = 10.0  # N m s/rad: gantry's damping in velocity mode, the whole controller
FLOOR_SIZE = 20.0  # m
OPTENV = re.compile(r"\$\(optenv \S+ ([^)]*)\)")
MODES = ("gantry_lua", "gantry_python", "gantry_advance", "mujoco_python", "mujoco_rollout", "pybullet")


class Unsupported(Exception):
    """The arm cannot be loaded into MuJoCo as it is published (the reason is the text)."""


# ---------------------------------------------------------------------------------------
# MuJoCo


def mujoco_model(urdf: pr.Urdf, self_collision: bool, mobile: bool = False) -> tuple[Any, list[int]]:
    """The robot as a MuJoCo model with an actuator per benchmark joint (position for an
    arm; velocity for a wheeled robot, which also gets a free base and a floor), and
    each joint's index in qpos (benchmark order)."""
    import mujoco

    root = ET.parse(urdf.path).getroot()
    # xacro leftovers (the Husky's IMU origin is "$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)"):
    # what xacro would write with the variable unset, the default.
    for element in root.iter():
        for key, value in element.attrib.items():
            if "$(" in value:
                element.set(key, OPTENV.sub(r"\1", value))
    for link in root.findall("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for collision in link.findall("collision"):
            geometry = collision.find("geometry")[0]
            if geometry.tag != "mesh":
                continue
            file = pr.mesh_file(urdf.path, geometry.get("filename"))
            if file.suffix.lower() == ".dae":
                file = dae_as_stl(file)
            elif file.suffix.lower() not in (".stl", ".obj", ".msh"):
                raise Unsupported(f"MuJoCo reads STL, OBJ and MSH meshes, not {file.suffix} ({file.name})")
            geometry.set("filename", str(file))
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", strippath="false", discardvisual="true", balanceinertia="true")
    spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    spec.option.timestep = pr.DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    if not self_collision:
        for geom in spec.geoms:
            geom.contype, geom.conaffinity = 1, 0
    if mobile:
        spec.worldbody.first_body().add_freejoint()
        # contype 0 / conaffinity 1: touches the robot's geoms (contype 1) in either case
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[FLOOR_SIZE / 2, FLOOR_SIZE / 2, 0.1],
                                contype=0, conaffinity=1)
    for j in urdf.joints:
        actuator = spec.add_actuator(name=j.name, target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        if mobile:
            actuator.set_to_velocity(kv=KV_VELOCITY)
        else:
            actuator.set_to_position(kp=KP, kv=KV)
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.forcerange = [-j.effort, j.effort]
    model = spec.compile()
    return model, [int(model.jnt_qposadr[model.joint(j.name).id]) for j in urdf.joints]


_converted: dict[Path, Path] = {}
_convert_dir: tempfile.TemporaryDirectory | None = None


def dae_as_stl(file: Path) -> Path:
    """A COLLADA mesh, which MuJoCo cannot read, as an STL file in a temporary directory
    (removed when the process exits; never in the repository), converted once per run by
    trimesh (with pycollada): every part of the file with its node transform applied,
    in one mesh."""
    global _convert_dir
    if file in _converted:
        return _converted[file]
    try:
        import trimesh
    except ImportError as e:
        raise Unsupported(f"MuJoCo does not read COLLADA ({file.name}), and trimesh is not installed "
                          "to convert it: pip install -r tools/bench/requirements.txt") from e
    if _convert_dir is None:
        _convert_dir = tempfile.TemporaryDirectory(prefix="gantry-bench-dae-")
    out = Path(_convert_dir.name) / f"{len(_converted)}_{file.stem}.stl"
    trimesh.load(file, force="mesh").export(out)
    _converted[file] = out
    return out


class Servo:
    """gantry's servo law as MuJoCo controls: each target plus kv / kp times the
    reference's velocity, the target's change over the last step (from the start
    position at the first step), as gantry's advance_reference computes it."""

    def __init__(self, urdf: pr.Urdf):
        self.previous = [j.start(urdf.joints) for j in urdf.joints]
        self.lead = KV / KP / pr.DT

    def controls(self, targets: list[float]) -> list[float]:
        lead = self.lead
        out = [q + lead * (q - p) for q, p in zip(targets, self.previous)]
        self.previous = targets
        return out


def mujoco_start(urdf: pr.Urdf, self_collision: bool, mobile: bool) -> tuple[Any, Any, list[int], float]:
    """Model, data at the trajectory's start, the benchmark joints' indices in qpos (in
    qvel for a wheeled robot), and the load time (s)."""
    import mujoco

    t0 = time.perf_counter()
    model, qpos = mujoco_model(urdf, self_collision, mobile)
    data = mujoco.MjData(model)
    load_s = time.perf_counter() - t0
    dofs = [int(model.jnt_dofadr[model.joint(j.name).id]) for j in urdf.joints]
    if mobile:  # at rest at the origin, as in the other two
        mujoco.mj_forward(model, data)
        return model, data, dofs, load_s
    # Moving at the trajectory's velocity (see the module's docstring): started at rest,
    # the servo's velocity term saturates a light wrist's effort on the first step, and
    # MuJoCo's clamped actuator, explicit, then chatters at its limit for the whole run.
    speed = [j.amplitude * 2 * math.pi * j.frequency for j in urdf.joints]
    for i, (j, a) in enumerate(zip(urdf.joints, qpos)):
        data.qpos[a] = j.start(urdf.joints)
        data.qvel[dofs[i]] = speed[i] if j.mimic is None else j.mimic[1] * speed[j.mimic[0]]
    mujoco.mj_forward(model, data)
    return model, data, qpos, load_s


def flag_unstable(result: dict) -> dict:
    rms = result["rms_error"]
    if not math.isfinite(rms) or rms > UNSTABLE_RMS:
        result["unstable"] = True
    return result


def run_mujoco_python(urdf: pr.Urdf, steps: int, self_collision: bool, mobile: bool = False) -> dict:
    """MuJoCo with a Python loop: targets into data.ctrl, mj_step, joints read back."""
    import mujoco

    model, data, qpos, load_s = mujoco_start(urdf, self_collision, mobile)
    targets_at, step, clock = pr.Trajectory(urdf).targets, mujoco.mj_step, time.perf_counter
    controls = (lambda targets: targets) if mobile else Servo(urdf).controls
    ctrl, q = data.ctrl, (data.qvel if mobile else data.qpos)
    n = len(qpos)
    sum_sq, largest, in_step, contacts = [0.0] * n, [0.0] * n, 0.0, 0
    t0 = clock()
    for k in range(1, steps + 1):
        targets = targets_at(k * pr.DT)
        ctrl[:] = controls(targets)
        ts = clock()
        step(model, data)
        in_step += clock() - ts
        contacts += data.ncon
        for i, a in enumerate(qpos):
            e = abs(float(q[a]) - targets[i])
            sum_sq[i] += e * e
            if e > largest[i]:
                largest[i] = e
    wall = clock() - t0
    return flag_unstable({
        "steps": steps,
        "steps_per_s": steps / wall,
        "wall_s": wall,
        "load_s": load_s,
        # mj_step alone, without the Python around it
        "step_only_steps_per_s": steps / in_step,
        "contacts_per_step": contacts / steps,
        # the root body's position at the end (the free joint's), to compare with gantry's
        **({"base_end_m": [float(x) for x in data.qpos[:3]]} if mobile else {}),
        **pr.errors(urdf, steps, sum_sq, largest),
    })


def run_mujoco_rollout(urdf: pr.Urdf, steps: int, self_collision: bool, mobile: bool = False) -> dict:
    """MuJoCo's engine alone: one rollout over the precomputed targets."""
    import mujoco
    from mujoco import rollout

    model, data, qpos, load_s = mujoco_start(urdf, self_collision, mobile)
    full = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(model, full))
    mujoco.mj_getState(model, data, state0, full)
    targets_at = pr.Trajectory(urdf).targets
    controls = (lambda targets: targets) if mobile else Servo(urdf).controls
    targets = np.array([targets_at(k * pr.DT) for k in range(1, steps + 1)])
    control = np.array([[controls(list(row)) for row in targets]])
    states = np.empty((1, steps, state0.size))
    t0 = time.perf_counter()
    rollout.rollout(model, data, state0[None], control, state=states)
    wall = time.perf_counter() - t0
    # A full-physics state is time, qpos, qvel, then the rest (mjtState's bit order).
    q = states[0][:, 1 + (model.nq if mobile else 0) + np.array(qpos)]
    e = np.abs(q - targets)
    return flag_unstable({
        "steps": steps,
        "steps_per_s": steps / wall,
        "wall_s": wall,
        "load_s": load_s,
        **pr.errors(urdf, steps, [float(x) for x in (e * e).sum(axis=0)], [float(x) for x in e.max(axis=0)]),
    })


# ---------------------------------------------------------------------------------------
# gantry in-process


def gantry_client(scene: Path, package_paths: list[Path], scripts: bool) -> Any:
    import gantry

    return gantry.Client(scene, realtime=False, scripts=scripts, package_paths=package_paths)


def joint_handles(sim: Any, robot: str, urdf: pr.Urdf) -> list[int]:
    """The robot's joint handles in benchmark order (its joints' aliases are the URDF names)."""
    base = sim.getObject("/" + robot)
    by_name = {sim.getObjectAlias(h, -1): h for h in sim.getObjectsInTree(base, sim.object_joint_type)}
    return [by_name[j.name] for j in urdf.joints]


def run_gantry_python(
    robot: str, scene: Path, urdf: pr.Urdf, steps: int, package_paths: list[Path], mobile: bool = False
) -> dict:
    """gantry in-process with a Python loop: setJointTargetPosition per joint,
    advance(1), getJointPosition per joint (the velocity calls for a wheeled robot)."""
    t0 = time.perf_counter()
    with gantry_client(scene, package_paths, scripts=False) as client:
        sim = client.require("sim")
        handles = joint_handles(sim, robot, urdf)
        load_s = time.perf_counter() - t0
        start = [sim.getJointPosition(h) for h in handles]
        if any(abs(q - j.start(urdf.joints)) > 1e-6 for q, j in zip(start, urdf.joints)):
            return {"error": f"joints start at {start}, not at the trajectory's centres"}
        targets_at, advance, clock = pr.Trajectory(urdf).targets, client.advance, time.perf_counter
        set_target, get_position = (
            (sim.setJointTargetVelocity, sim.getJointVelocity) if mobile
            else (sim.setJointTargetPosition, sim.getJointPosition)
        )
        n = len(handles)
        sum_sq, largest = [0.0] * n, [0.0] * n
        t0 = clock()
        for k in range(1, steps + 1):
            targets = targets_at(k * pr.DT)
            for h, q in zip(handles, targets):
                set_target(h, q)
            advance(1)
            for i, h in enumerate(handles):
                e = abs(get_position(h) - targets[i])
                sum_sq[i] += e * e
                if e > largest[i]:
                    largest[i] = e
        wall = clock() - t0
        simulated = sim.getSimulationTime()
        # where the root link (the model base's first child) ended, to compare with MuJoCo's
        end = sim.getObjectPosition(sim.getObjectChild(sim.getObject("/" + robot), 0), sim.handle_world)
    if abs(simulated - steps * pr.DT) > 1e-6:
        return {"error": f"{simulated} s simulated, expected {steps * pr.DT}"}
    return {
        **gantry_run(urdf, steps, wall, load_s, sum_sq, largest),
        **({"base_end_m": list(end)} if mobile else {}),
    }


def run_gantry_advance(robot: str, scene: Path, urdf: pr.Urdf, steps: int, package_paths: list[Path]) -> dict:
    """gantry in-process, engine only: client.advance(steps), the Lua script setting the
    targets inside each step."""
    t0 = time.perf_counter()
    with gantry_client(scene, package_paths, scripts=True) as client:
        sim = client.require("sim")
        base = sim.getObject("/" + robot)
        load_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        client.advance(steps)
        wall = time.perf_counter() - t0
        sum_sq, largest, count = client.getScriptFunctions(base).benchErrors()
    if count != steps or len(sum_sq) != len(urdf.joints):
        return {"error": f"the script measured {count} steps of {len(sum_sq)} joints"}
    return gantry_run(urdf, steps, wall, load_s, list(sum_sq), list(largest))


def gantry_run(urdf: pr.Urdf, steps: int, wall: float, load_s: float, sum_sq: list[float], largest: list[float]) -> dict:
    """An in-process gantry run's figures: its rate, its times and its tracking errors."""
    return {
        "steps": steps,
        "steps_per_s": steps / wall,
        "wall_s": wall,
        "load_s": load_s,
        **pr.errors(urdf, steps, sum_sq, largest),
    }


# ---------------------------------------------------------------------------------------
# The wheeled robot


def read_mobile(path: Path) -> pr.Urdf:
    """A wheeled robot's URDF with the wheels' velocity trajectory in place of the arms'
    (Joint.centre, amplitude and frequency are then rad/s, rad/s and Hz): the left
    wheels at WHEEL_SPEED["left"] sin(2 pi f t), the right ones at WHEEL_SPEED["right"],
    so the robot drives an arc forth and back."""
    urdf = pr.read_urdf(path)
    for j in urdf.joints:
        side = "left" if "left" in j.name else "right"
        j.centre, j.amplitude, j.frequency = 0.0, WHEEL_SPEED[side], WHEEL_FREQUENCY
    return urdf


def write_mobile_scene(name: str, urdf: pr.Urdf, origin: str) -> Path:
    """The wheeled robot's gantry scene (free base on a floor, velocity mode) and its
    script: scripts/bench/arm_tracking_any.lua in velocity mode, preceded by the joints'
    trajectory, followed by SCRIPT_TAIL."""
    pr.OUT.mkdir(parents=True, exist_ok=True)
    scene = pr.OUT / f"{name}.toml"
    script = pr.OUT / f"{name}_wheels.lua"
    joints = ", ".join(
        f"{{name = {json.dumps(j.name)}, c = {j.centre!r}, a = {j.amplitude!r}, f = {j.frequency!r}}}"
        for j in urdf.joints
    )
    script.write_text(
        f"-- Generated by tools/bench/mujoco_bench.py: {pr.SCRIPT.name} tracking {name}'s wheel velocities.\n"
        f"TRACK = 'velocity'\nJOINTS = {{ {joints} }}\n\n" + pr.SCRIPT.read_text() + SCRIPT_TAIL
    )
    rel = lambda p: os.path.relpath(p, pr.OUT)  # noqa: E731
    scene.write_text(
        f"# Generated by tools/bench/mujoco_bench.py (issue 33): {origin} on a floor, its wheels\n"
        f"# tracking velocity targets. Regenerated at every run.\n\n"
        f"[simulation]\n"
        f"dt = {pr.DT!r}   # s, 1/240: PyBullet's default step\n"
        f"substeps = 1\n\n"
        f"[floor]\n"
        f"size = [{FLOOR_SIZE!r}, {FLOOR_SIZE!r}]\n\n"
        f"[[robot]]\n"
        f"name = {pr.toml_str(name)}\n"
        f"urdf = {pr.toml_str(rel(urdf.path))}\n"
        f"fixed_base = false\n"
        f'joint_mode = "velocity"\n'
        f"script = {pr.toml_str(rel(script))}\n"
    )
    return scene


# ---------------------------------------------------------------------------------------


def paired(a: list[dict], b: list[dict]) -> tuple[float | None, list[float]]:
    """The median over rounds of a's steps/s over b's in the same round (rounds where
    either failed or diverged left out)."""
    ok = lambda r: "error" not in r and not r.get("unstable")  # noqa: E731
    ratios = [x["steps_per_s"] / y["steps_per_s"] for x, y in zip(a, b) if ok(x) and ok(y)]
    return (statistics.median(ratios) if ratios else None), ratios


def summary(mode: str, r: dict) -> str:
    if "error" in r:
        return f"{mode} failed"
    flag = " UNSTABLE" if r.get("unstable") else ""
    return f"{mode} {r['steps_per_s']:,.0f}/s rms {r['rms_error']:.4f}{flag}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--arms", default=",".join(pr.ARMS), help=f"comma-separated, from: {', '.join(pr.ARMS)}")
    ap.add_argument("--mobile", default=",".join(MOBILE),
                    help=f"wheeled robots, comma-separated, from: {', '.join(MOBILE)} ('' for none)")
    ap.add_argument("--steps", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=1, help="rounds; steps/s are medians over them")
    ap.add_argument("--timeout", type=float, default=600, help="seconds before a gantry binary run is given up")
    ap.add_argument("--mujoco-self-collision", action="store_true",
                    help="keep MuJoCo's default contacts (all but parent-child pairs) instead of none")
    args = ap.parse_args()
    names = [a.strip() for a in args.arms.split(",") if a.strip()]
    mobile_names = [a.strip() for a in args.mobile.split(",") if a.strip()]
    unknown = [a for a in names if a not in pr.ARMS] + [a for a in mobile_names if a not in MOBILE]
    if unknown:
        ap.error(f"unknown robot(s) {', '.join(unknown)}; arms: {', '.join(pr.ARMS)}; wheeled: {', '.join(MOBILE)}")
    # absolute: the working directory changes below
    binary = str(Path(os.environ.get("GANTRY_BIN", pr.ROOT / "target/release/gantry")).resolve())
    # PyBullet's C code and gantry's in-process scripts print to stdout: send file
    # descriptor 1 to stderr, and keep the real stdout for the JSON.
    sys.stdout.flush()
    json_out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    # MuJoCo appends its warnings (an unstable simulation) to MUJOCO_LOG.TXT in the
    # working directory: keep it with the generated scenes, out of the source tree.
    pr.OUT.mkdir(parents=True, exist_ok=True)
    os.chdir(pr.OUT)
    import gantry
    import mujoco
    import pybullet as p

    collide = args.mujoco_self_collision
    robots: list[dict] = []
    skipped: list[dict] = []
    for mobile, table in ((False, {n: pr.ARMS[n] for n in names}), (True, {n: MOBILE[n] for n in mobile_names})):
        for name, (package, rel, title) in table.items():
            base = pr.robots_dir(package)
            urdf = read_mobile(base / rel) if mobile else pr.read_urdf(base / rel)
            try:
                mujoco_model(urdf, collide, mobile)
            except Unsupported as e:
                print(f"{name}: skipped, {e}", file=sys.stderr, flush=True)
                skipped.append({"arm": name, "reason": str(e)})
                continue
            origin = f"{package} {rel}"
            scene = write_mobile_scene(name, urdf, origin) if mobile else pr.write_scene(name, urdf, origin,
                                                                                          SCRIPT_TAIL)
            package_paths = [base.parent.parent] if package == "example-robot-data" else []
            robots.append({"name": name, "title": title, "package": package, "path": rel, "urdf": urdf,
                           "mobile": mobile, "scene": scene, "package_paths": package_paths,
                           "runs": {m: [] for m in MODES}})

    steps = args.steps
    runners: dict[str, Callable[[dict], dict]] = {
        "gantry_lua": lambda a: pr.run_gantry(binary, a["scene"], a["urdf"], steps, a["package_paths"],
                                              args.timeout),
        "gantry_python": lambda a: run_gantry_python(a["name"], a["scene"], a["urdf"], steps,
                                                     a["package_paths"], a["mobile"]),
        "gantry_advance": lambda a: run_gantry_advance(a["name"], a["scene"], a["urdf"], steps,
                                                       a["package_paths"]),
        "mujoco_python": lambda a: run_mujoco_python(a["urdf"], steps, collide, a["mobile"]),
        "mujoco_rollout": lambda a: run_mujoco_rollout(a["urdf"], steps, collide, a["mobile"]),
        "pybullet": lambda a: pr.run_pybullet(a["urdf"], steps, a["mobile"]),
    }
    for r in range(args.repeat):
        for a in robots:  # round-robin: every robot in every mode, then the next round
            line = []
            for mode in MODES:
                result = runners[mode](a)
                a["runs"][mode].append(result)
                line.append(summary(mode, result))
            print(f"round {r + 1} {a['name']}: " + "; ".join(line), file=sys.stderr, flush=True)

    out: dict[str, Any] = {
        "gantry_bin": binary,
        "gantry_version": pr.gantry_version(binary),
        "gantry_package": str(Path(gantry.__file__).parent),
        "mujoco": mujoco.__version__,
        "pybullet": p.getAPIVersion(),
        "dt": pr.DT,
        "steps": steps,
        "repeat": args.repeat,
        "mujoco_gains": {"kp": KP, "kv": KV, "kv_velocity": KV_VELOCITY, "integrator": "implicitfast"},
        "mujoco_self_collision": collide,
        "wheels": {"speed_rad_s": WHEEL_SPEED, "frequency_hz": WHEEL_FREQUENCY},
        "skipped": skipped,
        "arms": [],
        "mobile": [],
    }
    for a in robots:
        runs = a["runs"]
        entry: dict[str, Any] = {
            "arm": a["name"], "title": a["title"], "package": a["package"], "path": a["path"],
            "dof": len(a["urdf"].joints), "joints": [j.name for j in a["urdf"].joints],
            "collision": {"kinds": sorted(a["urdf"].kinds), "triangles": a["urdf"].triangles},
        }
        for mode in MODES:
            entry[mode] = pr.combine(runs[mode])
        ratios = {
            "python_loop": ("gantry_python", "mujoco_python"),
            "lua_vs_mujoco_python": ("gantry_lua", "mujoco_python"),
            "engine": ("gantry_advance", "mujoco_rollout"),
            "lua_vs_pybullet": ("gantry_lua", "pybullet"),
        }
        for key, (x, y) in ratios.items():
            entry[f"ratio_{key}"], entry[f"ratio_{key}_runs"] = paired(runs[x], runs[y])
        out["mobile" if a["mobile"] else "arms"].append(entry)
    print(json.dumps(out, indent=2), file=json_out, flush=True)


if __name__ == "__main__":
    main()
