"""Public robot files and an independent referee for them (issue 15, "bring your own robot").

This module is the data and the arithmetic behind ``test_public_robots.py``:

* **Where the files come from.** Nothing is vendored: the URDFs and meshes are those of
  two PyPI packages installed in the test virtual environment, found at run time.
  ``pybullet`` ships ``pybullet_data`` (``pybullet_data.getDataPath()``);
  ``example-robot-data`` (a cmeel wheel) installs ``cmeel.prefix/share/example-robot-data``,
  which is found through the distribution's own file list (``importlib.metadata``). Its
  URDFs name meshes as ``package://example-robot-data/robots/...``, so gantry gets the
  ``share`` folder as ``--package-path``. A missing package raises (a failed test, not a
  skip).
* **The catalogue** (``CATALOGUE``): arms, grippers and hands, quadrupeds, wheeled and
  mobile robots, bipeds and humanoids, and a few textbook chains, each with an id that
  names the test. gantry always loads a file exactly as shipped; only the referee may
  read a fixed-up copy (``referee_fixups``: husky.urdf still carries xacro's
  ``$(optenv NAME default)``, which urdfdom cannot parse, so the referee reads the
  defaults).
* **The referee**: Pinocchio (PyPI ``pin``), an implementation that shares nothing with
  gantry but the file. ``Referee`` builds ``pinocchio.buildModelFromUrdf(path)`` with a
  fixed base (no root joint) and the default ``mimic=False``, so a ``<mimic>`` joint is
  an ordinary joint there; the configurations drawn here (``random_configuration``) set
  each mimic joint from its leader, and Pinocchio gets every joint's value. Pinocchio's
  continuous joints have two coordinates (cos, sin); ``Referee.q`` converts one angle
  per joint. Link poses are Pinocchio's BODY frames, one per URDF link,
  after ``framesForwardKinematics``.
* **Joints gantry imports as fixed** (``floating`` and ``planar``): Pinocchio keeps them
  as free-flyer and planar joints. The referee leaves them at Pinocchio's neutral
  configuration (the identity), which is exactly the fixed joint gantry builds from the
  joint's ``<origin>``; the test never moves them. No file of the catalogue has one today
  (``g1`` has a floating joint only inside a comment).
* **Passive dynamics**: ``Referee.simulate`` integrates Pinocchio's articulated-body
  algorithm (``pinocchio.aba``) with semi-implicit Euler, and ``write_dynamics_urdf``
  makes the modified copies the dynamics test loads (see there).

The XML of each file is also read here (``UrdfInfo``, with ``xml.etree``): joint types,
limits and ``<dynamics>``, the link list and the robot name come from the file itself,
and the test checks that Pinocchio read the same joints and links.
"""

from __future__ import annotations

import importlib.metadata
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# ---------------------------------------------------------------------------------------
# Where the packages put their files


def pybullet_data_dir() -> Path:
    """The ``pybullet_data`` folder of the installed ``pybullet`` wheel."""
    import pybullet_data

    return Path(pybullet_data.getDataPath())


def example_robot_data_share() -> Path:
    """``.../cmeel.prefix/share``: the folder that holds ``example-robot-data/robots``.

    Found from the ``example-robot-data`` distribution's RECORD, so it works wherever pip
    put the venv. Raises ``importlib.metadata.PackageNotFoundError`` if it is missing.
    """
    dist = importlib.metadata.distribution("example-robot-data")
    for f in dist.files or []:
        parts = f.parts
        if parts[-2:] == ("example-robot-data", "package.xml") and "share" in parts:
            share = Path(dist.locate_file(f)).resolve().parent.parent
            if (share / "example-robot-data" / "robots").is_dir():
                return share
    raise FileNotFoundError("example-robot-data is installed but has no share/example-robot-data/robots")


PYBULLET = "pybullet"
ERD = "example-robot-data"


