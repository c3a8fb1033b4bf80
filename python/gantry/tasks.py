"""The tasks of gantry's Gymnasium environments: what an episode on a scene is.

A :class:`Task` says how to randomise, act on, observe and reward a scene; a
:class:`gantry.gym.GantryEnv` runs one on a simulation of its own, and a
:class:`gantry.vector.VectorEnv` runs many. The two ready tasks, :class:`ArmReach` and
:class:`BubbleRobAvoid`, are registered with Gymnasium by :mod:`gantry.gym`, which
re-exports everything here: import them from there.

The tasks live apart from the envs so that :mod:`gantry.env` and :mod:`gantry.vector`
both build on them and :mod:`gantry.gym` on all three, without a module importing one
that imports it back.
"""

from __future__ import annotations

import abc
import math
import os
from types import MappingProxyType
from typing import Any, Mapping, NamedTuple, Optional

import numpy as np
from gymnasium import spaces

from ._gantry import StepPlan

__all__ = ["ArmReach", "BubbleRobAvoid", "Outcomes", "Task"]


class Outcomes(NamedTuple):
    """What the step of ``n`` envs gave, as arrays (:meth:`Task.outcomes`)."""

    #: ``(n, *observation_space.shape)``, ``float32``.
    observations: np.ndarray
    #: ``(n,)``, ``float64``.
    rewards: np.ndarray
    #: ``(n,)``, ``bool``.
    terminated: np.ndarray
    #: Each key of :meth:`Task.info` as an ``(n,)`` array of its values.
    infos: dict[str, np.ndarray]


class Task(abc.ABC):
    """What an episode on a scene is: the spaces, the actions, the observations, the reward.

    A subclass sets ``scene`` (anything :class:`gantry.Client` accepts), the two ``Box``
    spaces (the observation space ``float32``) and implements :meth:`act`,
    :meth:`observe` and :meth:`reward`. After each action the env steps the simulation
    ``steps_per_action`` times, then calls :meth:`observe`, :meth:`reward`,
    :meth:`terminated` and :meth:`info` in that order, so a task may keep what
    :meth:`observe` measured for the others.
    """

    scene: str | os.PathLike
    #: Extra :class:`gantry.Client` arguments (``scripts=False``, ``http_port=0``...);
    #: not ``realtime`` or ``autostart``, which the env sets.
    client_options: Mapping[str, Any] = MappingProxyType({})
    #: Simulation steps per action.
    steps_per_action: int = 1
    #: Actions after which ``step()`` reports truncation; None for never.
    max_episode_steps: Optional[int] = None
    #: Path of a vision sensor that ``render_mode="rgb_array"`` shows; None for no rendering.
    camera: Optional[str] = None
    observation_space: spaces.Box
    action_space: spaces.Box

    def setup(self, sim: Any) -> None:
        """Called after each (re)start of the simulation: look up handles here (objects
        made during a run, such as collections, are gone after a restart)."""

    def reset(self, sim: Any, rng: np.random.Generator) -> None:
        """Randomises the initial state of an episode, drawing only from ``rng``."""

    def plan(self, sim: Any) -> Optional[StepPlan]:
        """Optionally, what :meth:`act`, the steps and :meth:`observe` do, as a
        :class:`StepPlan` of ``sim`` calls (asked after :meth:`setup`; ``None``, the
        default, for none). An in-process env then runs each action in one call with the
        GIL released, so that threads (:class:`gantry.vector.VectorEnv`) overlap the whole
        step, not just the physics; :meth:`observation` turns its numbers into the
        observation. The plan must do exactly what ``act`` and ``observe`` do (a test
        should compare the two): served simulations, and the first observation of an
        episode, still use them. Needs a ``float32`` action space."""
        return None

    def observation(self, values: np.ndarray) -> np.ndarray:
        """The observation from the numbers a :meth:`plan` observed (``float64``, in the
        order of its observe calls), as :meth:`observe` would return it; like ``observe``,
        it may keep measurements for :meth:`reward` and the others. Default: as they are."""
        return values

    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> Optional[Outcomes]:
        """Optionally, :meth:`observation`, :meth:`reward`, :meth:`terminated` and
        :meth:`info` of many envs of this task at once, from their plans' numbers (one
        row each, ``(n, m)``) and their actions (``(n, *action_shape)``); ``None``, the
        default, for none. :class:`gantry.vector.VectorEnv` then computes a block's
        outcomes in a few numpy operations instead of a Python call per env, the part of
        a step that holds the GIL. Each row must come out exactly as the four methods
        give it for one env (the vector env's tests compare them bit for bit), and may
        depend only on the task's settings, which the envs of a vector env share, not on
        what one episode keeps (the methods' measurements are not kept)."""
        return None

    @abc.abstractmethod
    def act(self, sim: Any, action: np.ndarray) -> None:
        """Applies an action, already checked and clipped to ``action_space``."""

    @abc.abstractmethod
    def observe(self, sim: Any) -> np.ndarray:
        """The observation, of the shape of ``observation_space``."""

    @abc.abstractmethod
    def reward(self, sim: Any, obs: np.ndarray, action: np.ndarray) -> float:
        """The reward for the action that led to ``obs``."""

    def terminated(self, sim: Any, obs: np.ndarray) -> bool:
        """Whether the episode has ended (success or failure)."""
        return False

    def info(self, sim: Any, obs: np.ndarray) -> dict[str, Any]:
        """Diagnostics returned alongside ``obs``."""
        return {}


