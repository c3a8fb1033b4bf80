"""Many gantry environments in one process: a Gymnasium vector environment.

A :class:`VectorEnv` runs ``num_envs`` :class:`gantry.gym.GantryEnv` simulations of one
task on ``num_threads`` threads and steps them all in one call: ``step(actions)`` takes a
``(num_envs, *action_shape)`` batch and returns the observations as one
``(num_envs, *observation_shape)`` ``float32`` array, with the rewards, terminations and
truncations as arrays, as Gymnasium's vector API (``gymnasium.vector.VectorEnv``) has it.

The design, and why:

* A :class:`gantry.Client` belongs to the thread that made it (its Lua state cannot move
  between threads), so the envs are split into contiguous blocks, one per thread, and
  each thread makes its block's envs and drives them for its whole life: persistent
  workers, fed through queues, rather than a pool that would hand an env to any thread.
  The caller's thread drives the first block itself (one thread fewer to wake, and one
  thread means no worker at all).
* Only what runs without the GIL overlaps. The physics steps release it; the task's
  Python (``act``, ``observe``, ``reward``) holds it, so that part runs one thread at a
  time and bounds the speed-up at (Python + physics) / Python. For BubbleRob the physics
  dominates; for the kinematic arm of ArmReach a step is a few microseconds and its
  dozen ``sim`` calls from Python cost more. So a task may give its ``act`` / steps /
  ``observe`` as a step plan (:meth:`gantry.gym.Task.plan`: the same registry calls, made
  by the extension), and a block whose envs all have one runs them a few envs at a time
  (about ``_PLAN_SLICE`` of work) in one call with the GIL released: few hand-overs of
  the GIL, and one thread's Python overlaps the others' plans.
* A task may also give its observations, rewards, endings and infos for many envs at
  once, as arrays (:meth:`gantry.gym.Task.outcomes`). Then a block's Python part is a
  few numpy operations, whatever its size, and the worker threads need no Python at all
  between resets: each is parked outside Python (``PlanServer``, ``Engine.serve_plans``),
  takes the batch of actions for its block from a channel, runs its plans and sends the
  numbers back, while the caller's thread runs its own block; the caller then does every
  block's numpy part. No GIL hand-over and no Python thread wake-up per step (together a
  few hundred microseconds on a 2-core VM, more than a block of ArmReach's steps). A
  step that resets an env, and any other command, brings the workers back to Python.
* What stays in Python is kept small: actions are checked and clipped once for the
  batch, each thread writes its observations, rewards and flags straight into the
  batch arrays (its own rows), and the infos are batched per key in one go.

Results are those of ``num_envs`` separate ``GantryEnv``s given the same seeds and
actions, bit for bit, whatever ``num_threads``: each env is an independent simulation
with its own random generator, the physics is deterministic, and a single ``GantryEnv``
runs the same step plan. tools/bench/vector_env.py measures the speed-up.

Gymnasium's conventions are kept: ``reset(seed=s)`` seeds env ``i`` with ``s + i`` (a
list gives one seed per env); ``autoreset_mode`` is ``NEXT_STEP`` by default (an env that
ended is reset by the *next* ``step()``, which ignores its action and reports the reset
observation, reward 0 and no ending), or ``SAME_STEP`` (reset at once, the ending
observation and info in ``info["final_obs"]`` and ``info["final_info"]``), or
``DISABLED`` (reset ended envs with ``reset(options={"reset_mask": mask})``). An
exception in a worker (a task's bug, a failing ``sim`` call) is raised by the call that
caused it, naming the env. ``close()`` closes every env in its own thread and joins the
workers.

Importing :mod:`gantry.gym` registers ``vector_entry_point``\\ s, so that::

    gymnasium.make_vec("gantry/BubbleRobAvoid-v0", num_envs=4)
    gymnasium.make_vec("gantry/ArmReach-v0", num_envs=8, vectorization_mode="vector_entry_point",
                       num_threads=2)

return a :class:`VectorEnv` (``num_threads`` defaults to the number of cores, at most
``num_envs``; for ArmReach, whose steps are cheaper than handing them to another thread,
one thread per 8 envs). Episodes are truncated after the registered limit, as ``make`` does with
its ``TimeLimit``, unless ``max_episode_steps`` says otherwise.
"""

from __future__ import annotations

