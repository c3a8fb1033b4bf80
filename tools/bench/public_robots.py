#!/usr/bin/env python3
"""gantry against PyBullet on public mesh-collision arms (issue 15).

The arms come from two PyPI packages in the virtual environment, found at run time
(never copied into the repository): `pybullet_data` (pybullet's own robot files) and
`example-robot-data` (the Gepetto/LAAS collection, installed under
`cmeel.prefix/share/example-robot-data/robots/`, meshes as
`package://example-robot-data/robots/...`). Every arm's collision geometry is read from
mesh files (OBJ, STL or DAE); `xarm6` has convex decompositions (OBJ files of several
parts), `so101` several meshes per link.

For each arm, both simulators run the same URDF, fixed base, dt = 1/240 s, one substep,
every movable joint in position mode with the URDF's effort as its force limit, no
floor, and the same trajectory. The movable joints (revolute, prismatic, continuous) are
numbered i = 1, 2, ... by depth (how many joints lie between the root link and the
joint), then by name: for a serial arm, base to tip, whatever order the file lists them
in (so101.urdf lists them tip first); a gripper's two fingers alphabetically. Joint i
follows

    q_i(t) = c_i + A_i sin(2 pi f_i t),   f_i = 0.25 + 0.05 (i - 1) Hz

with c_i the middle of its limits and A_i = min(0.5, (upper - lower) / 4) (c_i = 0,
A_i = 0.5 for continuous or unlimited joints), in rad (m for prismatic joints), lowered
where needed so that the peak speed 2 pi f_i A_i stays within 0.9 of the joint's URDF
<limit velocity> (gantry enforces that limit, PyBullet's setJointMotorControlArray does
not; only the Kinova's joints are that slow). Both
start at the centres c_i; the target sent before a step is q at the step's end, and the
error |q_i - target_i| is read after the step; RMS and largest error over the joints
and steps (rad and m alike), per joint in the JSON too. A URDF <mimic> follower (panda's
second finger) is left out of the error: a gantry that supports <mimic> moves it from
its leader whatever target the script sends it (an older one tracks that target), and
PyBullet, which has no mimic, is sent the leader's target mapped through <mimic>.

* gantry: one scene per arm in target/bench/public/ (`[[robot]]` with
  `joint_mode = "position"`, `initial` at the centres, and the generic script
  scripts/bench/arm_tracking_any.lua, which finds the joints, computes the same
  trajectory and prints its errors), run as `gantry -v run SCENE --fast --steps N
  --no-listen`. Its steps/s is the binary's own figure (`steps=N ... wall_s=W
  steps_per_s=R` on stdout): the stepping loop only, from after the scene, the meshes,
  the physics world and the Lua state are built and `sysCall_init` has run, to after
  `sysCall_cleanup`. Load time (process start to exit, minus that) is reported apart.
* PyBullet (DIRECT): loadURDF with useFixedBase and URDF_USE_INERTIA_FROM_FILE, the
  default self-collision (off), resetJointState to the centres, then per step
  setJointMotorControlArray (POSITION_CONTROL, default gains, forces = URDF effort),
  stepSimulation and getJointStates. steps/s is that loop's.

Joints are matched by name on the PyBullet side, and the script's joint list, centres,
amplitudes and start positions are checked against this file's before a result counts.

Prints one JSON object on stdout (tools/bench/report.py turns it into a table) and one
progress line per run on stderr. GANTRY_BIN selects the binary (default
target/release/gantry).

    .venv/bin/python tools/bench/public_robots.py [--arms xarm6,panda] [--steps 10000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts/bench/arm_tracking_any.lua"
OUT = ROOT / "target/bench/public"
DT = 1.0 / 240.0
DEFAULT_EFFORT = 100.0  # gantry's max force for a joint whose effort is 0 or missing
VELOCITY_MARGIN = 0.9  # peak trajectory speed as a fraction of a joint's <limit velocity>

# name: (PyPI package, URDF path inside the package's robot folder, what it is)
ARMS: dict[str, tuple[str, str, str]] = {
    "xarm6": ("pybullet_data", "xarm/xarm6_robot.urdf", "UFactory xArm6"),
    "panda": ("pybullet_data", "franka_panda/panda.urdf", "Franka Emika Panda with fingers"),
    "kuka_iiwa": ("pybullet_data", "kuka_iiwa/model.urdf", "KUKA LBR iiwa 14"),
    "ur5": ("example-robot-data", "ur_description/urdf/ur5_robot.urdf", "Universal Robots UR5"),
    "so101": ("example-robot-data", "so_arm_description/urdf/so101.urdf", "SO-101 (LeRobot)"),
    "kinova": ("example-robot-data", "kinova_description/robots/kinova.urdf", "Kinova Jaco j2s6s200"),
    "xarm7": ("example-robot-data", "xarm_description/urdf/xarm7.urdf", "UFactory xArm7"),
}


def robots_dir(package: str) -> Path:
    """The folder the ARMS paths of `package` are relative to, in the installed package."""
    if package == "pybullet_data":
        import pybullet_data

        return Path(pybullet_data.getDataPath())
    if package == "example-robot-data":
        rel = "cmeel.prefix/share/example-robot-data/robots"
        try:
            path = Path(importlib.metadata.distribution("example-robot-data").locate_file(rel))
            if path.is_dir():
                return path
        except importlib.metadata.PackageNotFoundError:
            pass
        for entry in sys.path:
            path = Path(entry) / rel
            if path.is_dir():
                return path
        sys.exit("example-robot-data is not installed: pip install -r tools/bench/requirements.txt")
    raise ValueError(package)


# ---------------------------------------------------------------------------------------
# The URDF: movable joints in benchmark order, their trajectory, the collision geometry.


@dataclass
class Joint:
    name: str
    kind: str  # revolute, prismatic or continuous
    lower: float | None
    upper: float | None
    effort: float
    velocity: float | None = None  # URDF <limit velocity>, rad/s or m/s
    centre: float = 0.0
    amplitude: float = 0.5
    frequency: float = 0.25
    # URDF <mimic>: (master joint's index in Urdf.joints, multiplier, offset)
    mimic: tuple[int, float, float] | None = None

    def start(self, joints: list["Joint"]) -> float:
        """Where both simulators start it: the centre, or a mimic joint's master's centre
        mapped through its <mimic>."""
        if self.mimic is None:
            return self.centre
        m, mult, off = self.mimic
        return off + mult * joints[m].centre


@dataclass
class Urdf:
    path: Path
    joints: list[Joint]
    parts: dict[str, int]  # collision parts per link that has collision geometry
    kinds: set[str] = field(default_factory=set)  # mesh formats and primitives used
    triangles: int = 0  # collision triangles over all meshes


def read_urdf(path: Path) -> Urdf:
    root = ET.parse(path).getroot()
    links = [l.get("name") for l in root.findall("link")]
    children: dict[str, list[ET.Element]] = {name: [] for name in links}
    has_parent = set()
    for j in root.findall("joint"):
        children[j.find("parent").get("link")].append(j)
        has_parent.add(j.find("child").get("link"))
    roots = [name for name in links if name not in has_parent]
    assert len(roots) == 1, f"{path}: {len(roots)} root links"
    joints: list[Joint] = []
    mimic: dict[str, tuple[str, float, float]] = {}
    stack = [(j, 0) for j in reversed(children[roots[0]])]
    depth: dict[str, int] = {}
    while stack:  # depth-first; depth = joints of any type above this one
        j, d = stack.pop()
        kind = j.get("type")
        if (m := j.find("mimic")) is not None:
            mimic[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
        if kind in ("revolute", "prismatic", "continuous"):
            lim = j.find("limit")
            attr = (lambda k: float(lim.get(k, 0))) if lim is not None else (lambda k: 0.0)
            lower, upper, effort, velocity = attr("lower"), attr("upper"), attr("effort"), attr("velocity")
            # gantry (urdf-rs) reads a missing <limit lower upper> as [0, 0]: unlimited.
            if kind == "continuous" or (lower == 0 and upper == 0):
                lower = upper = None
            joints.append(
                Joint(j.get("name"), kind, lower, upper, effort if effort > 0 else DEFAULT_EFFORT, velocity or None)
            )
            depth[j.get("name")] = d
        stack.extend((c, d + 1) for c in reversed(children[j.find("child").get("link")]))
    # By depth, then by name: independent of how either simulator orders siblings.
    joints.sort(key=lambda j: (depth[j.name], j.name.encode()))
    for i, j in enumerate(joints):
        if j.lower is not None and j.upper is not None:
            j.centre = (j.lower + j.upper) / 2
            j.amplitude = min(0.5, (j.upper - j.lower) / 4)
        j.frequency = 0.25 + 0.05 * i
        # A joint whose <limit velocity> is below the trajectory's peak speed (the Kinova
        # Jaco's 0.63 rad/s) is given a smaller amplitude, peaking at VELOCITY_MARGIN of
        # its limit: gantry honours the limit and PyBullet's setJointMotorControlArray
        # does not, so a faster target would measure that difference, not tracking.
        if j.velocity:
            j.amplitude = min(j.amplitude, VELOCITY_MARGIN * j.velocity / (2 * math.pi * j.frequency))
    index = {j.name: i for i, j in enumerate(joints)}
    for j in joints:
        if j.name in mimic and mimic[j.name][0] in index:
            master, mult, off = mimic[j.name]
            j.mimic = (index[master], mult, off)
    urdf = Urdf(path, joints, {})
    for link in root.findall("link"):
        n = 0
        for c in link.findall("collision"):
            g = c.find("geometry")[0]
            if g.tag != "mesh":
                urdf.kinds.add(g.tag)
                n += 1
                continue
            file = mesh_file(path, g.get("filename"))
            ext = file.suffix.lower()
            urdf.kinds.add(ext[1:].upper())
            parts, tris = mesh_parts(file)
            n += parts
            urdf.triangles += tris
        if n:
            urdf.parts[link.get("name")] = n
    return urdf


def mesh_file(urdf: Path, uri: str) -> Path:
    """A mesh reference, resolved as gantry does for these files: package://NAME/rest in
    the URDF's folder or an ancestor named NAME, or in a folder NAME inside one of them."""
    if uri.startswith("file://"):
        return Path(uri[len("file://"):])
    if not uri.startswith("package://"):
        return urdf.parent / uri
    name, _, rest = uri[len("package://"):].partition("/")
    for d in [urdf.parent, *urdf.parent.parents]:
        for candidate in ([d] if d.name == name else []) + [d / name]:
            if (candidate / rest).exists():
                return candidate / rest
    raise FileNotFoundError(f"{urdf}: {uri}")