@dataclass(frozen=True)
class Robot:
    """One public URDF: ``rid`` names the test, ``package`` is the PyPI package that ships it."""

    rid: str
    package: str
    relpath: str
    kind: str
    # Referee-only text substitutions, for files that are not valid URDF as shipped
    # (xacro left-overs). gantry always loads the file exactly as shipped.
    referee_fixups: tuple[tuple[str, str], ...] = ()

    @property
    def path(self) -> Path:
        if self.package == PYBULLET:
            return pybullet_data_dir() / self.relpath
        if self.package == ERD:
            return example_robot_data_share() / "example-robot-data" / "robots" / self.relpath
        raise ValueError(self.package)

    @property
    def package_paths(self) -> list[Path]:
        """Folders for gantry's ``--package-path``."""
        return [example_robot_data_share()] if self.package == ERD else []


# ``$(optenv NAME default...)`` is xacro for "the environment variable NAME, else the
# default"; husky.urdf still carries two of them. The referee reads the defaults.
_OPTENV = (r"\$\(optenv \w+ ([^)]*)\)", r"\1")

CATALOGUE: list[Robot] = [
    # --- arms (and arms with a gripper)
    Robot("kuka_iiwa", PYBULLET, "kuka_iiwa/model.urdf", "arm: KUKA LBR iiwa 14, 7 DoF"),
    Robot("pb_panda", PYBULLET, "franka_panda/panda.urdf", "arm: Franka Panda + hand (package://meshes)"),
    Robot("xarm6", PYBULLET, "xarm/xarm6_robot.urdf", "arm: UFactory xArm6"),
    Robot("xarm6_gripper", PYBULLET, "xarm/xarm6_with_gripper.urdf", "arm + gripper, <mimic> joints"),
    Robot("ur5", ERD, "ur_description/urdf/ur5_robot.urdf", "arm: Universal Robots UR5"),
    Robot("ur10", ERD, "ur_description/urdf/ur10_robot.urdf", "arm: Universal Robots UR10"),
    Robot("erd_panda", ERD, "panda_description/urdf/panda.urdf", "arm: Franka Panda + hand (DAE meshes)"),
    Robot("kinova", ERD, "kinova_description/robots/kinova.urdf", "arm: Kinova Jaco, continuous joints"),
    Robot("xarm7", ERD, "xarm_description/urdf/xarm7.urdf", "arm: UFactory xArm7"),
    Robot("z1", ERD, "z1_description/urdf/z1.urdf", "arm: Unitree Z1 + gripper"),
    Robot("so101", ERD, "so_arm_description/urdf/so101.urdf", "arm: SO-101 (LeRobot)"),
    Robot("talos_left_arm", ERD, "talos_data/robots/talos_left_arm.urdf", "arm: TALOS left arm + gripper, <mimic>"),
    Robot("baxter", ERD, "baxter_description/urdf/baxter.urdf", "dual arm: Rethink Baxter"),
    # --- grippers and hands
    Robot("pr2_gripper", PYBULLET, "pr2_gripper.urdf", "gripper: PR2"),
    Robot("allegro_hand", ERD, "allegro_hand_description/urdf/allegro_right_hand.urdf", "hand: Allegro, 16 DoF"),
    Robot("finger_edu", ERD, "finger_edu_description/robots/finger_edu.urdf", "finger: TriFinger edu"),
    # --- quadrupeds
    Robot("laikago", PYBULLET, "laikago/laikago_toes_zup.urdf",
          "quadruped: Unitree Laikago (continuous, unaligned axes)"),
    Robot("minitaur", PYBULLET, "quadruped/minitaur.urdf", "quadruped: Ghost Minitaur"),
    Robot("minitaur_rainbow_dash", PYBULLET, "quadruped/minitaur_rainbow_dash_v1.urdf",
          "quadruped: Minitaur, prismatic feet"),
    Robot("pb_a1", PYBULLET, "a1/a1.urdf", "quadruped: Unitree A1"),
    Robot("aliengo", PYBULLET, "aliengo/aliengo.urdf", "quadruped: Unitree Aliengo"),
    Robot("mini_cheetah", PYBULLET, "mini_cheetah/mini_cheetah.urdf", "quadruped: MIT Mini Cheetah"),
    Robot("spirit40", PYBULLET, "quadruped/spirit40.urdf", "quadruped: Ghost Spirit 40"),
    Robot("solo12", ERD, "solo_description/robots/solo12.urdf", "quadruped: ODRI Solo 12"),
    Robot("anymal_c", ERD, "anymal_c_simple_description/urdf/anymal.urdf", "quadruped: ANYbotics ANYmal C"),
    Robot("go1", ERD, "go1_description/urdf/go1.urdf", "quadruped: Unitree Go1"),
    Robot("hyq", ERD, "hyq_description/robots/hyq_no_sensors.urdf", "quadruped: IIT HyQ"),
    Robot("b1_z1", ERD, "b1_description/urdf/b1-z1.urdf", "quadruped + arm: Unitree B1 with Z1"),
    # --- wheeled and mobile robots
    Robot("r2d2", PYBULLET, "r2d2.urdf", "wheeled: R2D2 (continuous wheels, prismatic gripper)"),
    Robot("racecar", PYBULLET, "racecar/racecar.urdf", "wheeled: MIT racecar"),
    Robot("husky", PYBULLET, "husky/husky.urdf", "wheeled: Clearpath Husky", referee_fixups=(_OPTENV,)),
    Robot("tiago", ERD, "tiago_description/robots/tiago_no_hand.urdf", "mobile manipulator: PAL TIAGo"),
    Robot("pr2", ERD, "pr2_description/urdf/pr2.urdf", "mobile manipulator: Willow Garage PR2"),
    # --- bipeds and humanoids
    Robot("bolt", ERD, "bolt_description/robots/bolt.urdf", "biped: ODRI Bolt"),
    Robot("talos", ERD, "talos_data/robots/talos_reduced.urdf", "humanoid: PAL TALOS"),
    Robot("g1", ERD, "g1_description/urdf/g1_29dof_rev_1_0.urdf", "humanoid: Unitree G1, 29 DoF"),
    Robot("icub", ERD, "icub_description/robots/icub_reduced.urdf", "humanoid: iCub"),
    Robot("romeo", ERD, "romeo_description/urdf/romeo_small.urdf", "humanoid: Aldebaran Romeo"),
    # --- textbook chains
    Robot("cartpole", PYBULLET, "cartpole.urdf", "chain: cart-pole (prismatic + continuous)"),
    Robot("pendulum5", PYBULLET, "pendulum5.urdf", "chain: 5-link continuous pendulum"),
    Robot("double_pendulum", ERD, "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
          "chain: double pendulum"),
]