# --- ArmReach ------------------------------------------------------------------------


def _box(low: list[float], high: list[float]) -> spaces.Box:
    return spaces.Box(np.array(low, dtype=np.float32), np.array(high, dtype=np.float32), dtype=np.float32)


# arm6.urdf's limits; joints 1, 4 and 6 are continuous and read back wrapped to [-pi, pi].
_ARM_JOINT_LOW = [-math.pi, math.radians(-110), math.radians(-50), -math.pi, math.radians(-120), -math.pi]
_ARM_JOINT_HIGH = [math.pi, math.radians(90), math.radians(230), math.pi, math.radians(120), math.pi]
# Everywhere the tip can be: shoulder at (0.07, 0, 0.352), 0.8 m from shoulder to tip.
_ARM_TIP_LOW = [-1.0, -1.0, -0.5]
_ARM_TIP_HIGH = [1.0, 1.0, 1.2]
_ARM_REACH_STEPS = 200  # 10 s


class ArmReach(Task):
    """The ``fk_arm`` arm brings its tool tip within ``tolerance`` of a random target.

    The target (``target``) is the tip position of a random joint configuration
    (``target_config``) within ``target_spread`` rad of the start pose on each joint and at least
    ``min_target_height`` above the floor, so it is always reachable. Action: joint
    position increments in [-1, 1], times ``max_joint_step`` rad per action (the joints are
    kinematic: they reach their target within the step). Observation: the six joint
    positions (rad), the tip position and the target position (m, world frame). Reward:
    minus the tip-target distance (m), plus ``success_bonus`` on reaching the target, which
    ends the episode.
    """

    scene = "fk_arm"
    client_options = MappingProxyType({"scripts": False})

    def __init__(
        self,
        *,
        tolerance: float = 0.02,
        max_joint_step: float = 0.1,
        target_spread: float = 1.0,
        min_target_height: float = 0.1,
        success_bonus: float = 10.0,
        max_episode_steps: Optional[int] = _ARM_REACH_STEPS,
    ):
        self.tolerance = tolerance
        self.max_joint_step = max_joint_step
        self.target_spread = target_spread
        self.min_target_height = min_target_height
        self.success_bonus = success_bonus
        self.max_episode_steps = max_episode_steps
        self.action_space = spaces.Box(-1.0, 1.0, shape=(6,), dtype=np.float32)
        self.observation_space = _box(
            _ARM_JOINT_LOW + _ARM_TIP_LOW + _ARM_TIP_LOW, _ARM_JOINT_HIGH + _ARM_TIP_HIGH + _ARM_TIP_HIGH
        )
        self.target_config = np.zeros(6)
        self.target = np.zeros(3)
        self.distance = math.inf  # tip to target (m), as of the last observation

    def setup(self, sim: Any) -> None:
        self.joints = [sim.getObject(f"/arm6/joint{i}") for i in range(1, 7)]
        self.tip = sim.getObject("/arm6/tip/tip")  # the scene's tip_frame dummy
        self.target_dummy = sim.getObject("/target")

    def _config(self, sim: Any) -> np.ndarray:
        return np.array(self._config_list(sim))

    def _config_list(self, sim: Any) -> list[float]:
        return [sim.getJointPosition(j) for j in self.joints]

    def _set_config(self, sim: Any, config: np.ndarray) -> None:
        for joint, q in zip(self.joints, config):
            sim.setJointPosition(joint, float(q))

    def reset(self, sim: Any, rng: np.random.Generator) -> None:
        start = self._config(sim)
        low, high = np.array(_ARM_JOINT_LOW), np.array(_ARM_JOINT_HIGH)
        # Kinematic joints move at once, so the tip's position is read back directly.
        for _ in range(1000):
            config = np.clip(start + rng.uniform(-self.target_spread, self.target_spread, 6), low, high)
            self._set_config(sim, config)
            tip = np.array(sim.getObjectPosition(self.tip, sim.handle_world))
            if tip[2] >= self.min_target_height:
                break
        else:
            raise ValueError(f"no target found at least {self.min_target_height} m above the floor")
        self._set_config(sim, start)
        self.target_config, self.target = config, tip
        # The target dummy shows it in the viewer, and the observation reads it back.
        sim.setObjectPosition(self.target_dummy, tip.tolist(), sim.handle_world)

    # Per step, plain lists rather than small numpy arrays: this Python runs with the GIL
    # held, the part of a step that threads (gantry.vector) cannot overlap.

    def act(self, sim: Any, action: np.ndarray) -> None:
        # The simulator clamps limited joints and wraps the continuous ones.
        increments = (action * self.max_joint_step).tolist()
        for joint, q, dq in zip(self.joints, self._config_list(sim), increments):
            sim.setJointTargetPosition(joint, q + dq)

    def observe(self, sim: Any) -> np.ndarray:
        tip = sim.getObjectPosition(self.tip, sim.handle_world)
        target = sim.getObjectPosition(self.target_dummy, sim.handle_world)
        return self.observation(np.array(self._config_list(sim) + tip + target))

    def plan(self, sim: Any) -> StepPlan:
        # act and observe above, call for call.
        world = sim.handle_world
        return StepPlan(
            act=[
                ("sim.setJointTargetPosition", joint, "sim.getJointPosition", k, self.max_joint_step)
                for k, joint in enumerate(self.joints)
            ],
            steps=self.steps_per_action,
            observe=[
                *(("sim.getJointPosition", [joint]) for joint in self.joints),
                ("sim.getObjectPosition", [self.tip, world]),
                ("sim.getObjectPosition", [self.target_dummy, world]),
            ],
        )

    def observation(self, values: np.ndarray) -> np.ndarray:
        # Kept for reward, terminated and info, which follow (in double precision), and
        # computed as `outcomes` computes it, operation for operation, so that the two
        # agree to the bit (math.dist rounds differently).
        v = values.tolist()
        dx, dy, dz = v[6] - v[9], v[7] - v[10], v[8] - v[11]
        self.distance = math.sqrt(dx * dx + dy * dy + dz * dz)
        return values

    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> Outcomes:
        d = values[:, 6:9] - values[:, 9:12]
        distance = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
        success = distance < self.tolerance
        return Outcomes(
            observations=values.astype(np.float32),
            rewards=-distance + np.where(success, self.success_bonus, 0.0),
            terminated=success,
            infos={"distance": distance, "is_success": success},
        )

    def reward(self, sim: Any, obs: np.ndarray, action: np.ndarray) -> float:
        return -self.distance + (self.success_bonus if self.distance < self.tolerance else 0.0)

    def terminated(self, sim: Any, obs: np.ndarray) -> bool:
        return self.distance < self.tolerance

    def info(self, sim: Any, obs: np.ndarray) -> dict[str, Any]:
        return {"distance": self.distance, "is_success": self.distance < self.tolerance}


