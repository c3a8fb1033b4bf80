"""Issue 15, "bring your own robot": public URDFs in gantry against Pinocchio.

The robots are the URDFs and meshes of two PyPI packages, ``pybullet`` (``pybullet_data``)
and ``example-robot-data``, read where pip installed them (``public_robots.py`` finds them
and lists the catalogue). Nothing of them is copied into the repository. The referee is
Pinocchio (PyPI ``pin``), which parses the same file with its own URDF parser (urdfdom)
and shares nothing else with gantry.

1. ``test_forward_kinematics[ROBOT]``. gantry runs the bare URDF as shipped (``gantry run
   FILE.urdf``: base fixed to the world, every joint kinematic) and must load it without
   error; a load failure fails the test with gantry's error line. Its objects must be one
   shape per URDF link and one joint object per URDF joint, aliased by the URDF names,
   under a root model base aliased by ``<robot name>`` (found by enumerating the tree, not
   by path). Then, at the zero configuration and N_CONFIGS - 1 seeded random ones inside
   the joint limits, every movable joint is set with ``sim.setJointPosition`` while
   ``setStepping`` holds the simulation (nothing steps in between, so the link poses must
   follow at once), read back with ``sim.getJointPosition`` (TOL_JOINT), and every link's
   world pose (``sim.getObjectPose``; checked once against ``getObjectPosition`` and
   ``getObjectQuaternion``) is compared with Pinocchio's BODY frame of that link after
   ``framesForwardKinematics``, composed with the model base's world pose as gantry
   reports it (today the identity): position within TOL_POS_M, rotation angle of the
   difference within TOL_ROT_RAD.

   Joints gantry imports as fixed (``floating``, ``planar``) stay at Pinocchio's neutral
   configuration, which is the fixed joint's pose; no catalogue file has one today.
   ``<mimic>`` joints are never drawn nor set in gantry: each must follow its leader,
   ``multiplier * leader + offset`` (leaders are drawn where every follower stays inside
   its own limits). Pinocchio reads the file with ``mimic=False`` (its default: each
   mimic joint is an ordinary joint) and is given the followers' values explicitly.

2. ``test_passive_dynamics[ARM-DT]``. Fixed-base arms whose joints have no motor at all
   (``joint_mode = "free"``) fall from rest under gravity (0, 0, -9.81) for
   DYN_DURATION_S; the joint positions are compared with Pinocchio's forward dynamics
   (``pinocchio.aba``) integrated with the same time step by semi-implicit Euler
   (v += dt * a; q = integrate(q, dt * v)) within TOL_DYN_RAD, without damping and with a
   viscous ``<dynamics damping>`` on every joint (an explicit torque -damping * v in the
   referee). This referee reproduces PyBullet's Featherstone integration of the same
   files to 1e-15 rad (checked by hand on kuka_iiwa, both pandas, ur5, ur10 and kinova).

   Integrators. gantry (rapier's reduced-coordinate multibodies, f32) is also a
   first-order method that converges to the same motion as dt -> 0, but not the same
   one: on kuka_iiwa and the pandas its end positions differ from the referee's by 2 to 7
   times (mostly 4 to 6) the change of the referee's own end positions when its step is
   halved. From a typical start that difference is 1e-2 to 1e-1 rad at dt = 1 ms and
   5e-3 to 0.8 rad at dt = 1/240 s, where the referee alone moves by up to 0.3 rad with
   the step. So a start is used only if halving the referee's step changes its end
   positions by less than DYN_MAX_STEP_SENSITIVITY_RAD (TOL_DYN_RAD / 10); at dt = 1/240
   s almost no start passes that, and DYN_TIME_STEPS has dt = 1 ms only. The damping is
   sized per joint (``damping_for``) so that the referee's explicit damping stays well
   inside its stable range (DYN_MAX_DAMPING_STEP), where it and an implicit treatment
   agree to O(dt).

   Set-up. The URDFs gantry loads are modified copies written into ``tmp_path``
   (``public_robots.write_dynamics_urdf``): no geometry, so no contacts on either side
   (ABA has none); the damping under test and no friction; gripper fingers welded. The
   arms hang from the ceiling (DYN_MOUNT_DEG) so that they swing instead of collapsing
   into their limits. Starts are drawn between a rest configuration and a uniform one
   (``sample_start``) and rejection-sampled so that the referee's whole trajectory, damped
   and undamped, stays DYN_LIMIT_MARGIN_RAD inside every joint limit (gantry enforces
   limits, ABA does not). Copies of one arm, one per start and damping variant, hang side
   by side in one gantry process. The scene is stopped first (gantry starts running at
   once; stopping restores its initial state at rest), the starts are set with
   ``sim.setJointPosition`` (every link must follow and every joint velocity read 0),
   then the simulation is started and stepped by the client.
"""