BY_ID = {r.rid: r for r in CATALOGUE}

# ---------------------------------------------------------------------------------------
# The URDF file itself

MOVABLE = ("revolute", "continuous", "prismatic")


@dataclass
class UrdfJoint:
    name: str
    type: str
    parent: str
    child: str
    lower: float | None = None
    upper: float | None = None
    damping: float = 0.0
    friction: float = 0.0
    # <mimic joint multiplier offset>: this joint = multiplier * leader + offset.
    mimic: tuple[str, float, float] | None = None

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE


@dataclass
class UrdfInfo:
    """What the test needs from a URDF's XML: robot name, links, joints (in file order)."""

    name: str
    links: list[str]
    joints: list[UrdfJoint] = field(default_factory=list)

    @classmethod
    def parse(cls, text: str) -> UrdfInfo:
        root = ET.fromstring(text)
        if root.tag != "robot":
            raise ValueError(f"root element is <{root.tag}>, not <robot>")
        info = cls(root.get("name", ""), [link.get("name") for link in root.findall("link")])
        for j in root.findall("joint"):
            uj = UrdfJoint(j.get("name"), j.get("type"), j.find("parent").get("link"), j.find("child").get("link"))
            lim = j.find("limit")
            if lim is not None and lim.get("lower") is not None and lim.get("upper") is not None:
                uj.lower, uj.upper = float(lim.get("lower")), float(lim.get("upper"))
            dyn = j.find("dynamics")
            if dyn is not None:
                uj.damping = float(dyn.get("damping", 0) or 0)
                uj.friction = float(dyn.get("friction", 0) or 0)
            mim = j.find("mimic")
            if mim is not None:
                uj.mimic = (mim.get("joint"), float(mim.get("multiplier", "1")), float(mim.get("offset", "0")))
            info.joints.append(uj)
        return info

    @property
    def movable(self) -> list[UrdfJoint]:
        return [j for j in self.joints if j.movable]

    @property
    def followers(self) -> dict[str, str]:
        """Movable ``<mimic>`` joints whose leader is a movable joint: name -> leader."""
        movable = {j.name for j in self.movable}
        return {j.name: j.mimic[0] for j in self.movable if j.mimic and j.mimic[0] in movable}