def mesh_parts(file: Path) -> tuple[int, int]:
    """(parts, triangles) of a mesh file: OBJ objects/groups with faces, DAE <geometry>
    elements, 1 for STL."""
    ext = file.suffix.lower()
    if ext == ".obj":
        groups, faces, current = set(), 0, None
        for line in file.read_text(errors="replace").splitlines():
            if line.startswith(("o ", "g ")):
                current = line
            elif line.startswith("f "):
                groups.add(current)
                faces += len(line.split()) - 3  # a polygon of n vertices is n - 2 triangles
        return len(groups), faces
    if ext == ".stl":
        data = file.read_bytes()
        if data[:5].lower() == b"solid" and b"facet" in data[:1000]:
            return 1, data.count(b"facet normal")
        return 1, int.from_bytes(data[80:84], "little")
    if ext == ".dae":
        tree = ET.parse(file).getroot()
        ns = tree.tag.split("}")[0] + "}" if tree.tag.startswith("{") else ""
        geoms = tree.findall(f".//{ns}library_geometries/{ns}geometry")
        tris = sum(int(t.get("count", 0)) for t in tree.iter(f"{ns}triangles"))
        tris += sum(int(t.get("count", 0)) for t in tree.iter(f"{ns}polylist"))
        return len(geoms), tris
    return 1, 0