from __future__ import annotations

import math
import random
import re
import time

import numpy as np
import pytest

from public_robots import (
    BY_ID,
    CATALOGUE,
    GantryRobot,
    Referee,
    limited,
    load_referee,
    random_configuration,
    rotation_angle,
    wrap_angle,
    write_dynamics_urdf,
    zero_configuration,
)

# The robots load through gantry's command line (package paths, viewer port): the
# binary's ZMQ server only. The loader is the same code in-process.
pytestmark = pytest.mark.zmq_only

# --- forward kinematics
N_CONFIGS = 20  # the zero configuration, then N_CONFIGS - 1 random ones
TOL_POS_M = 1e-6
TOL_ROT_RAD = 1e-6
TOL_JOINT = 1e-9  # joint position read back after setJointPosition (rad or m)

# --- passive dynamics
DYN_DURATION_S = 0.5
DYN_TIME_STEPS = (0.001,)
TOL_DYN_RAD = 1e-2
DYN_CONFIGS = 3  # start configurations per arm, each run with and without damping
DYN_LIMIT_MARGIN_RAD = 0.1
DYN_MAX_TRIES = 2000
# The arms hang from the ceiling: base upside down (CoppeliaSim Euler angles, degrees)
# DYN_MOUNT_HEIGHT_M above the origin. An unactuated arm standing on the floor collapses
# into its shoulder limit within 0.5 s from almost any start (about 1 in 100 starts of
# the iiwa, xArm and Panda keep off their limits); hanging, it swings about its stable
# equilibrium and 5 to 50 in 100 do. Gravity stays (0, 0, -9.81) in the world; the
# referee gets it in the base frame.
DYN_MOUNT_DEG = (180.0, 0.0, 0.0)
DYN_MOUNT_HEIGHT_M = 2.0
DYN_DAMPING_RATE = 1.0  # 1/s, see damping_for()
# Largest dt * (fastest damping decay rate) accepted at a start configuration: beyond it
# the referee's explicit damping torque drifts from any implicit treatment by more than
# the tolerance (see Referee.damping_stiffness).
DYN_MAX_DAMPING_STEP = 0.1
# Largest change of the referee's end positions when its step is halved. Two correct
# first-order integrators differ by O(dt); from starts where that is not well below the
# tolerance (the arm whips a light wrist around) no comparison at this dt can tell a
# bug from a legitimate integrator, so they are rejected like starts that hit a limit.
DYN_MAX_STEP_SENSITIVITY_RAD = TOL_DYN_RAD / 10
# The damped run must differ from the undamped one by at least this much at the end
# (in the referee), or the damping comparison would not test anything.
DYN_MIN_DAMPING_EFFECT_RAD = 10 * TOL_DYN_RAD

SEED = 15
GRAVITY = (0.0, 0.0, -9.81)


def gantry_args(robot) -> list[str]:
    """Extra ``gantry run`` options: free ports for every listener, package paths."""
    args = ["--http-port", "0"]
    for p in robot.package_paths:
        args += ["--package-path", str(p)]
    return args


def load_error(stderr: str) -> str:
    """gantry's error line(s) from its stderr, without the log decoration."""
    plain = re.sub(r"\x1b\[[0-9;]*m", "", stderr)
    lines = [ln for ln in plain.splitlines() if re.search(r"\berror\b", ln, re.I)]
    return "\n".join(lines) or plain[-2000:]


def start_gantry(gantry, scene, extra):
    """Starts gantry on ``scene``; a load failure fails the test with gantry's own error."""
    try:
        return gantry(scene, extra=extra)
    except RuntimeError as e:
        error = load_error(str(e))
    pytest.fail(f"gantry could not load {scene}:\n{error}", pytrace=False)


# ---------------------------------------------------------------------------------------
# Summary table, printed in pytest's terminal summary (visible with -q too).