def read_urdf_text(robot: Robot) -> str:
    """The file's text with the robot's referee fix-ups applied."""
    text = robot.path.read_text(errors="replace")
    for pattern, repl in robot.referee_fixups:
        text = re.sub(pattern, repl, text)
    return text


# ---------------------------------------------------------------------------------------
# Sampling configurations

# Distance kept from each joint limit, so no implementation's clamping can matter.
LIMIT_MARGIN = 1e-3
# Range of a prismatic joint without limits, metres.
FREE_PRISMATIC = 0.5


def limited(j: UrdfJoint) -> bool:
    """Whether ``j`` has usable limits (continuous joints have none, whatever they say)."""
    return j.type != "continuous" and j.lower is not None and j.upper is not None and j.lower <= j.upper


def joint_range(j: UrdfJoint, margin: float = LIMIT_MARGIN) -> tuple[float, float]:
    """The interval a configuration is drawn from for joint ``j``.

    Continuous joints and revolute joints without usable limits take one turn, open at
    both ends (gantry wraps continuous joints into (-pi, pi]); prismatic joints without
    limits take +-FREE_PRISMATIC. Limits are shrunk by ``margin``; a range narrower than
    two margins collapses to its middle.
    """
    if not limited(j):
        if j.type == "prismatic":
            return -FREE_PRISMATIC, FREE_PRISMATIC
        return -math.pi + LIMIT_MARGIN, math.pi - LIMIT_MARGIN
    lo, hi = j.lower + margin, j.upper - margin
    if lo > hi:
        mid = 0.5 * (j.lower + j.upper)
        return mid, mid
    return lo, hi


def _leader_range(info: UrdfInfo, leader: UrdfJoint) -> tuple[float, float]:
    """Where a ``<mimic>`` leader may go so that each of its followers stays in range.

    Intersects the leader's range with the preimage of each follower's range under
    ``multiplier * leader + offset``. Some files admit no interior point (PR2's
    ``*_gripper_r_parallel_root_joint`` mirrors its leader with the same limits [0,
    0.548], so only 0 fits both): then the URDF limits themselves, without margins.
    """
    followers = [j for j in info.movable if j.mimic and j.mimic[0] == leader.name and j.mimic[1] != 0]
    for margin in (LIMIT_MARGIN, 0.0):
        lo, hi = joint_range(leader, margin)
        for f in followers:
            _, mult, offset = f.mimic
            flo, fhi = joint_range(f, margin)
            a, b = (flo - offset) / mult, (fhi - offset) / mult
            lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
        if lo <= hi:
            return lo, hi
    raise AssertionError(f"{info.name}: no position of {leader.name} keeps its <mimic> joints in their limits")


def _configuration(info: UrdfInfo, pick) -> dict[str, float]:
    """``pick(lo, hi)`` for each independent joint; ``<mimic>`` joints follow their leaders."""
    movable = {j.name: j for j in info.movable}
    followers = info.followers
    leaders = set(followers.values())
    out = {}
    for j in movable.values():
        if j.name not in followers:
            out[j.name] = pick(*(_leader_range(info, j) if j.name in leaders else joint_range(j)))
    for j in movable.values():
        if j.name in followers:
            leader, mult, offset = j.mimic
            if leader not in out:
                raise AssertionError(f"{info.name}: <mimic> chain at {j.name} (leader {leader} mimics too)")
            out[j.name] = mult * out[leader] + offset
    return {j: out[j] for j in movable}