# --- BubbleRobAvoid ------------------------------------------------------------------

_NOSE_RANGE = 0.15  # m, the sensingNose's range in bubble_rob.toml
_WHEEL_RADIUS = 0.04  # m
_BUBBLE_ROB_STEPS = 400  # 40 s


class BubbleRobAvoid(Task):
    """BubbleRob (``bubble_rob`` without its Lua controller) drives fast without hitting
    anything.

    Each episode starts at a random position within ``start_spread`` m of the arena's
    centre with a random heading. Action: the left and right wheel target velocities in
    [-1, 1], times ``max_wheel_speed`` rad/s; each lasts two steps (0.1 s). Observation:
    whether the nose sensor detects something (0 or 1), the detected distance (m, its
    range of 0.15 m when nothing is detected), the position x, y (m), the heading as cos
    and sin, the forward speed (m/s) and the yaw rate (rad/s), the last two clipped to
    their bounds. Reward: the forward speed as a fraction of the top speed, minus
    ``proximity_penalty`` times how far into the sensor's range the detected object is
    (0 at its edge, 1 on contact); a collision (clearance below ``collision_clearance``
    m between the rover and any other object) costs ``collision_penalty`` and ends the
    episode.
    """

    scene = "bubble_rob"
    client_options = MappingProxyType({"scripts": False})
    steps_per_action = 2
    camera = "/bubbleRob/visionSensor"

    def __init__(
        self,
        *,
        max_wheel_speed: float = 5.0,
        start_spread: float = 0.5,
        proximity_penalty: float = 2.0,
        collision_penalty: float = 10.0,
        collision_clearance: float = 0.005,
        max_episode_steps: Optional[int] = _BUBBLE_ROB_STEPS,
    ):
        self.max_wheel_speed = max_wheel_speed
        self.start_spread = start_spread
        self.proximity_penalty = proximity_penalty
        self.collision_penalty = collision_penalty
        self.collision_clearance = collision_clearance
        self.max_episode_steps = max_episode_steps
        self.top_speed = max_wheel_speed * _WHEEL_RADIUS
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        # Walls' inner faces at 2.4 m; speeds at twice the top speed allow for bumps.
        self.observation_space = _box(
            [0, 0, -2.5, -2.5, -1, -1, -2 * self.top_speed, -10.0],
            [1, _NOSE_RANGE, 2.5, 2.5, 1, 1, 2 * self.top_speed, 10.0],
        )
        self.clearance = math.inf

    def setup(self, sim: Any) -> None:
        self.body = sim.getObject("/bubbleRob")
        self.motors = [sim.getObject("/bubbleRob/leftMotor"), sim.getObject("/bubbleRob/rightMotor")]
        self.nose = sim.getObject("/bubbleRob/sensingNose")
        self.rover = sim.createCollection(0)
        sim.addItemToCollection(self.rover, sim.handle_tree, self.body, 0)

    def reset(self, sim: Any, rng: np.random.Generator) -> None:
        x, y = rng.uniform(-self.start_spread, self.start_spread, 2)
        heading = rng.uniform(-math.pi, math.pi)
        z = sim.getObjectPosition(self.body, sim.handle_world)[2]
        # Moving the model base before the first step carries the wheels and caster along.
        sim.setObjectPosition(self.body, [float(x), float(y), z], sim.handle_world)
        sim.setObjectOrientation(self.body, [0.0, 0.0, float(heading)], sim.handle_world)

    def act(self, sim: Any, action: np.ndarray) -> None:
        # Scaled in single precision, as the step plan does.
        for motor, speed in zip(self.motors, (action * self.max_wheel_speed).tolist()):
            sim.setJointTargetVelocity(motor, speed)

    def _queries(self, sim: Any) -> list[tuple[str, list[Any]]]:
        """What an observation reads, in order: the nose sensor (9 numbers), the body's
        matrix (12), its velocity (6) and its clearance (10)."""
        world = sim.handle_world
        return [
            # Sensed explicitly so that the observation after reset() reflects the new pose.
            ("sim.handleProximitySensor", [self.nose]),
            ("sim.getObjectMatrix", [self.body, world]),
            ("sim.getObjectVelocity", [self.body]),
            ("sim.checkDistance", [self.rover, sim.handle_all]),
        ]

    def observe(self, sim: Any) -> np.ndarray:
        values: list[float] = []
        for name, args in self._queries(sim):
            for v in _as_tuple(getattr(sim, name[4:])(*args)):
                values.extend(v if isinstance(v, list) else [v])
        return self.observation(np.array(values, dtype=np.float64))

    def plan(self, sim: Any) -> StepPlan:
        # act and observe above, call for call.
        return StepPlan(
            act=[
                ("sim.setJointTargetVelocity", motor, None, k, self.max_wheel_speed)
                for k, motor in enumerate(self.motors)
            ],
            steps=self.steps_per_action,
            observe=self._queries(sim),
        )

    # Observation and outcomes use only +, -, *, / and sqrt (the heading's cosine and
    # sine from the body's x axis, not trigonometry), so that the per-env methods and the
    # batched `outcomes` agree to the bit: numpy's and libm's cos and atan2 need not.

    def observation(self, values: np.ndarray) -> np.ndarray:
        v = values.tolist()
        detected, distance = v[0], v[1]
        if detected <= 0:
            distance = _NOSE_RANGE
        m = v[9:21]
        # The heading: the body's x axis (its forward direction) in the floor plane.
        cx, cy = m[0], m[4]
        norm = math.sqrt(cx * cx + cy * cy)
        cos_h, sin_h = (cx / norm, cy / norm) if norm > 0 else (1.0, 0.0)
        vx, vy, yaw_rate = v[21], v[22], v[26]
        forward = vx * cos_h + vy * sin_h
        # checkDistance: result, then [p1, p2, distance]
        self.clearance = v[34] if v[27] > 0 else math.inf
        obs = np.array([detected > 0, distance, m[3], m[7], cos_h, sin_h, forward, yaw_rate], dtype=np.float32)
        return np.clip(obs, self.observation_space.low, self.observation_space.high)

    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> Outcomes:
        detected = values[:, 0] > 0
        distance = np.where(detected, values[:, 1], _NOSE_RANGE)
        cx, cy = values[:, 9], values[:, 13]
        norm = np.sqrt(cx * cx + cy * cy)
        level = norm > 0
        safe = np.where(level, norm, 1.0)
        cos_h, sin_h = np.where(level, cx / safe, 1.0), np.where(level, cy / safe, 0.0)
        forward = values[:, 21] * cos_h + values[:, 22] * sin_h
        clearance = np.where(values[:, 27] > 0, values[:, 34], math.inf)
        columns = (detected.astype(np.float64), distance, values[:, 12], values[:, 16], cos_h, sin_h, forward, values[:, 26])
        obs = np.clip(np.stack(columns, axis=1).astype(np.float32), self.observation_space.low, self.observation_space.high)
        o = obs.astype(np.float64)
        collided = clearance < self.collision_clearance
        rewards = o[:, 6] / self.top_speed
        rewards = np.where(o[:, 0] > 0, rewards - self.proximity_penalty * (1.0 - o[:, 1] / _NOSE_RANGE), rewards)
        rewards = rewards - np.where(collided, self.collision_penalty, 0.0)
        return Outcomes(obs, rewards, collided, {"clearance": clearance, "collision": collided})

    def _collided(self) -> bool:
        return self.clearance < self.collision_clearance

    def reward(self, sim: Any, obs: np.ndarray, action: np.ndarray) -> float:
        reward = float(obs[6]) / self.top_speed
        if obs[0] > 0:
            reward -= self.proximity_penalty * (1.0 - float(obs[1]) / _NOSE_RANGE)
        return reward - (self.collision_penalty if self._collided() else 0.0)

    def terminated(self, sim: Any, obs: np.ndarray) -> bool:
        return self._collided()

    def info(self, sim: Any, obs: np.ndarray) -> dict[str, Any]:
        return {"clearance": self.clearance, "collision": self._collided()}


def _as_tuple(reply: Any) -> tuple[Any, ...]:
    """A ``sim`` call's results as a tuple (one result comes as itself)."""
    return reply if isinstance(reply, tuple) else (reply,)