FK_RESULTS: dict[str, dict] = {}
DYN_RESULTS: dict[tuple[str, float], dict] = {}


class _Summary:
    """A plugin registered by the ``summary`` fixture: its hook prints the tables."""

    def __init__(self):
        self.elapsed = 0.0

    def pytest_terminal_summary(self, terminalreporter):
        write = terminalreporter.write_line
        if FK_RESULTS:
            terminalreporter.section("public robots: forward kinematics against Pinocchio")
            write(f"{N_CONFIGS} configurations each; tolerance {TOL_POS_M:g} m, {TOL_ROT_RAD:g} rad")
            write(f"{'robot':22} {'package':18} {'links':>5} {'joints':>6} {'worst pos (m)':>13} "
                  f"{'worst rot (rad)':>15}  result")
            for r in CATALOGUE:
                res = FK_RESULTS.get(r.rid)
                if res is None:
                    continue
                pos = f"{res['pos']:.1e}" if "pos" in res else "-"
                rot = f"{res['rot']:.1e}" if "rot" in res else "-"
                write(f"{r.rid:22} {r.package:18} {res.get('links', '-'):>5} {res.get('joints', '-'):>6} "
                      f"{pos:>13} {rot:>15}  {res['result']}")
        if DYN_RESULTS:
            terminalreporter.section("public robots: passive dynamics against pinocchio.aba")
            write(f"{DYN_CONFIGS} start configurations each, {DYN_DURATION_S} s; tolerance {TOL_DYN_RAD:g} rad")
            write(f"{'arm':16} {'dt (s)':>9} {'undamped (rad)':>15} {'damped (rad)':>13} "
                  f"{'damping effect':>15}  result")
            for (rid, dt), res in DYN_RESULTS.items():
                und = f"{res['undamped']:.1e}" if "undamped" in res else "-"
                dmp = f"{res['damped']:.1e}" if "damped" in res else "-"
                eff = f"{res['effect']:.2f}" if "effect" in res else "-"
                write(f"{rid:16} {dt:9.6f} {und:>15} {dmp:>13} {eff:>15}  {res['result']}")
        write(f"(test_public_robots.py: {self.elapsed:.1f} s)")


@pytest.fixture(scope="module", autouse=True)
def summary(request):
    plugins = request.config.pluginmanager
    plugin = plugins.get_plugin("public-robots-summary")
    if plugin is None:
        plugin = _Summary()
        plugins.register(plugin, "public-robots-summary")
    t0 = time.monotonic()
    yield
    plugin.elapsed += time.monotonic() - t0


# ---------------------------------------------------------------------------------------
# 1. Forward kinematics