def zero_configuration(info: UrdfInfo) -> dict[str, float]:
    """Every independent joint at 0, or at the nearest point of its range if 0 is
    outside; ``<mimic>`` joints follow their leaders."""
    return _configuration(info, lambda lo, hi: min(max(0.0, lo), hi))


def random_configuration(rng, info: UrdfInfo) -> dict[str, float]:
    """One value per movable joint, uniform in ``joint_range``.

    A ``<mimic>`` joint is not drawn: it is ``multiplier * leader + offset``, with the
    leader drawn where every one of its followers stays in range.
    """
    return _configuration(info, rng.uniform)


# ---------------------------------------------------------------------------------------
# Rotations


def quat_xyzw_to_matrix(q) -> np.ndarray:
    """Rotation matrix of a quaternion given as (x, y, z, w), normalised first."""
    x, y, z, w = (float(c) for c in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def rotation_angle(r_a: np.ndarray, r_b: np.ndarray) -> float:
    """Angle (rad) of the rotation that takes ``r_a`` to ``r_b``.

    It is 2*acos(|<q_a, q_b>|) for the two quaternions, computed as
    atan2(|vee(E - E^T)|/2, (tr E - 1)/2) with E = r_a^T r_b, which keeps full precision
    near zero (acos loses half the digits there).
    """
    e = r_a.T @ r_b
    s = 0.5 * math.sqrt((e[2, 1] - e[1, 2]) ** 2 + (e[0, 2] - e[2, 0]) ** 2 + (e[1, 0] - e[0, 1]) ** 2)
    c = 0.5 * (e[0, 0] + e[1, 1] + e[2, 2] - 1.0)
    return math.atan2(s, c)


def wrap_angle(a: float) -> float:
    """``a`` wrapped into (-pi, pi]."""
    w = math.remainder(a, 2 * math.pi)
    return math.pi if w == -math.pi else w


# ---------------------------------------------------------------------------------------
# The referee


class Referee:
    """Pinocchio's model of one URDF, fixed base, with name-based access.

    ``path`` is the file Pinocchio reads (a fixed-up copy for files that need one);
    ``info`` the same file's XML, for cross-checks and joint ranges.
    """

    def __init__(self, path: Path, info: UrdfInfo):
        import pinocchio as pin

        self.pin = pin
        self.info = info
        self.model = pin.buildModelFromUrdf(str(path))
        self.data = self.model.createData()
        self.continuous: dict[str, bool] = {}
        self.idx_q: dict[str, int] = {}
        self.idx_v: dict[str, int] = {}
        for j in info.movable:
            if not self.model.existJointName(j.name):
                raise AssertionError(f"pinocchio has no joint {j.name!r}")
            jm = self.model.joints[self.model.getJointId(j.name)]
            if jm.nv != 1 or jm.nq not in (1, 2):
                raise AssertionError(f"pinocchio made {j.name!r} a {jm.shortname()} (nq={jm.nq}, nv={jm.nv})")
            self.continuous[j.name] = jm.nq == 2
            self.idx_q[j.name] = jm.idx_q
            self.idx_v[j.name] = jm.idx_v
        self.body_frames = {
            f.name: i for i, f in enumerate(self.model.frames) if f.type == pin.FrameType.BODY
        }

    def check_matches_file(self) -> None:
        """The referee read the same links and movable joints as the XML lists."""
        links = set(self.info.links)
        assert set(self.body_frames) == links, (
            f"pinocchio BODY frames {sorted(set(self.body_frames) ^ links)} differ from the URDF links"
        )
        assert len(self.body_frames) == len(self.info.links), "duplicate link names"
        pin_joints = {self.model.names[i] for i in range(1, self.model.njoints)}
        gantry_fixed = {j.name for j in self.info.joints if j.type in ("floating", "planar")}
        assert pin_joints - gantry_fixed == set(self.idx_q), (
            f"pinocchio joints {sorted(pin_joints)} vs URDF movable joints {sorted(self.idx_q)}"
        )

    def q(self, values: dict[str, float]) -> np.ndarray:
        """Pinocchio's configuration vector: neutral, then one angle or offset per joint."""
        q = self.pin.neutral(self.model)
        for name, v in values.items():
            i = self.idx_q[name]
            if self.continuous[name]:
                q[i], q[i + 1] = math.cos(v), math.sin(v)
            else:
                q[i] = v
        return q

    def values(self, q: np.ndarray) -> dict[str, float]:
        """The inverse of ``q``: one number per movable joint (continuous: atan2)."""
        out = {}
        for name, i in self.idx_q.items():
            out[name] = math.atan2(q[i + 1], q[i]) if self.continuous[name] else float(q[i])
        return out

    def link_poses(self, values: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """World (= robot base) pose of every URDF link: name -> (position, rotation matrix)."""
        self.pin.framesForwardKinematics(self.model, self.data, self.q(values))
        return {
            name: (self.data.oMf[i].translation.copy(), self.data.oMf[i].rotation.copy())
            for name, i in self.body_frames.items()
        }

    # -- passive dynamics

    def joint_inertia(self, values: dict[str, float]) -> np.ndarray:
        """The joint-space inertia matrix M(q) (``pinocchio.crba``, symmetrised)."""
        m = self.pin.crba(self.model, self.data, self.q(values))
        return np.triu(m) + np.triu(m, 1).T

    def damping_stiffness(self, values: dict[str, float], damping: dict[str, float]) -> float:
        """Largest eigenvalue (1/s) of M(q)^-1 D: the fastest decay rate the damping gives.

        An explicit damping torque in a time step dt is accurate only while dt times this
        is small (and unstable beyond 2).
        """
        d = np.zeros(self.model.nv)
        for name, c in damping.items():
            d[self.idx_v[name]] = c
        return float(max(np.linalg.eigvals(np.linalg.solve(self.joint_inertia(values), np.diag(d))).real))

    def simulate(self, start: dict[str, float], dt: float, steps: int, damping: dict[str, float],
                 bounds: dict[str, tuple[float, float]] | None = None,
                 gravity=(0.0, 0.0, -9.81)) -> dict[str, float] | None:
        """Joint positions after ``steps`` steps of free motion from rest.

        Every joint is unactuated except for viscous damping, tau_i = -damping_i * v_i.
        Each step is semi-implicit (symplectic) Euler: a = ABA(q, v, tau);
        v += dt * a; q = integrate(q, dt * v). With ``bounds`` (joint name -> (lo, hi),
        for joints with one coordinate), returns None as soon as a joint leaves its bounds.
        """
        pin = self.pin
        self.model.gravity.linear = np.array(gravity, dtype=float)
        d = np.zeros(self.model.nv)
        for name, c in damping.items():
            d[self.idx_v[name]] = c
        bounds = bounds or {}
        idx = np.array([self.idx_q[n] for n in bounds], dtype=int)
        lo = np.array([b[0] for b in bounds.values()])
        hi = np.array([b[1] for b in bounds.values()])
        q = self.q(start)
        v = np.zeros(self.model.nv)
        for _ in range(steps):
            a = pin.aba(self.model, self.data, q, v, -d * v)
            v = v + dt * a
            q = pin.integrate(self.model, q, dt * v)
            if len(idx) and (np.any(q[idx] < lo) or np.any(q[idx] > hi)):
                return None
        return self.values(q)


def load_referee(robot: Robot, workdir: Path) -> Referee:
    """The referee for a catalogue entry (reading a fixed-up copy if the entry has fix-ups)."""
    text = read_urdf_text(robot)
    info = UrdfInfo.parse(text)
    path = robot.path
    if robot.referee_fixups:
        # Same folder name as the original is not needed: the referee never reads meshes.
        path = workdir / f"{robot.rid}_referee.urdf"
        path.write_text(text)
    return Referee(path, info)


# ---------------------------------------------------------------------------------------
# Modified copies for the dynamics test


def write_dynamics_urdf(src: Path, dst: Path, *, damping: dict[str, float] | None = None,
                        fix: tuple[str, ...] = ()) -> UrdfInfo:
    """Writes the copy of ``src`` that the passive-dynamics test loads, and returns its info.

    * Every ``<visual>`` and ``<collision>`` element is removed. Pinocchio's ABA has no
      contacts; without geometry nothing can touch anything in gantry either (not the
      floor, not another link), so both sides simulate the same contact-free system.
      Masses and inertias come from each link's ``<inertial>``, which is kept.
    * Every joint's ``<dynamics>`` is replaced: a joint named in ``damping`` gets
      ``<dynamics damping="..." friction="0"/>`` with that value, every other joint no
      ``<dynamics>`` element at all, so the undamped copy is undamped even for a file
      that ships damping or friction (kuka_iiwa, xarm6 and erd_panda do).
    * The joints named in ``fix`` become ``fixed`` (gripper fingers: under gravity they
      slide into their limits within milliseconds, and gantry enforces limits while ABA
      does not).
    * ``<transmission>`` and ``<gazebo>`` elements and ``<mimic>`` are dropped (neither
      side simulates them; the arms of the test have none on a joint that stays movable).
    """
    tree = ET.parse(src)
    root = tree.getroot()
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for el in link.findall(tag):
                link.remove(el)
    for tag in ("transmission", "gazebo"):
        for el in root.findall(tag):
            root.remove(el)
    names = {j.get("name") for j in root.findall("joint")}
    damping = damping or {}
    missing = (set(fix) | set(damping)) - names
    if missing:
        raise ValueError(f"{src}: no joints {sorted(missing)}")
    for j in root.findall("joint"):
        for el in j.findall("dynamics"):
            j.remove(el)
        for el in j.findall("mimic"):
            j.remove(el)
        if j.get("name") in fix:
            j.set("type", "fixed")
        elif j.get("name") in damping:
            ET.SubElement(j, "dynamics", {"damping": repr(damping[j.get("name")]), "friction": "0"})
    tree.write(dst, encoding="utf-8", xml_declaration=True)
    return UrdfInfo.parse(dst.read_text())


# ---------------------------------------------------------------------------------------
# The gantry side


class GantryRobot:
    """The objects gantry built for one URDF robot, found through the ZMQ remote API.

    The model base is the root object aliased by the robot name; below it every URDF
    link is a shape and every URDF joint a joint object, each aliased by its URDF name.
    They are found by enumerating the tree (``getObjectsInTree`` with a type filter, then
    ``getObjectAlias``) rather than by path, so link and joint names that collide or
    contain path characters need no escaping.
    """

    def __init__(self, sim, robot_name: str, *, base: int | None = None):
        self.sim = sim
        if base is None:
            roots = sim.getObjectsInTree(sim.handle_scene, sim.handle_all, 2)
            bases = [h for h in roots if sim.getObjectAlias(h) == robot_name]
            if len(bases) != 1:
                raise AssertionError(f"{len(bases)} root objects aliased {robot_name!r} (roots: "
                                     f"{[sim.getObjectAlias(h) for h in roots]})")
            base = bases[0]
        self.base = base
        self.links = self._by_alias(sim.object_shape_type)
        self.joints = self._by_alias(sim.object_joint_type)

    def _by_alias(self, object_type: int) -> dict[str, list[int]]:
        out: dict[str, list[int]] = {}
        for h in self.sim.getObjectsInTree(self.base, object_type):
            out.setdefault(self.sim.getObjectAlias(h), []).append(h)
        return out

    def pose(self, h: int) -> tuple[np.ndarray, np.ndarray]:
        """World pose of object ``h``: (position, rotation matrix), from ``getObjectPose``."""
        p = self.sim.getObjectPose(h, self.sim.handle_world)
        return np.array(p[:3], dtype=float), quat_xyzw_to_matrix(p[3:])