class Trajectory:
    """The benchmark's targets, for the simulators driven from Python (PyBullet, MuJoCo,
    gantry in-process): every joint's sinusoid, a <mimic> follower's mapped from its
    leader's target."""

    def __init__(self, urdf: Urdf):
        self.params = [(j.centre, j.amplitude, 2 * math.pi * j.frequency) for j in urdf.joints]
        self.followers = [(i, j.mimic) for i, j in enumerate(urdf.joints) if j.mimic is not None]

    def targets(self, t: float) -> list[float]:
        """The joints' targets at time t (s), in the URDF's benchmark order."""
        sin = math.sin
        targets = [c + a * sin(w * t) for c, a, w in self.params]
        for i, (m, mult, off) in self.followers:
            targets[i] = off + mult * targets[m]
        return targets


# ---------------------------------------------------------------------------------------
# gantry


def toml_str(s: str) -> str:
    return json.dumps(s)  # a JSON string is a valid TOML basic string


def write_scene(name: str, urdf: Urdf, origin: str, script_tail: str = "") -> Path:
    """Writes OUT/name.toml and its script; `script_tail` is Lua appended to the script
    (tools/bench/mujoco_bench.py adds a function that returns the errors in-process)."""
    OUT.mkdir(parents=True, exist_ok=True)
    scene = OUT / f"{name}.toml"
    rel = lambda p: os.path.relpath(p, OUT)  # noqa: E731
    # The generic script, preceded by this arm's velocity limits (the script cannot read
    # them through the sim API), so both simulators compute the same amplitudes.
    script = OUT / f"{name}_tracking.lua"
    caps = ", ".join(f"[{json.dumps(j.name)}] = {j.velocity!r}" for j in urdf.joints if j.velocity)
    script.write_text(
        f"-- Generated by tools/bench/public_robots.py: {SCRIPT.name} with {name}'s <limit velocity>.\n"
        f"VELOCITY_LIMIT = {{ {caps} }}\nVELOCITY_MARGIN = {VELOCITY_MARGIN!r}\n\n" + SCRIPT.read_text() + script_tail
    )
    initial = ", ".join(
        f"{toml_str(j.name)} = {math.degrees(q) if j.kind != 'prismatic' else q!r}"
        for j in urdf.joints
        for q in [j.start(urdf.joints)]
    )
    scene.write_text(
        f"# Generated by tools/bench/public_robots.py (issue 15): {origin}, tracking the\n"
        f"# benchmark trajectory in position mode. Regenerated at every run.\n\n"
        f"[simulation]\n"
        f"dt = {DT!r}   # s, 1/240: PyBullet's default step\n"
        f"substeps = 1\n\n"
        f"[[robot]]\n"
        f"name = {toml_str(name)}\n"
        f"urdf = {toml_str(rel(urdf.path))}\n"
        f'joint_mode = "position"\n'
        f"script = {toml_str(rel(script))}\n"
        f"initial = {{ {initial} }}   # the trajectory's centres (deg, or m for prismatic joints)\n"
    )
    return scene


