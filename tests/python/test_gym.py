"""gantry.gym: the Gymnasium API contract, the two registered environments doing what
their tasks say, seeding, custom tasks and input errors. In-process simulations, no
gantry binary needed."""

from __future__ import annotations

import math
import warnings
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.utils.env_checker import check_env

import gantry.gym as gg

ENV_IDS = ["gantry/ArmReach-v0", "gantry/BubbleRobAvoid-v0"]


@pytest.fixture
def make():
    """gymnasium.make, or GantryEnv on a task; every env is closed after the test."""
    envs: list[gymnasium.Env] = []

    def make_env(what: str | gg.Task, **kwargs: Any) -> gymnasium.Env:
        env = gymnasium.make(what, **kwargs) if isinstance(what, str) else gg.GantryEnv(what, **kwargs)
        envs.append(env)
        return env

    yield make_env
    for env in envs:
        env.close()


def rollout(env: gymnasium.Env, seed: int, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Observations and rewards of a seeded random policy, resetting at episode ends."""
    env.action_space.seed(seed)
    obs, _ = env.reset(seed=seed)
    observations, rewards = [obs], []
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        observations.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            obs, _ = env.reset()
            observations.append(obs)
    return np.array(observations), np.array(rewards)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_check_env_passes_without_warnings(make, env_id):
    env = make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_random_rollout_stays_in_bounds(make, env_id):
    env = make(env_id)
    observations, rewards = rollout(env, seed=1, steps=100)
    assert observations.dtype == np.float32
    assert all(env.observation_space.contains(obs) for obs in observations)
    assert np.all(np.isfinite(rewards))
    assert np.ptp(observations, axis=0).max() > 0.01  # the actions moved something


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_actions_same_trajectory(make, env_id):
    obs_a, rewards_a = rollout(make(env_id), seed=5, steps=60)
    obs_b, rewards_b = rollout(make(env_id), seed=5, steps=60)
    np.testing.assert_array_equal(obs_a, obs_b)
    np.testing.assert_array_equal(rewards_a, rewards_b)
    # And the seed matters: another one draws another initial state.
    other, _ = make(env_id).reset(seed=6)
    assert not np.array_equal(other, obs_a[0])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_registered_envs_are_truncated_by_make(make, env_id):
    assert gymnasium.spec(env_id).max_episode_steps is not None
    env = make(env_id, max_episode_steps=3)
    env.reset(seed=0)
    still = np.zeros(env.action_space.shape, dtype=np.float32)
    assert [env.step(still)[3] for _ in range(3)] == [False, False, True]


def test_arm_reach_joint_space_controller_reaches_the_target(make):
    env = make("gantry/ArmReach-v0")
    obs, info = env.reset(seed=3)
    task: gg.ArmReach = env.unwrapped.task
    assert not info["is_success"] and info["distance"] > 0.1
    np.testing.assert_allclose(obs[9:12], task.target)
    distances = [info["distance"]]
    for _ in range(40):
        # Straight towards the configuration the target was drawn from.
        action = np.clip((task.target_config - obs[:6]) / task.max_joint_step, -1, 1)
        obs, reward, terminated, truncated, info = env.step(action)
        distances.append(info["distance"])
        if terminated:
            break
    assert terminated and not truncated and info["is_success"]
    assert info["distance"] < task.tolerance
    assert reward == pytest.approx(task.success_bonus - info["distance"])
    np.testing.assert_allclose(obs[6:9], task.target, atol=task.tolerance)
    assert distances[-1] < distances[0]


def test_bubble_rob_driving_straight_detects_then_hits_an_obstacle(make):
    env = make("gantry/BubbleRobAvoid-v0")
    task: gg.BubbleRobAvoid = env.unwrapped.task
    obs, info = env.reset(seed=4)
    assert obs[0] == 0 and obs[1] == pytest.approx(0.15)
    heading = obs[4:6].copy()
    history = []
    for _ in range(300):
        obs, reward, terminated, truncated, info = env.step([1.0, 1.0])
        history.append((obs, reward))
        if terminated or truncated:
            break
    assert terminated and info["collision"] and info["clearance"] < task.collision_clearance
    assert reward < -task.collision_penalty + 1
    clear = [r for o, r in history[10:-1] if o[0] == 0]
    near = [(o, r) for o, r in history[:-1] if o[0] == 1]
    # Cruising straight at top speed: reward about 1, heading unchanged.
    assert clear and min(clear) > 0.85
    np.testing.assert_allclose(history[len(clear) // 2][0][4:6], heading, atol=0.05)
    # Then the nose sees the obstacle coming closer and the reward falls with it.
    assert len(near) >= 3
    assert near[-1][0][1] < near[0][0][1] - 0.05
    for o, r in near:
        expected = o[6] / task.top_speed - task.proximity_penalty * (1 - o[1] / 0.15)
        assert r == pytest.approx(expected, abs=1e-5)
    assert near[-1][1] < min(clear) - 0.5


def test_bubble_rob_observes_its_current_pose(make):
    env = make("gantry/BubbleRobAvoid-v0").unwrapped
    env.reset(seed=0)
    sim, task = env.sim, env.task
    # Moved without a step to 0.2 m from obstacle0 at (1, 0.3) and facing it: the
    # sensor is read afresh, not left at its reading of the last step.
    sim.setObjectPosition(task.body, [1.0, 0.1, 0.12], sim.handle_world)
    sim.setObjectOrientation(task.body, [0.0, 0.0, math.pi / 2], sim.handle_world)
    obs = task.observe(sim)
    assert obs[0] == 1 and obs[1] == pytest.approx(0.05, abs=0.005)
    np.testing.assert_allclose(obs[2:6], [1.0, 0.1, 0.0, 1.0], atol=1e-6)
    assert task.clearance == pytest.approx(0.05, abs=0.005)  # the body is a 0.1 m sphere


def test_bubble_rob_renders_its_camera(make):
    env = make("gantry/BubbleRobAvoid-v0", render_mode="rgb_array")
    env.reset(seed=4)
    open_floor = env.render()
    assert open_floor.shape == (256, 256, 3) and open_floor.dtype == np.uint8
    for _ in range(120):
        env.step([1.0, 1.0])  # up to a wall, which fills the view
    assert np.abs(env.render().astype(int) - open_floor).mean() > 20
    # Right after a reset the image shows the new pose, not the last step's.
    env.reset(seed=4)
    np.testing.assert_array_equal(env.render(), open_floor)
    with pytest.raises(ValueError, match="render_mode 'rgb_array' is not offered by ArmReach"):
        make("gantry/ArmReach-v0", render_mode="rgb_array")


class JointGoal(gg.Task):
    """Drive the arm's first joint to a random angle, three steps per action."""

    scene = "fk_arm"
    client_options = {"scripts": False}
    steps_per_action = 3
    max_episode_steps = 4
    action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
    observation_space = spaces.Box(-np.pi, np.pi, shape=(2,), dtype=np.float32)

    def __init__(self) -> None:
        self.setups = 0

    def setup(self, sim: Any) -> None:
        self.setups += 1
        self.joint = sim.getObject("/arm6/joint1")

    def reset(self, sim: Any, rng: np.random.Generator) -> None:
        self.goal = rng.uniform(-1.0, 1.0)

    def act(self, sim: Any, action: np.ndarray) -> None:
        sim.setJointTargetPosition(self.joint, float(action[0]))

    def observe(self, sim: Any) -> np.ndarray:
        return np.array([sim.getJointPosition(self.joint), self.goal])

    def reward(self, sim: Any, obs: np.ndarray, action: np.ndarray) -> float:
        return -abs(obs[0] - obs[1])

    def terminated(self, sim: Any, obs: np.ndarray) -> bool:
        return abs(obs[0] - obs[1]) < 1e-3


def test_custom_task(make):
    env = make(JointGoal())
    sim = env.unwrapped.sim
    obs, info = env.reset(seed=0)
    goal = obs[1]
    assert obs.dtype == np.float32 and obs[0] == 0 and -1 <= goal <= 1 and info == {}
    assert env.unwrapped.metadata == {"render_modes": [], "render_fps": pytest.approx(1 / 0.15)}

    obs, reward, terminated, truncated, _ = env.step([0.5])
    assert sim.getSimulationTime() == pytest.approx(0.15)  # steps_per_action steps
    assert obs[0] == pytest.approx(0.5) and reward == pytest.approx(-abs(0.5 - goal))
    assert not terminated and not truncated
    obs, reward, terminated, truncated, _ = env.step([goal])
    assert terminated and reward == pytest.approx(0, abs=1e-6)
    # No early end for max_episode_steps = 4: truncated at the fourth action.
    assert [env.step([0.0])[3] for _ in range(2)] == [False, True]

    # A reset restores the scene (the joint back at 0), sets up again, draws a new goal.
    obs, _ = env.reset()
    assert obs[0] == 0 and obs[1] != goal and env.unwrapped.task.setups == 2
    assert sim.getSimulationTime() == 0
    assert env.reset(seed=0)[0][1] == goal


def test_bad_input_gives_clear_errors(make):
    env = make("gantry/BubbleRobAvoid-v0").unwrapped
    with pytest.raises(RuntimeError, match=r"call reset\(\) before step\(\)"):
        env.step([0.0, 0.0])
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action must have shape \(2,\), got \(3,\)"):
        env.step([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="action must be finite"):
        env.step([math.nan, 0.0])

    class WrongShape(JointGoal):
        def observe(self, sim: Any) -> np.ndarray:
            return np.zeros(3)

    with pytest.raises(ValueError, match=r"WrongShape.observe returned shape \(3,\), not .* \(2,\)"):
        make(WrongShape()).reset()

    paced = JointGoal()
    paced.client_options = {"realtime": True}
    with pytest.raises(ValueError, match=r"client_options may not set \['realtime'\]"):
        make(paced)


def test_actions_are_clipped_to_the_action_space(make):
    def final_obs(action: list[float]) -> np.ndarray:
        env = make("gantry/BubbleRobAvoid-v0")
        env.reset(seed=0)
        for _ in range(10):
            obs, *_ = env.step(action)
        return obs

    np.testing.assert_array_equal(final_obs([10.0, 10.0]), final_obs([1.0, 1.0]))


def test_served_simulation_steps_like_in_process(make):
    # With listeners open the simulation runs on its own thread: only the client's
    # stepping level keeps it from running ahead between calls.
    served = gg.BubbleRobAvoid()
    served.client_options = {"scripts": False, "http_port": 0}
    served_env = make(served)
    assert not served_env.unwrapped.client.in_process
    obs_a, rewards_a = rollout(served_env, seed=8, steps=50)
    obs_b, rewards_b = rollout(make("gantry/BubbleRobAvoid-v0"), seed=8, steps=50)
    np.testing.assert_array_equal(obs_a, obs_b)
    np.testing.assert_array_equal(rewards_a, rewards_b)


def test_close_is_idempotent(make):
    env = make("gantry/ArmReach-v0")
    env.reset(seed=0)
    env.close()
    env.close()
    with pytest.raises(RuntimeError, match="closed"):
        env.reset()