import os
import queue
import threading
import time
import traceback
import weakref
from typing import Any, Callable, NamedTuple, Optional, Sequence, Union

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from ._gantry import Engine, PlanServer
from .env import GantryEnv
from .tasks import _ARM_REACH_STEPS, _BUBBLE_ROB_STEPS, ArmReach, BubbleRobAvoid, Task

__all__ = ["VectorEnv", "arm_reach_vector_env", "bubble_rob_avoid_vector_env"]

# How long the caller waits for a worker before checking that it is still alive (s).
_POLL = 1.0
# How long one call of step plans should last (s): a block runs its envs' plans a few
# envs at a time, as many as take about this long, then their Python parts
# (observation, reward) with the GIL held, while the other threads' plans run. One env
# per call would hand the GIL over twice per env, too often for ArmReach's
# few-microsecond steps (a hand-over wakes a thread: tens of microseconds); the whole
# block per call would leave the threads' Python parts to pile up at the end of the
# step instead of overlapping the others' plans. A task that gives its outcomes as arrays
# (Task.outcomes) has a Python part that hardly grows with the envs (a few numpy
# operations per call): its blocks run whole, one call each (ArmReach, 64 envs on 2
# threads: 79,000 env steps/s whole, 76,000 in slices of 200 us, 56,500 of 100 us).
_PLAN_SLICE = 200e-6


class _Infos(NamedTuple):
    """The infos of several envs at once (from :meth:`gantry.gym.Task.outcomes`): each
    key's values for the envs ``envs`` (vector env indices), as arrays."""

    envs: np.ndarray
    values: dict[str, np.ndarray]


# What a block's step or reset reports of its envs' infos: ``(env, info)`` pairs, and
# ``_Infos`` for those whose task gave them as arrays.
_InfoPiece = Union[tuple[int, dict[str, Any]], _Infos]


class _WorkerError(Exception):
    """A failure in a block of envs, carried back to the caller's thread."""

    def __init__(self, env: Optional[int], error: BaseException):
        super().__init__(env, error)
        self.env = env
        self.error = error


def _check_outcomes(task: Task, out: Any, obs_shape: tuple[int, ...], env: int) -> None:
    """That ``task.outcomes`` gave arrays of the batch's shapes and types; a clear error
    (naming the first env of the batch) otherwise."""
    n = obs_shape[0]
    wanted = (
        ("observations", out.observations, obs_shape, np.float32),
        ("rewards", out.rewards, (n,), np.float64),
        ("terminated", out.terminated, (n,), np.bool_),
    )
    for name, array, shape, dtype in wanted:
        if not isinstance(array, np.ndarray) or array.shape != shape or array.dtype != dtype:
            got = f"{array.shape} {array.dtype}" if isinstance(array, np.ndarray) else type(array).__name__
            problem = f"{name} must be a {shape} {np.dtype(dtype)} array, got {got}"
            raise _WorkerError(env, ValueError(f"{type(task).__name__}.outcomes: {problem}"))
    for key, array in out.infos.items():
        if not isinstance(array, np.ndarray) or array.shape != (n,):
            problem = f"info {key!r} must be an ({n},) array"
            raise _WorkerError(env, ValueError(f"{type(task).__name__}.outcomes: {problem}"))