ANSI = re.compile(r"\x1b\[[0-9;]*m")
FIELD = re.compile(r"(\w+)=(\S+)")
WARNING = re.compile(r" WARN [\w:]+: (.*)")


def run_gantry(binary: str, scene: Path, urdf: Urdf, steps: int, package_paths: list[Path], timeout: float) -> dict:
    cmd = [binary, "-v", "run", str(scene), "--fast", "--steps", str(steps), "--no-listen"]
    for p in package_paths:
        cmd += ["--package-path", str(p)]
    # The script's print lines are info-level logs of target `script` (stderr).
    env = dict(os.environ, NO_COLOR="1", RUST_LOG="warn,script=info")
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"{steps} steps not done in {timeout:.0f} s (--timeout)"}
    process_s = time.perf_counter() - t0
    err = ANSI.sub("", proc.stderr)
    if proc.returncode != 0:
        return {"error": f"exit {proc.returncode}: {err.strip()[-2000:]}"}
    summary = next((l for l in proc.stdout.splitlines() if l.startswith("steps=")), None)
    if summary is None:
        return {"error": f"no summary line on stdout: {proc.stdout[-500:]}"}
    s = dict(FIELD.findall(summary))
    lines: dict[str, list[dict]] = {"@track-joint": [], "@track-error": [], "@track-result": []}
    for line in err.splitlines():
        for tag, found in lines.items():
            if tag + " " in line:
                found.append(dict(FIELD.findall(line.split(tag, 1)[1])))
    if not lines["@track-result"]:
        return {"error": f"no @track-result line on stderr: {err.strip()[-2000:]}"}
    result = lines["@track-result"][0]
    problems = check_script_joints(urdf, lines["@track-joint"])
    if int(result["samples"]) != steps * len(urdf.joints):
        problems.append(f"{result['samples']} error samples, expected {steps * len(urdf.joints)}")
    if [e["name"] for e in lines["@track-error"]] != [j.name for j in urdf.joints]:
        problems.append("the script's per-joint errors do not list the URDF's joints")
    if problems:
        return {"error": "; ".join(problems)}
    per_joint = lines["@track-error"]
    warnings = sorted({m.group(1) for m in WARNING.finditer(err)})
    wall = float(s["wall_s"])
    return {
        "steps": int(s["steps"]),
        "steps_per_s": int(s["steps"]) / wall,
        "wall_s": wall,
        "load_s": process_s - wall,
        **errors(urdf, steps, [float(e["sumsq"]) for e in per_joint], [float(e["max"]) for e in per_joint]),
        "warnings": warnings,
    }