@pytest.mark.parametrize("rid", [r.rid for r in CATALOGUE])
def test_forward_kinematics(rid, gantry, tmp_path):
    """Every link of a public URDF where Pinocchio puts it, at N_CONFIGS configurations."""
    robot = BY_ID[rid]
    res = FK_RESULTS.setdefault(rid, {"result": "FAIL"})
    ref = load_referee(robot, tmp_path)
    ref.check_matches_file()
    info = ref.info
    res["links"], res["joints"] = len(info.links), len(info.movable)

    g = start_gantry(gantry, robot.path, gantry_args(robot))
    client = g.client()
    sim = client.require("sim")
    client.setStepping(True)

    gr = GantryRobot(sim, info.name)
    # The import made exactly one object per URDF element, with the URDF names.
    assert sorted(gr.links) == sorted(info.links), "shapes under the model base vs URDF links"
    assert all(len(hs) == 1 for hs in gr.links.values()), "a URDF link became several shapes"
    assert sorted(gr.joints) == sorted(j.name for j in info.joints), "joint objects vs URDF joints"
    assert all(len(hs) == 1 for hs in gr.joints.values()), "a URDF joint became several joints"
    link_h = {name: hs[0] for name, hs in gr.links.items()}
    joint_h = {j.name: gr.joints[j.name][0] for j in info.movable}
    # <mimic> joints are not set: they must follow their leaders.
    followers = info.followers

    # Pinocchio's poses are relative to the robot base; gantry's are in the world.
    base_p, base_r = gr.pose(gr.base)
    base_offset = (float(np.linalg.norm(base_p)), rotation_angle(np.eye(3), base_r))

    rng = random.Random(f"{SEED}:{rid}")
    worst_p = worst_r = 0.0
    for k in range(N_CONFIGS):
        q = zero_configuration(info) if k == 0 else random_configuration(rng, info)
        for name, v in q.items():
            if name not in followers:
                sim.setJointPosition(joint_h[name], v)
        for name, v in q.items():
            got = sim.getJointPosition(joint_h[name])
            how = f"follows {followers[name]}" if name in followers else "was set"
            assert abs(wrap_angle(got - v) if ref.continuous[name] else got - v) < TOL_JOINT, (
                f"config {k}: joint {name} reads {got}, should be {v} ({how})"
            )
        want = ref.link_poses(q)
        for name, h in link_h.items():
            got_p, got_r = gr.pose(h)
            p, r = want[name]
            want_p, want_r = base_r @ p + base_p, base_r @ r
            dp = float(max(abs(got_p - want_p)))
            dr = rotation_angle(want_r, got_r)
            worst_p, worst_r = max(worst_p, dp), max(worst_r, dr)
            assert dp < TOL_POS_M and dr < TOL_ROT_RAD, (
                f"config {k}, link {name}: position {got_p.tolist()} vs {want_p.tolist()} "
                f"({dp:.2e} m), rotation off by {dr:.2e} rad; joints {q}"
            )
        if k == 1:
            # getObjectPose agrees with the two calls the issue names (on the link
            # farthest from the base, whose pose involves the most joints).
            far = link_h[max(want, key=lambda n: float(np.linalg.norm(want[n][0])))]
            pose = sim.getObjectPose(far, sim.handle_world)
            assert sim.getObjectPosition(far, sim.handle_world) == pose[:3]
            assert sim.getObjectQuaternion(far, sim.handle_world) == pose[3:]
    res.update(pos=worst_p, rot=worst_r, result="pass")
    print(f"{rid}: {len(link_h)} links, worst {worst_p:.2e} m, {worst_r:.2e} rad; model base "
          f"{base_offset[0]:.2e} m, {base_offset[1]:.2e} rad from the world origin")


# ---------------------------------------------------------------------------------------
# 2. Passive dynamics


class DynArm:
    """An arm of the dynamics test: its catalogue id and the joints to weld."""

    def __init__(self, rid: str, *, fix: tuple[str, ...] = ()):
        self.rid, self.fix = rid, fix


def damping_for(ref: Referee) -> dict[str, float]:
    """Per-joint viscous damping (N m s/rad) for the damped copy.

    Joint i gets DYN_DAMPING_RATE times M_ii, its diagonal joint-space inertia at the zero
    configuration, rounded to 3 significant digits: a decay time of about 1 / rate on
    every joint, from the base's (inertia ~1 kg m^2) to the last wrist joint's (~1e-4),
    so the damping visibly changes every joint's motion, while dt times the fastest decay
    rate stays small enough for the referee's explicit damping torque (see
    ``Referee.damping_stiffness``). One value for all joints would either not affect the
    heavy joints or make the light wrist joints stiff beyond the explicit step's reach.
    """
    m = ref.joint_inertia(zero_configuration(ref.info))
    return {n: float(f"{DYN_DAMPING_RATE * m[i, i]:.3g}") for n, i in ref.idx_v.items()}


DYN_ARMS = [
    DynArm("kuka_iiwa"),
    DynArm("pb_panda", fix=("panda_finger_joint1", "panda_finger_joint2")),
    DynArm("erd_panda", fix=("panda_finger_joint1", "panda_finger_joint2")),
    DynArm("xarm6"),
    DynArm("ur5"),
    DynArm("ur10"),
    DynArm("kinova"),
]


def inner_bounds(ref: Referee, margin: float) -> dict[str, tuple[float, float]]:
    """Each limited joint's limits, shrunk by ``margin``."""
    return {j.name: (j.lower + margin, j.upper - margin) for j in ref.info.movable if limited(j)}


def euler_matrix(alpha: float, beta: float, gamma: float) -> np.ndarray:
    """CoppeliaSim Euler angles (rad): R = Rx(alpha) Ry(beta) Rz(gamma)."""
    ca, sa, cb, sb, cg, sg = (f(x) for x in (alpha, beta, gamma) for f in (math.cos, math.sin))
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cg, -sg, 0], [sg, cg, 0], [0, 0, 1]])
    return rx @ ry @ rz