class _Block:
    """Contiguous envs made and driven by one thread; its methods run in that thread.
    Results go straight into the vector env's batch arrays (each block its own rows);
    infos come back as ``(env, info)`` pairs, or as arrays (``_Infos``) from a task's
    ``outcomes``, batched by the caller."""

    def __init__(self, index: int, envs: range, vec: "VectorEnv"):
        self.index = index
        self.indices = envs
        self.envs: list[GantryEnv] = []
        self._engines: list[Any] = []  # the envs' engines, for Engine.run_plans
        self._chunk = 1  # envs per call of step plans (see _PLAN_SLICE)
        # Whether the task gives its outcomes as arrays (Task.outcomes): then the whole
        # block's plans run in one call, followed by one numpy pass over the block.
        self._batching = False
        self._plan_time = _PLAN_SLICE  # running mean of one env's plan (s)
        # Weak: the vector env owns its blocks, and without a cycle it is freed (and
        # closes) in the thread that drops it, not in whichever runs the collector.
        self._vec: "VectorEnv" = weakref.proxy(vec)

    def make(self, make: Callable[[], GantryEnv]) -> None:
        for i in self.indices:
            try:
                self.envs.append(make())
            except Exception as e:
                raise _WorkerError(i, e) from e
        # Taken once, in this thread (which owns them): a client's engine is its for life.
        self._engines = [env.client._engine_here for env in self.envs]

    def close(self) -> None:
        # Dropped here, in their thread: an engine freed by another thread is an error.
        self._engines.clear()
        for env in self.envs:
            try:
                env.close()
            except Exception:  # noqa: BLE001 - the others still close
                pass
        self.envs.clear()

    def reset(
        self, seeds: Sequence[Optional[int]], options: Optional[dict], mask: Optional[np.ndarray]
    ) -> list[tuple[int, dict]]:
        vec, infos = self._vec, []
        for env, i in zip(self.envs, self.indices):
            if mask is not None and not mask[i]:
                continue
            try:
                vec._obs[i], info = env.reset(seed=seeds[i], options=options)
            except Exception as e:
                raise _WorkerError(i, e) from e
            infos.append((i, info))
        return infos

    def step(self, actions: np.ndarray) -> list[_InfoPiece]:
        infos: list[_InfoPiece] = []
        # Plans are made at reset: all envs have one, or they step one by one.
        planning = all(env._plan is not None for env in self.envs)
        start = 0
        while start < len(self.envs):
            stop = min(start + (len(self.envs) if self._batching else self._chunk), len(self.envs))
            self._step_chunk(range(start, stop), actions, planning, infos)
            start = stop
        return infos

    def _step_chunk(self, chunk: range, actions: np.ndarray, planning: bool, infos: list[_InfoPiece]) -> None:
        """Steps the envs at positions ``chunk`` of the block: their plans together (or
        each env in turn), then their Python (observation, reward, resets): for all of
        them at once where the task gives its outcomes as arrays."""
        vec = self._vec
        next_step = vec.autoreset_mode == AutoresetMode.NEXT_STEP
        planned = self._run_plans(chunk, actions, vec._autoreset, next_step) if planning else None
        self._finish(planned, actions, infos, chunk)

    def _finish(
        self,
        planned: Optional[tuple[list[int], np.ndarray]],
        actions: np.ndarray,
        infos: list[_InfoPiece],
        chunk: Optional[range] = None,
    ) -> None:
        """The Python part of stepping the envs at positions ``chunk`` of the block (all
        of them by default), once their plans have run (``planned``: their positions and
        numbers) or, without plans, stepping them one by one. Runs in the block's thread,
        or in the caller's while the block's thread is parked outside Python (then only
        for plans whose task gives its outcomes as arrays)."""
        vec = self._vec
        chunk = range(len(self.envs)) if chunk is None else chunk
        same_step, ended = vec.autoreset_mode == AutoresetMode.SAME_STEP, vec._autoreset
        next_step = vec.autoreset_mode == AutoresetMode.NEXT_STEP
        all_obs, rewards, terminations, truncations = vec._obs, vec._rewards, vec._terminations, vec._truncations
        done: set[int] = set()
        if planned is not None and planned[0]:
            done = self._batched(*planned, actions, same_step, infos)
            self._batching = bool(done)
        # Where each env's numbers are, for the envs not done at once above.
        row_of = {k: r for r, k in enumerate(planned[0])} if planned is not None and not done else {}
        for k in chunk:
            if k in done:
                continue
            env, i = self.envs[k], self.indices[k]
            try:
                if next_step and ended[i]:
                    obs, info = env.reset()
                    reward, terminated, truncated = 0.0, False, False
                else:
                    if planned is not None:
                        outcome = env._planned(actions[i], planned[1][row_of[k]])
                    else:
                        outcome = env._step_checked(actions[i])
                    obs, reward, terminated, truncated, info = outcome
                    if same_step and (terminated or truncated):
                        final = {"final_obs": obs, "final_info": info}
                        obs, info = env.reset()
                        info = {**final, **info}
            except Exception as e:
                raise _WorkerError(i, e) from e
            all_obs[i] = obs
            rewards[i] = reward
            terminations[i] = terminated
            truncations[i] = truncated
            infos.append((i, info))

    def _batched(
        self,
        acting: list[int],
        values: np.ndarray,
        actions: np.ndarray,
        same_step: bool,
        infos: list[_InfoPiece],
    ) -> set[int]:
        """Observations, rewards, endings and infos of the envs whose plans ran
        (``acting``, by position in the block; ``values``, one row each) in a few numpy
        operations, when their task gives them (:meth:`gantry.gym.Task.outcomes`); the
        positions done, none if the task does not. What ``GantryEnv`` does per env around
        them (counting the actions, truncating, a same-step reset) is done here too."""
        task = self.envs[acting[0]].task
        first = self.indices.start
        rows = [first + k for k in acting]
        try:
            out = task.outcomes(values, actions[rows])
        except Exception as e:
            # A task's bug: named by the batch's first env, as a check below would be.
            raise _WorkerError(rows[0], e) from e
        if out is None:
            return set()
        vec, n = self._vec, len(acting)
        _check_outcomes(task, out, (n, *vec.single_observation_space.shape), rows[0])
        truncated = np.zeros(n, dtype=np.bool_)
        for r, k in enumerate(acting):
            env = self.envs[k]
            env._steps += 1
            limit = env.task.max_episode_steps
            truncated[r] = limit is not None and env._steps >= limit
        # Usually the acting envs are a run of rows (all but those reset this step).
        at: slice | list[int] = slice(rows[0], rows[-1] + 1) if rows[-1] - rows[0] + 1 == n else rows
        vec._obs[at] = out.observations
        vec._rewards[at] = out.rewards
        vec._terminations[at] = out.terminated
        vec._truncations[at] = truncated
        ended = np.flatnonzero(out.terminated | truncated).tolist() if same_step else []
        for r in ended:
            # SAME_STEP: reset at once, as GantryEnv's caller would, the ending in the info.
            k, i = acting[r], rows[r]
            final = {
                "final_obs": out.observations[r].copy(),
                "final_info": {key: v[r].item() for key, v in out.infos.items()},
            }
            try:
                vec._obs[i], info = self.envs[k].reset()
            except Exception as e:
                raise _WorkerError(i, e) from e
            infos.append((i, {**final, **info}))
        if ended:
            kept = np.ones(n, dtype=np.bool_)
            kept[ended] = False
            infos.append(_Infos(np.array(rows)[kept], {key: v[kept] for key, v in out.infos.items()}))
        else:
            infos.append(_Infos(np.array(rows), out.infos))
        return set(acting)

    def _run_plans(
        self, chunk: range, actions: np.ndarray, ended: np.ndarray, next_step: bool
    ) -> tuple[list[int], np.ndarray]:
        """Runs the step plans of the envs of ``chunk`` that act this step (every env
        of the block has one) in one call, with the GIL released once: their
        positions in the block and their observed numbers, one row each."""
        acting = [k for k in chunk if not (next_step and ended[self.indices[k]])]
        if not acting:
            return [], np.empty((0, 0))
        first = self.indices.start
        try:
            # This thread's CPU time: the wall clock would count the wait for the GIL too.
            t0 = time.thread_time()
            values = Engine.run_plans(
                [self._engines[k] for k in acting],
                [self.envs[k]._plan for k in acting],
                actions[[first + k for k in acting]],
            )
            # The next chunks' size, from a running mean of a plan's duration.
            self._plan_time += 0.25 * ((time.thread_time() - t0) / len(acting) - self._plan_time)
            self._chunk = max(1, min(len(self.envs), round(_PLAN_SLICE / max(self._plan_time, 1e-7))))
        except Exception as e:
            # The extension names the failing plan by its position: (message, position).
            if len(e.args) == 2 and isinstance(e.args[1], int):
                raise _WorkerError(self.indices[acting[e.args[1]]], Exception(e.args[0])) from None
            raise
        return acting, values

    def call(self, name: str, args: tuple, kwargs: dict) -> list[Any]:
        out = []
        for env, i in zip(self.envs, self.indices):
            try:
                attr = env.get_wrapper_attr(name)
                out.append(attr(*args, **kwargs) if callable(attr) else attr)
            except Exception as e:
                raise _WorkerError(i, e) from e
        return out