def check_script_joints(urdf: Urdf, joints: list[dict]) -> list[str]:
    """The script must see the same joints, in the same order, with the same trajectory,
    starting where the scene put them."""
    names = [j["name"] for j in joints]
    want = [j.name for j in urdf.joints]
    if names != want:
        return [f"the script's joints {names} are not the URDF's {want}"]
    out = []
    for j, s in zip(urdf.joints, joints):
        if abs(float(s["c"]) - j.centre) > 1e-9 or abs(float(s["a"]) - j.amplitude) > 1e-9:
            out.append(f"{j.name}: script centre/amplitude {s['c']}/{s['a']}, expected {j.centre}/{j.amplitude}")
        if abs(float(s["q0"]) - j.start(urdf.joints)) > 1e-6:
            out.append(f"{j.name}: starts at {s['q0']}, not at {j.start(urdf.joints)}")
    return out


def errors(urdf: Urdf, steps: int, sum_sq: list[float], largest: list[float]) -> dict:
    """RMS and largest error over the joints that count (not <mimic> followers), and
    each joint's."""
    counted = [i for i, j in enumerate(urdf.joints) if j.mimic is None]
    return {
        "rms_error": math.sqrt(sum(sum_sq[i] for i in counted) / (steps * len(counted))),
        "max_error": max(largest[i] for i in counted),
        "joint_rms_error": {j.name: math.sqrt(sum_sq[i] / steps) for i, j in enumerate(urdf.joints)},
        "joint_max_error": {j.name: largest[i] for i, j in enumerate(urdf.joints)},
    }


# ---------------------------------------------------------------------------------------
# PyBullet


def run_pybullet(urdf: Urdf, steps: int, mobile: bool = False) -> dict:
    """PyBullet tracking the trajectory in position mode; with `mobile`
    (tools/bench/mujoco_bench.py's wheeled robot) the base is free on pybullet_data's
    plane.urdf at the origin, the targets are joint velocities (VELOCITY_CONTROL) and the
    error is the joints' velocity error."""
    import pybullet as p

    client = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=client)
        p.setTimeStep(DT, physicsClientId=client)
        if mobile:
            import pybullet_data

            p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=client)
        with tempfile.TemporaryFile("w+") as log:
            # PyBullet's importer writes its warnings to file descriptor 1: keep them.
            sys.stdout.flush()
            saved = os.dup(1)
            os.dup2(log.fileno(), 1)
            try:
                t0 = time.perf_counter()
                robot = p.loadURDF(
                    str(urdf.path), useFixedBase=not mobile, flags=p.URDF_USE_INERTIA_FROM_FILE,
                    physicsClientId=client,
                )
                load_s = time.perf_counter() - t0
            finally:
                os.dup2(saved, 1)
                os.close(saved)
            log.seek(0)
            text = re.sub(r"b3\w+\[[^\]]*\]:", "\n", log.read())
            warnings = sorted({line.strip() for line in text.splitlines() if line.strip()})
        index = {
            p.getJointInfo(robot, i, physicsClientId=client)[1].decode(): i
            for i in range(p.getNumJoints(robot, physicsClientId=client))
        }
        joints = [index[j.name] for j in urdf.joints]
        forces = [j.effort for j in urdf.joints]
        for j, i in zip(urdf.joints, joints):
            p.resetJointState(robot, i, j.start(urdf.joints), physicsClientId=client)
        # <mimic> followers get their leader's target (PyBullet has no mimic).
        trajectory = Trajectory(urdf)
        targets_at, clock = trajectory.targets, time.perf_counter
        mode, target_key, read = (
            (p.VELOCITY_CONTROL, "targetVelocities", 1) if mobile else (p.POSITION_CONTROL, "targetPositions", 0)
        )
        n = len(joints)
        sum_sq, largest, in_step = [0.0] * n, [0.0] * n, 0.0
        t0 = time.perf_counter()
        for k in range(1, steps + 1):
            targets = targets_at(k * DT)
            p.setJointMotorControlArray(
                robot, joints, mode, **{target_key: targets}, forces=forces, physicsClientId=client
            )
            ts = clock()
            p.stepSimulation(physicsClientId=client)
            in_step += clock() - ts
            for i, state in enumerate(p.getJointStates(robot, joints, physicsClientId=client)):
                e = abs(state[read] - targets[i])
                sum_sq[i] += e * e
                if e > largest[i]:
                    largest[i] = e
        wall = time.perf_counter() - t0
    finally:
        p.disconnect(client)
    return {
        "steps": steps,
        "steps_per_s": steps / wall,
        "wall_s": wall,
        "load_s": load_s,
        # stepSimulation alone, without the Python calls that set targets and read joints
        "step_only_steps_per_s": steps / in_step,
        **errors(urdf, steps, sum_sq, largest),
        "warnings": warnings,
    }