def step_sensitivity(ref: Referee, q0, end, dt: float, steps: int, damping, gravity) -> float:
    """How much the referee's end positions depend on its step: the largest joint change
    when the same run is made with dt / 2 (about half the run's discretisation error)."""
    fine = ref.simulate(q0, dt / 2, 2 * steps, damping, None, gravity)
    return max(abs(wrap_angle(end[n] - fine[n])) for n in q0)


def sample_start(rng, ref_plain: Referee, ref_damped: Referee, damping: dict[str, float], dt: float,
                 steps: int, gravity):
    """A start configuration for the dynamics test, with the referee's end positions.

    Candidates are ``rest + u * (uniform - rest)``, u uniform in [0, 1): a uniform
    configuration within the limits pulled towards ``rest`` (0, the hanging arm, or the
    middle of a joint's range if that excludes 0) by a random amount, so small swings and
    full-range ones are both drawn. A candidate is kept if both referee runs (undamped,
    damped) stay DYN_LIMIT_MARGIN_RAD inside the limits, its damping is not stiff for the
    step (DYN_MAX_DAMPING_STEP) and its end positions do not depend on the step
    (DYN_MAX_STEP_SENSITIVITY_RAD).
    """
    bounds = inner_bounds(ref_plain, DYN_LIMIT_MARGIN_RAD)
    rest = {n: 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)
            for n, (lo, hi) in inner_bounds(ref_plain, 2 * DYN_LIMIT_MARGIN_RAD).items()}
    rest.update({j.name: 0.0 for j in ref_plain.info.movable if j.name not in rest})
    for _ in range(DYN_MAX_TRIES):
        far = random_configuration(rng, ref_plain.info)
        u = rng.random()
        q0 = {n: rest[n] + u * (far[n] - rest[n]) for n in far}
        if any(not lo <= q0[n] <= hi for n, (lo, hi) in bounds.items()):
            continue
        if dt * ref_damped.damping_stiffness(q0, damping) > DYN_MAX_DAMPING_STEP:
            continue
        ends = []
        for ref, c in ((ref_plain, {}), (ref_damped, damping)):
            end = ref.simulate(q0, dt, steps, c, bounds, gravity)
            if end is None or step_sensitivity(ref, q0, end, dt, steps, c, gravity) > DYN_MAX_STEP_SENSITIVITY_RAD:
                break
            ends.append(end)
        else:
            return q0, ends[0], ends[1]
    raise AssertionError(f"no start configuration in {DYN_MAX_TRIES} tries keeps off the limits "
                         f"with a step-independent end")