class _Worker:
    """A thread that runs the methods of its block it is sent (the first makes the
    envs) until told to close."""

    def __init__(self, block: _Block):
        self.block = block
        self.inbox: queue.SimpleQueue = queue.SimpleQueue()
        self.outbox: queue.SimpleQueue = queue.SimpleQueue()
        # Where the thread waits outside Python for batches of plans (``serve``), and
        # whether it was sent there and not yet released.
        self.server = PlanServer()
        self.parked = False
        self.thread = threading.Thread(target=self._run, name=f"gantry-vector-{block.index}", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while True:
            seq, command, args = self.inbox.get()
            if command == "close":
                self.block.close()
                return
            if command == "serve":
                # Until released (PlanServer.release): batches of plans, without the GIL.
                # A refusal is answered to the batches, so nothing is reported here.
                block = self.block
                try:
                    Engine.serve_plans(self.server, block._engines, [env._plan for env in block.envs])
                except Exception as e:  # noqa: BLE001 - answered to the batches instead
                    self.server.refuse(f"{type(e).__name__}: {e}")
                continue
            try:
                self.outbox.put((seq, "ok", getattr(self.block, command)(*args)))
            except BaseException as e:  # noqa: BLE001 - reported to the caller
                error = e if isinstance(e, _WorkerError) else _WorkerError(None, e)
                _forget_locals(error)
                self.outbox.put((seq, "error", error))

    def send(self, seq: int, command: str, args: tuple) -> None:
        self.inbox.put((seq, command, args))

    def reply(self, seq: int) -> tuple[str, Any]:
        """The answer to command ``seq``; an error if the thread has died. Answers to
        earlier commands (whose caller was interrupted, by Ctrl-C say) are dropped."""
        while True:
            try:
                got, status, value = self.outbox.get(timeout=_POLL)
            except queue.Empty:
                if not self.thread.is_alive():
                    return "error", _WorkerError(None, RuntimeError("the worker thread has died"))
                continue
            if got == seq:
                return status, value


def _raise(block: _Block, e: _WorkerError) -> None:
    """Raises a block's failure in the caller's thread, naming the env (or the thread)."""
    last = block.indices.stop - 1
    where = f"env {e.env}" if e.env is not None else f"the thread of envs {block.indices.start}-{last}"
    raise RuntimeError(f"gantry VectorEnv: {where} failed: {type(e.error).__name__}: {e.error}") from e.error


def _forget_locals(error: BaseException) -> None:
    """Drops the local variables of the frames in ``error``'s tracebacks (its causes'
    too), keeping their lines. Those locals hold this thread's envs: freed later by the
    caller's thread, their clients would end outside the thread they belong to."""
    seen: set[int] = set()
    e: Optional[BaseException] = error
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        traceback.clear_frames(e.__traceback__)
        e = e.__cause__ or e.__context__


class VectorEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` simulations of ``task_factory()``'s task stepped together by
    ``num_threads`` threads (default: the number of cores; never more than
    ``num_envs``): the caller's thread, which drives the first block of envs, and
    ``num_threads - 1`` workers. ``task_factory`` is called once per env, in the thread
    that drives it (a task keeps per-episode state, so each env needs its own), and once
    more here for the spaces. Like a ``GantryEnv``, the vector env belongs to the thread
    that made it. ``copy=False`` returns the observation batch itself, overwritten by the
    next call. See the module's docs for the design and the conventions."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        task_factory: Callable[[], Task],
        num_envs: int,
        num_threads: Optional[int] = None,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        copy: bool = True,
    ):
        if not (isinstance(num_envs, int) and num_envs >= 1):
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        if num_threads is None:
            num_threads = os.cpu_count() or 1
        if not (isinstance(num_threads, int) and num_threads >= 1):
            raise ValueError(f"num_threads must be a positive integer, got {num_threads!r}")
        self.num_envs = num_envs
        self.num_threads = min(num_threads, num_envs)  # an idle thread would only cost
        self.autoreset_mode = AutoresetMode(autoreset_mode)
        self.copy = copy
        self.metadata = {"autoreset_mode": self.autoreset_mode, "render_modes": []}
        self.render_mode = None
        self.closed = False
        self._workers: list[_Worker] = []
        self._seq = 0  # commands sent to the workers

        # The spaces from a task made here: making a task is cheap; its env is not.
        probe = task_factory()
        self.single_observation_space = probe.observation_space
        self.single_action_space = probe.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)

        self._obs = np.zeros((num_envs, *self.single_observation_space.shape), dtype=np.float32)
        self._rewards = np.zeros(num_envs, dtype=np.float64)
        self._terminations = np.zeros(num_envs, dtype=np.bool_)
        self._truncations = np.zeros(num_envs, dtype=np.bool_)
        self._autoreset = np.zeros(num_envs, dtype=np.bool_)
        self._started = False

        def make() -> GantryEnv:
            return GantryEnv(task_factory())

        # Contiguous blocks, sizes differing by at most one; the first is the caller's.
        bounds = [num_envs * w // self.num_threads for w in range(self.num_threads + 1)]
        blocks = [_Block(w, range(bounds[w], bounds[w + 1]), self) for w in range(self.num_threads)]
        self._local = blocks[0]
        try:
            # The workers make their envs while this thread makes its own.
            self._workers = [_Worker(b) for b in blocks[1:]]
            self._run(self._workers, self._local.make, make)
        except BaseException:
            self.close()
            raise

    # --- the vector API ----------------------------------------------------------

    def reset(
        self, *, seed: int | Sequence[Optional[int]] | None = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Resets every env (or those of ``options["reset_mask"]``); ``seed`` as
        Gymnasium's vector envs take it: ``s`` seeds env ``i`` with ``s + i``."""
        self._check_open()
        if seed is None:
            seeds: list[Optional[int]] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"reset: {len(seeds)} seeds for {self.num_envs} envs")
        options = dict(options) if options is not None else None
        mask = None
        if options is not None and "reset_mask" in options:
            mask = options.pop("reset_mask")
            if not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (self.num_envs,)):
                raise ValueError(f"options['reset_mask'] must be a bool numpy array of shape ({self.num_envs},)")
            if not mask.any():
                raise ValueError("options['reset_mask'] resets no env")
        for flags in (self._terminations, self._truncations, self._autoreset):
            if mask is None:
                flags[:] = False
            else:
                flags[mask] = False
        infos = self._infos(self._run(self._workers, self._local.reset, seeds, options, mask))
        self._started = True
        return self._observations(), infos

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Steps every env with its row of ``actions`` (checked and clipped to
        ``single_action_space`` as ``GantryEnv.step`` does), in parallel."""
        self._check_open()
        if not self._started:
            raise RuntimeError("call reset() before step()")
        if self.autoreset_mode == AutoresetMode.DISABLED and self._autoreset.any():
            ended = np.flatnonzero(self._autoreset).tolist()
            raise RuntimeError(
                f"envs {ended} have ended: with autoreset_mode DISABLED, reset them "
                "(reset(options={'reset_mask': mask})) before stepping"
            )
        space = self.single_action_space
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != (self.num_envs, *space.shape):
            raise ValueError(f"actions must have shape {(self.num_envs, *space.shape)}, got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"actions must be finite, got {a}")
        # Checked and clipped once for all envs, as each GantryEnv.step would one by one.
        a = np.clip(a, space.low, space.high).astype(space.dtype)
        parts = self._parked_step(a)
        if parts is None:
            parts = self._run(self._workers, self._local.step, a)
        infos = self._infos(parts)
        np.logical_or(self._terminations, self._truncations, out=self._autoreset)
        return (
            self._observations(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            infos,
        )

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Calls each env's method ``name`` (in its own thread), or reads its attribute."""
        self._check_open()
        parts = self._run(self._workers, self._local.call, name, args, kwargs)
        return tuple(x for part in parts for x in part)

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Each env's attribute ``name``."""
        return self.call(name)

    def set_attr(self, name: str, values: Any) -> None:
        """Sets each env's attribute ``name``: to ``values[i]`` for a list or tuple (one
        per env), else to ``values`` for all. Plain Python objects, so set from here."""
        self._check_open()
        if not isinstance(values, (list, tuple)):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"set_attr: {len(values)} values for {self.num_envs} envs")
        envs = [env for block in (self._local, *(w.block for w in self._workers)) for env in block.envs]
        for env, value in zip(envs, values):
            env.set_wrapper_attr(name, value)

    def close_extras(self, **kwargs: Any) -> None:
        """Closes every env in its own thread and joins the workers."""
        workers = getattr(self, "_workers", [])  # none if the constructor failed early
        self._unpark(workers)
        for w in workers:
            if w.thread.is_alive():
                w.send(-1, "close", ())
        if hasattr(self, "_local"):
            self._local.close()
        for w in workers:
            w.thread.join()
        self._workers = []

    def __del__(self) -> None:
        # Dropped without close(): the workers would otherwise wait for ever.
        if not getattr(self, "closed", True):
            self.close()

    # --- internals ---------------------------------------------------------------

    def _check_open(self) -> None:
        if self.closed:
            raise RuntimeError("this VectorEnv is closed")

    def _observations(self) -> np.ndarray:
        return self._obs.copy() if self.copy else self._obs

    def _run(self, workers: list[_Worker], local: Callable[..., Any], *args: Any) -> list[Any]:
        """``local(*args)`` in this thread and the same method of each worker's block in
        its thread, in parallel; the replies in block order. A failure is raised once
        every block has answered (so that none is left mid-command), naming the env."""
        name = local.__name__
        self._unpark(workers)
        self._seq += 1
        for w in workers:
            w.send(self._seq, name, args)
        failure: Optional[tuple[_Block, _WorkerError]] = None
        try:
            replies = [local(*args)]
        except _WorkerError as e:
            # Its frames' envs are this thread's, but the error may be freed elsewhere.
            _forget_locals(e)
            replies, failure = [None], (self._local, e)
        for w in workers:
            status, value = w.reply(self._seq)
            if status == "error" and failure is None:
                failure = (w.block, value)
            replies.append(value if status == "ok" else None)
        if failure is not None:
            _raise(*failure)
        return replies

    def _parked_step(self, a: np.ndarray) -> Optional[list[list[_InfoPiece]]]:
        """The step with the workers kept outside Python (see ``PlanServer``): each
        worker runs its block's plans on a batch of actions sent to it, without the GIL,
        while this thread runs its own block's; this thread then does every block's
        Python part. For blocks whose envs all have plans and whose task gives its
        outcomes as arrays, when no env is reset by this step; None otherwise (the
        workers then take the step as Python commands). The blocks' infos, in order."""
        if not self._workers or self.autoreset_mode == AutoresetMode.SAME_STEP or self._autoreset.any():
            return None
        blocks = [self._local, *(w.block for w in self._workers)]
        if not all(b._batching and all(env._plan is not None for env in b.envs) for b in blocks):
            return None
        self._seq += 1
        seq = self._seq
        for w in self._workers:
            if not w.parked:
                w.send(seq, "serve", ())
                w.parked = True
            w.server.step(seq, a[w.block.indices.start : w.block.indices.stop])
        parts: list[list[_InfoPiece]] = []
        failure: Optional[tuple[_Block, _WorkerError]] = None
        local = self._local
        try:
            infos: list[_InfoPiece] = []
            local._finish(local._run_plans(range(len(local.envs)), a, self._autoreset, False), a, infos)
            parts.append(infos)
        except _WorkerError as e:
            _forget_locals(e)
            parts.append([])
            failure = (local, e)
        # Every worker answers before anything is raised: no reply is left for later.
        for w in self._workers:
            try:
                infos = []
                w.block._finish((list(range(len(w.block.envs))), self._collect(w, seq)), a, infos)
                parts.append(infos)
            except _WorkerError as e:
                _forget_locals(e)
                parts.append([])
                failure = failure or (w.block, e)
        if failure is not None:
            _raise(*failure)
        return parts

    def _collect(self, w: _Worker, seq: int) -> np.ndarray:
        """Worker ``w``'s numbers for batch ``seq``; a failed plan as a ``_WorkerError``
        naming its env."""
        while True:
            try:
                values = w.server.collect(seq, _POLL)
            except Exception as e:
                # The extension names the failing plan by its position: (message, position).
                if len(e.args) == 2 and isinstance(e.args[1], int):
                    raise _WorkerError(w.block.indices.start + e.args[1], Exception(e.args[0])) from None
                raise _WorkerError(None, e) from e
            if values is not None:
                return values
            if not w.thread.is_alive():
                raise _WorkerError(None, RuntimeError("the worker thread has died"))

    @staticmethod
    def _unpark(workers: list[_Worker]) -> None:
        """Sends parked workers back to Python, where the next command finds them."""
        for w in workers:
            if w.parked:
                w.server.release()
                w.parked = False

    def _infos(self, parts: list[list[_InfoPiece]]) -> dict[str, Any]:
        """The blocks' infos as one vector info (Gymnasium's layout: one array per key,
        with a ``_key`` mask of the envs that have it)."""
        pieces = [piece for part in parts for piece in part]
        if not pieces:
            return {}
        batched = self._batched_infos(pieces)
        if batched is not None:
            return batched
        infos: dict[str, Any] = {}
        for piece in pieces:
            if isinstance(piece, _Infos):
                for r, i in enumerate(piece.envs.tolist()):
                    infos = self._add_info(infos, {k: v[r].item() for k, v in piece.values.items()}, i)
            else:
                infos = self._add_info(infos, piece[1], piece[0])
        return infos

    def _batched_infos(self, pieces: list[_InfoPiece]) -> Optional[dict[str, Any]]:
        """The usual case at once: every env reported, all with the same keys, and each
        key's values scalars of one type (as Gymnasium's ``_add_info`` types them), so
        that each becomes one array. None otherwise."""
        first = pieces[0]
        keys = first.values.keys() if isinstance(first, _Infos) else first[1].keys()
        dtypes: dict[str, np.dtype] = {}
        count = 0
        for piece in pieces:
            values = piece.values if isinstance(piece, _Infos) else piece[1]
            if values.keys() != keys:
                return None
            for k, v in values.items():
                if isinstance(piece, _Infos):
                    dtype = v.dtype
                elif type(v) in _SCALARS:
                    dtype = np.dtype(type(v))
                else:
                    return None
                if dtypes.setdefault(k, dtype) != dtype:
                    return None
            count += len(piece.envs) if isinstance(piece, _Infos) else 1
        if count != self.num_envs:
            return None
        out: dict[str, Any] = {}
        for k in keys:
            array = np.empty(self.num_envs, dtype=dtypes[k])
            for piece in pieces:
                if isinstance(piece, _Infos):
                    array[piece.envs] = piece.values[k]
                else:
                    array[piece[0]] = piece[1][k]
            out[k] = array
            out[f"_{k}"] = np.ones(self.num_envs, dtype=np.bool_)
        return out


# The info values that the fast path batches (as Gymnasium's _add_info types them).
_SCALARS = (bool, int, float, np.bool_, np.float32, np.float64, np.int32, np.int64)


# --- registration (gantry.gym registers these as vector_entry_point) -----------------


def arm_reach_vector_env(
    num_envs: int = 1,
    num_threads: Optional[int] = None,
    autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
    max_episode_steps: Optional[int] = None,
    **options: Any,
) -> VectorEnv:
    """A :class:`VectorEnv` of :class:`ArmReach` (``options`` are its arguments);
    episodes truncated after ``max_episode_steps`` actions, by default the registered
    limit."""
    if num_threads is None:
        # An ArmReach step is about 16 us in a vector env (13 of them without the GIL):
        # a few envs cost less than handing their step to another thread. Measured
        # (tools/bench/vector_env.py, workers parked outside Python), 2 threads gave
        # 0.84x one thread with 4 envs, 1.24x with 16, 1.43x with 32, 1.62x with 64 and
        # 1.95x with 128. So one thread per 8 envs.
        num_threads = max(1, min(os.cpu_count() or 1, num_envs // _ARM_REACH_ENVS_PER_THREAD))
    limit = _ARM_REACH_STEPS if max_episode_steps is None else max_episode_steps
    return _vector_env(ArmReach, limit, num_envs, num_threads, autoreset_mode, options)


# ArmReach envs worth a thread of their own by default (see arm_reach_vector_env).
_ARM_REACH_ENVS_PER_THREAD = 8


def bubble_rob_avoid_vector_env(
    num_envs: int = 1,
    num_threads: Optional[int] = None,
    autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
    max_episode_steps: Optional[int] = None,
    **options: Any,
) -> VectorEnv:
    """A :class:`VectorEnv` of :class:`BubbleRobAvoid` (``options`` are its arguments);
    episodes truncated after ``max_episode_steps`` actions, by default the registered
    limit."""
    limit = _BUBBLE_ROB_STEPS if max_episode_steps is None else max_episode_steps
    return _vector_env(BubbleRobAvoid, limit, num_envs, num_threads, autoreset_mode, options)


def _vector_env(
    task: Callable[..., Task],
    limit: Optional[int],
    num_envs: int,
    num_threads: Optional[int],
    autoreset_mode: AutoresetMode | str,
    options: dict[str, Any],
) -> VectorEnv:
    """The registered entry points' vector env: ``task(max_episode_steps=limit,
    **options)`` per env."""
    return VectorEnv(
        lambda: task(max_episode_steps=limit, **options), num_envs, num_threads, autoreset_mode=autoreset_mode
    )
