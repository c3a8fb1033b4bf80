"""The Gymnasium environment on one gantry simulation: :class:`GantryEnv`.

Imported from :mod:`gantry.gym`, which describes it with the ready tasks it registers;
it is a module of its own so that :mod:`gantry.vector` can build on it while
:mod:`gantry.gym` re-exports the vector env.
"""

from __future__ import annotations

from typing import Any, Optional

import gymnasium
import numpy as np
from gymnasium import spaces

from . import Client
from ._gantry import StepPlan
from .tasks import Task

__all__ = ["GantryEnv"]


class GantryEnv(gymnasium.Env[np.ndarray, np.ndarray]):
    """A Gymnasium environment running ``task`` on its scene in this process.

    ``client`` and ``sim`` give the simulation itself (for diagnostics; actions should go
    through ``step``). ``render_mode="rgb_array"`` is offered when the task names a
    camera: ``render()`` returns its ``(height, width, 3)`` ``uint8`` image. ``step()``
    reports truncation after the task's ``max_episode_steps`` actions. Like its client,
    the env belongs to the thread that made it.
    """

    # What make() reads before building an env; each env narrows it to what its task offers.
    metadata: dict[str, Any] = {"render_modes": ["rgb_array"]}

    def __init__(self, task: Task, render_mode: Optional[str] = None):
        name = type(task).__name__
        if not isinstance(task.action_space, spaces.Box) or not isinstance(task.observation_space, spaces.Box):
            raise TypeError(f"{name}'s action_space and observation_space must be gymnasium.spaces.Box")
        if task.observation_space.dtype != np.float32:
            raise TypeError(f"{name}'s observation_space must be float32, not {task.observation_space.dtype}")
        fixed = sorted({"realtime", "autostart"} & set(task.client_options))
        if fixed:
            raise ValueError(f"client_options may not set {fixed}: GantryEnv steps the simulation itself")
        render_modes = ["rgb_array"] if task.camera is not None else []
        if render_mode is not None and render_mode not in render_modes:
            raise ValueError(f"render_mode {render_mode!r} is not offered by {name} (offered: {render_modes})")

        self.task = task
        self.action_space = task.action_space
        self.observation_space = task.observation_space
        self.render_mode = render_mode
        self.client = Client(task.scene, realtime=False, autostart=False, **task.client_options)
        self.sim: Any = self.client.require("sim")
        dt = self.sim.getSimulationTimeStep()
        self.metadata = {"render_modes": render_modes, "render_fps": 1.0 / (dt * task.steps_per_action)}
        self._camera = -1
        self._steps: Optional[int] = None  # actions since the last reset; None before the first
        self._plan: Optional[StepPlan] = None

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Restarts the scene as loaded and randomises it; ``options`` is unused."""
        super().reset(seed=seed)
        self.sim.stopSimulation()
        # A stop resets the client's stepping level. Stepping matters when the client
        # serves listeners (http_port...): the simulation thread would otherwise run free.
        self.client.setStepping(True)
        self.sim.startSimulation()
        if self.task.camera is not None:
            self._camera = self.sim.getObject(self.task.camera)
        self.task.setup(self.sim)
        self._plan = self.task.plan(self.sim) if self.client.in_process else None
        if self._plan is not None and self._plan.steps != self.task.steps_per_action:
            raise ValueError(
                f"{type(self.task).__name__}.plan() takes {self._plan.steps} steps per action, "
                f"not steps_per_action={self.task.steps_per_action}"
            )
        self.task.reset(self.sim, self.np_random)
        self._steps = 0
        obs = self._observe()
        return obs, self.task.info(self.sim, obs)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._steps is None:
            raise RuntimeError("call reset() before step()")
        return self._step_checked(self._checked_action(action))

    def _step_checked(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """``step()`` on an action already checked and clipped (as :class:`VectorEnv`
        does for all its envs at once)."""
        if self._plan is not None:
            # act, the steps and observe's calls in one call, with the GIL released.
            return self._planned(action, self.client._engine_here.run_plan(self._plan, action))
        self.task.act(self.sim, action)
        for _ in range(self.task.steps_per_action):
            self.sim.step()
        return self._outcome(action, self._observe())

    def _planned(self, action: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """The rest of ``step()`` once the plan has run (here or, for a vector env's
        block, together with its neighbours')."""
        return self._outcome(action, self._shaped(self.task.observation(values)))

    def _outcome(self, action: np.ndarray, obs: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        self._steps += 1
        reward = float(self.task.reward(self.sim, obs, action))
        terminated = bool(self.task.terminated(self.sim, obs))
        limit = self.task.max_episode_steps
        truncated = limit is not None and self._steps >= limit
        return obs, reward, terminated, truncated, self.task.info(self.sim, obs)

    def render(self) -> Optional[np.ndarray]:
        if self.render_mode is None:
            return None
        if self._steps is None:
            raise RuntimeError("call reset() before render()")
        # The image as of the last step, row 0 on top; copied so that kept frames stay put.
        return self.client.image(self._camera).copy()

    def close(self) -> None:
        self.client.close()

    def _checked_action(self, action: Any) -> np.ndarray:
        space = self.action_space
        a = np.asarray(action, dtype=np.float64)
        if a.shape != space.shape:
            raise ValueError(f"action must have shape {space.shape}, got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"action must be finite, got {a}")
        return np.clip(a, space.low, space.high).astype(space.dtype)

    def _observe(self) -> np.ndarray:
        return self._shaped(self.task.observe(self.sim))

    def _shaped(self, observation: Any) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float32)
        if obs.shape != self.observation_space.shape:
            raise ValueError(
                f"{type(self.task).__name__}.observe returned shape {obs.shape}, "
                f"not the observation space's {self.observation_space.shape}"
            )
        return obs
