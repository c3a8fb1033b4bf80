"""Gymnasium environments on gantry simulations.

A :class:`GantryEnv` is a generic ``gymnasium.Env``: a gantry scene plus a small
:class:`Task` that says how to randomise, act on, observe and reward it. The env owns an
in-process :class:`gantry.Client`, created with the env (so it belongs to the env's
thread, as clients do) with real-time pacing off: the simulation advances only when
``step()`` asks, ``Task.steps_per_action`` simulation steps per action, so a run is as
fast as the physics allows and, the physics being deterministic, reproducible.

``reset()`` stops the simulation, which restores the scene as loaded, starts it again and
lets the task look up its handles (``Task.setup``) and draw a random initial state from
the env's seeded ``np_random`` (``Task.reset``): the same seed and the same actions give
the same observations and rewards.

Importing this module registers two ready environments with Gymnasium:

* ``gantry/ArmReach-v0`` (:class:`ArmReach`): the six-axis arm of the ``fk_arm`` scene
  brings its tool tip to a random reachable point.
* ``gantry/BubbleRobAvoid-v0`` (:class:`BubbleRobAvoid`): BubbleRob, without its Lua
  controller, drives around its arena without running into obstacles.

``gymnasium.make_vec`` on either gives a :class:`VectorEnv` (:mod:`gantry.vector`): many
simulations stepped together on a pool of threads in this process.

Units are SI (metres, seconds) and angles are radians, as in the ``sim`` API. Actions of
the ready tasks are normalised to [-1, 1] and scaled by the task (as Gymnasium advises);
observations are ``float32``.

This module gathers what the others define, each in a module of its own so that none
imports one that imports it back: the tasks (:mod:`gantry.tasks`), the env
(:mod:`gantry.env`) and the vector env (:mod:`gantry.vector`, which builds on both).
Import them from here, as before.
"""

from __future__ import annotations

from typing import Any, Optional

import gymnasium

from ._gantry import StepPlan
from .env import GantryEnv
from .tasks import _ARM_REACH_STEPS, _BUBBLE_ROB_STEPS, ArmReach, BubbleRobAvoid, Outcomes, Task
from .vector import VectorEnv

__all__ = [
    "GantryEnv",
    "Outcomes",
    "Task",
    "ArmReach",
    "BubbleRobAvoid",
    "StepPlan",
    "VectorEnv",
    "arm_reach_env",
    "bubble_rob_avoid_env",
]


# --- registration --------------------------------------------------------------------


def arm_reach_env(render_mode: Optional[str] = None, **options: Any) -> GantryEnv:
    """A :class:`GantryEnv` on :class:`ArmReach` (``options`` are its arguments)."""
    return GantryEnv(ArmReach(**options), render_mode=render_mode)


def bubble_rob_avoid_env(render_mode: Optional[str] = None, **options: Any) -> GantryEnv:
    """A :class:`GantryEnv` on :class:`BubbleRobAvoid` (``options`` are its arguments)."""
    return GantryEnv(BubbleRobAvoid(**options), render_mode=render_mode)


# The TimeLimit wrapper that make() adds truncates registered envs (so that
# make(id, max_episode_steps=n) can change the limit); their tasks do not.
# make_vec() builds a gantry.vector.VectorEnv (its vector_entry_point), which applies the
# registered limit itself, as make_vec adds no TimeLimit.
for _id, _entry, _vector_entry, _limit in (
    ("gantry/ArmReach-v0", "gantry.gym:arm_reach_env", "gantry.vector:arm_reach_vector_env", _ARM_REACH_STEPS),
    (
        "gantry/BubbleRobAvoid-v0",
        "gantry.gym:bubble_rob_avoid_env",
        "gantry.vector:bubble_rob_avoid_vector_env",
        _BUBBLE_ROB_STEPS,
    ),
):
    if _id not in gymnasium.registry:
        gymnasium.register(
            _id,
            entry_point=_entry,
            vector_entry_point=_vector_entry,
            max_episode_steps=_limit,
            kwargs={"max_episode_steps": None},
        )