@pytest.mark.parametrize("dt", DYN_TIME_STEPS, ids=lambda dt: f"dt{dt:.6f}")
@pytest.mark.parametrize("arm", DYN_ARMS, ids=lambda a: a.rid)
def test_passive_dynamics(arm, dt, gantry, tmp_path):
    """Free joints fall like Pinocchio's ABA says, without and with viscous damping."""
    robot = BY_ID[arm.rid]
    res = DYN_RESULTS.setdefault((arm.rid, dt), {"result": "FAIL"})
    steps = round(DYN_DURATION_S / dt)

    plain_urdf, damped_urdf = tmp_path / "plain.urdf", tmp_path / "damped.urdf"
    info_plain = write_dynamics_urdf(robot.path, plain_urdf, fix=arm.fix)
    ref_plain = Referee(plain_urdf, info_plain)
    ref_plain.check_matches_file()
    damping = damping_for(ref_plain)
    info_damped = write_dynamics_urdf(robot.path, damped_urdf, damping=damping, fix=arm.fix)
    ref_damped = Referee(damped_urdf, info_damped)
    # The copies say what they should, and Pinocchio read the damping from the file.
    assert all(j.damping == 0 and j.friction == 0 for j in info_plain.movable)
    assert {j.name: j.damping for j in info_damped.movable} == damping and all(damping.values())
    assert list(ref_damped.model.damping) == [damping[n] for n in sorted(damping, key=ref_damped.idx_v.get)]
    res["damping"] = damping

    mount = euler_matrix(*(math.radians(a) for a in DYN_MOUNT_DEG))
    gravity = mount.T @ np.array(GRAVITY)  # in the base frame
    rng = random.Random(f"{SEED}:{arm.rid}:{dt}")
    cases = []  # (robot name in the scene, urdf, start, referee's final positions)
    effect = 0.0
    for k in range(DYN_CONFIGS):
        q0, end_plain, end_damped = sample_start(rng, ref_plain, ref_damped, damping, dt, steps, gravity)
        effect = max(effect, max(abs(wrap_angle(end_plain[n] - end_damped[n])) for n in q0))
        cases.append((f"plain{k}", plain_urdf, q0, end_plain))
        cases.append((f"damped{k}", damped_urdf, q0, end_damped))
    res["effect"] = effect
    assert effect > DYN_MIN_DAMPING_EFFECT_RAD, f"damping {damping} changes too little ({effect:.3f} rad)"

    scene = tmp_path / "scene.toml"
    lines = [f"[simulation]\ndt = {dt!r}\nsubsteps = 1\ngravity = {list(GRAVITY)}\n"]
    for i, (name, urdf, _, _) in enumerate(cases):
        # Side by side, 3 m apart; without geometry nothing touches anyway.
        lines.append(f'[[robot]]\nname = "{name}"\nurdf = "{urdf}"\n'
                     f'position = [{3 * i}, 0, {DYN_MOUNT_HEIGHT_M}]\norientation_deg = {list(DYN_MOUNT_DEG)}\n'
                     f'joint_mode = "free"\n')
    scene.write_text("\n".join(lines))
    g = start_gantry(gantry, scene, ["--http-port", "0"])
    client = g.client()
    sim = client.require("sim")
    # gantry starts running at once; the arms have been falling until now. Stopping
    # restores the scene's initial state (every joint at 0, at rest); stepping then holds
    # the simulation from its first step on (stopping resets the stepping level).
    sim.stopSimulation()
    client.setStepping(True)
    assert sim.getSimulationState() == sim.simulation_stopped
    assert sim.getSimulationTime() == 0.0

    handles = []
    for i, (name, _, q0, _) in enumerate(cases):
        gr = GantryRobot(sim, name)
        # The base is where the scene puts it, so the referee's gravity is the right one.
        base_p, base_r = gr.pose(gr.base)
        assert max(abs(base_p - [3 * i, 0, DYN_MOUNT_HEIGHT_M])) < TOL_POS_M
        assert rotation_angle(mount, base_r) < TOL_ROT_RAD
        jh = {n: gr.joints[n][0] for n in q0}
        for n, v in q0.items():
            sim.setJointPosition(jh[n], v)
        # The links followed at once (gantry starts at the zero configuration), and
        # nothing moves yet.
        for link, (p, r) in ref_plain.link_poses(q0).items():
            got_p, got_r = gr.pose(gr.links[link][0])
            assert max(abs(got_p - (base_r @ p + base_p))) < TOL_POS_M, f"{name}: {link} is not at the start pose"
            assert rotation_angle(base_r @ r, got_r) < TOL_ROT_RAD, f"{name}: {link} is not at the start pose"
        for n, v in q0.items():
            assert abs(sim.getJointPosition(jh[n]) - v) < TOL_JOINT
            assert sim.getJointVelocity(jh[n]) == 0.0, f"{name}: {n} moves before the first step"
        handles.append(jh)

    sim.startSimulation()
    for _ in range(steps):
        client.step()
    assert sim.getSimulationTime() == pytest.approx(DYN_DURATION_S, abs=dt / 2)

    worst = {"plain": 0.0, "damped": 0.0}
    failures = []
    for (name, _, q0, want), jh in zip(cases, handles):
        variant = "damped" if name.startswith("damped") else "plain"
        for n, h in jh.items():
            got = sim.getJointPosition(h)
            err = abs(wrap_angle(got - want[n]))
            worst[variant] = max(worst[variant], err)
            if err > TOL_DYN_RAD:
                failures.append(f"{name} {n}: gantry {got:.4f}, pinocchio {want[n]:.4f} (from {q0[n]:.4f})")
    res.update(undamped=worst["plain"], damped=worst["damped"])
    print(f"{arm.rid} dt={dt:.6f}: worst joint error undamped {worst['plain']:.2e} rad, "
          f"damped {worst['damped']:.2e} rad (damping effect {effect:.2f} rad)")
    assert not failures, f"after {DYN_DURATION_S} s:\n" + "\n".join(failures)
    res["result"] = "pass"