# ---------------------------------------------------------------------------------------


def combine(runs: list[dict]) -> dict:
    """Median steps/s over the repeats (every figure listed); errors from the first run,
    with their spread over the repeats (0 for a deterministic simulator)."""
    ok = [r for r in runs if "error" not in r]
    if not ok:
        return {"error": runs[0]["error"]}
    out = dict(ok[0])
    out["steps_per_s_runs"] = [r["steps_per_s"] for r in ok]
    out["steps_per_s"] = statistics.median(out["steps_per_s_runs"])
    out["rms_error_spread"] = max(r["rms_error"] for r in ok) - min(r["rms_error"] for r in ok)
    if len(ok) < len(runs):
        out["failed_runs"] = [r["error"] for r in runs if "error" in r]
    return out


def gantry_version(binary: str) -> str:
    try:
        return subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=30).stdout.strip()
    except OSError as e:
        sys.exit(f"cannot run {binary}: {e} (set GANTRY_BIN or build with cargo build --release)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--arms", default=",".join(ARMS), help=f"comma-separated, from: {', '.join(ARMS)}")
    ap.add_argument("--steps", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=1, help="runs per arm and simulator; steps/s is the median")
    ap.add_argument("--timeout", type=float, default=600, help="seconds before a gantry run is given up")
    args = ap.parse_args()
    names = [a.strip() for a in args.arms.split(",") if a.strip()]
    unknown = [a for a in names if a not in ARMS]
    if unknown:
        ap.error(f"unknown arm(s) {', '.join(unknown)}; known: {', '.join(ARMS)}")
    binary = os.environ.get("GANTRY_BIN", str(ROOT / "target/release/gantry"))
    # PyBullet's C code prints to stdout (its build time, URDF warnings): send file
    # descriptor 1 to stderr, and keep the real stdout for the JSON.
    sys.stdout.flush()
    json_out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    import pybullet as p

    out = {
        "gantry_bin": binary,
        "gantry_version": gantry_version(binary),
        "pybullet": p.getAPIVersion(),
        "dt": DT,
        "steps": args.steps,
        "repeat": args.repeat,
        "arms": [],
    }
    for name in names:
        package, rel, title = ARMS[name]
        base = robots_dir(package)
        urdf = read_urdf(base / rel)
        scene = write_scene(name, urdf, f"{package} {rel}")
        # Not needed (gantry finds package://example-robot-data above the URDF), but explicit.
        package_paths = [base.parent.parent] if package == "example-robot-data" else []
        g_runs, p_runs = [], []
        for r in range(args.repeat):
            g = run_gantry(binary, scene, urdf, args.steps, package_paths, args.timeout)
            pb = run_pybullet(urdf, args.steps)
            g_runs.append(g)
            p_runs.append(pb)
            print(
                f"{name} run {r + 1}: gantry "
                + (g.get("error") or f"{g['steps_per_s']:,.0f} steps/s rms {g['rms_error']:.4f}")
                + f"; PyBullet {pb['steps_per_s']:,.0f} steps/s rms {pb['rms_error']:.4f}",
                file=sys.stderr,
                flush=True,
            )
            if "error" in g:
                break  # a failed or timed-out run would only fail again
        g, pb = combine(g_runs), combine(p_runs)
        # gantry's steps/s over PyBullet's in the same repeat (the two runs are back to
        # back, so they share the machine's load); the median of those is the ratio.
        paired = [gr["steps_per_s"] / pr["steps_per_s"] for gr, pr in zip(g_runs, p_runs) if "error" not in gr]
        out["arms"].append({
            "arm": name,
            "title": title,
            "package": package,
            "path": rel,
            "scene": str(scene.relative_to(ROOT)),
            "dof": len(urdf.joints),
            "joints": [j.name for j in urdf.joints],
            # <mimic> followers: left out of rms_error and max_error
            "mimic": [
                {"joint": j.name, "leader": urdf.joints[j.mimic[0]].name, "multiplier": j.mimic[1], "offset": j.mimic[2]}
                for j in urdf.joints
                if j.mimic is not None
            ],
            "collision": {
                "kinds": sorted(urdf.kinds),
                "parts_per_link": urdf.parts,
                "triangles": urdf.triangles,
            },
            "gantry": g,
            "pybullet": pb,
            "ratio": statistics.median(paired) if paired else None,
            "ratio_runs": paired,
        })
    print(json.dumps(out, indent=2), file=json_out, flush=True)


if __name__ == "__main__":
    main()
