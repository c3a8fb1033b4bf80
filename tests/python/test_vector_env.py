"""gantry.vector: many simulations stepped together on a pool of threads in one process
(issue 33). The same results as separate ``GantryEnv``s and as Gymnasium's own
``SyncVectorEnv`` over them, bit for bit, whatever the number of threads; Gymnasium's
autoreset modes, seeding and ``make_vec`` registration; errors raised by the call that
caused them; ``close()`` joining the workers. No timing here: the speed-up is measured
by tools/bench/vector_env.py."""

from __future__ import annotations

import os
import threading
from typing import Any, Callable

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import gantry.gym as gg
from gantry.vector import VectorEnv

# Short episodes, so that a rollout of a few dozen steps crosses truncations and resets.
LIMIT = 12
TASKS: dict[str, Callable[[], gg.Task]] = {
    "ArmReach": lambda: gg.ArmReach(max_episode_steps=LIMIT),
    "BubbleRobAvoid": lambda: gg.BubbleRobAvoid(max_episode_steps=LIMIT),
}


@pytest.fixture
def closing():
    """Closes what the test made, pass or fail."""
    made: list[Any] = []

    def keep(env: Any) -> Any:
        made.append(env)
        return env

    yield keep
    for env in made:
        env.close()


def random_actions(space: gymnasium.spaces.Box, num_envs: int, steps: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    # Beyond the bounds too, so that clipping is part of what must agree.
    return rng.uniform(-1.5, 1.5, size=(steps, num_envs, *space.shape))


def separate_rollout(
    envs: list[gg.GantryEnv], seed: int, actions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What a vector env in NEXT_STEP mode must give, from separate envs: env i seeded
    ``seed + i``; an env that ended is reset by the next step, which ignores its action."""
    obs = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    observations, rewards, terminations, truncations = [np.array(obs)], [], [], []
    ended = [False] * len(envs)
    for row in actions:
        step = []
        for i, (env, a) in enumerate(zip(envs, row)):
            if ended[i]:
                o, _ = env.reset()
                step.append((o, 0.0, False, False))
            else:
                o, r, te, tr, _ = env.step(a)
                step.append((o, r, te, tr))
            ended[i] = step[-1][2] or step[-1][3]
        observations.append(np.array([s[0] for s in step]))
        rewards.append([s[1] for s in step])
        terminations.append([s[2] for s in step])
        truncations.append([s[3] for s in step])
    return np.array(observations), np.array(rewards), np.array(terminations), np.array(truncations)


def vector_rollout(
    env: gymnasium.vector.VectorEnv, seed: int, actions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    obs, _ = env.reset(seed=seed)
    observations, rewards, terminations, truncations = [obs], [], [], []
    for row in actions:
        obs, r, te, tr, _ = env.step(row)
        observations.append(obs)
        rewards.append(r)
        terminations.append(te)
        truncations.append(tr)
    return np.array(observations), np.array(rewards), np.array(terminations), np.array(truncations)


@pytest.mark.parametrize("task", TASKS)
@pytest.mark.parametrize("num_threads", [1, 2, 3])
def test_same_results_as_separate_envs(closing, task, num_threads):
    factory, num_envs = TASKS[task], 3
    vec = closing(VectorEnv(factory, num_envs, num_threads))
    assert vec.num_threads == num_threads
    separate = [closing(gg.GantryEnv(factory())) for _ in range(num_envs)]
    actions = random_actions(vec.single_action_space, num_envs, 2 * LIMIT + 5, seed=7)

    got = vector_rollout(vec, 11, actions)
    want = separate_rollout(separate, 11, actions)
    for name, g, w in zip(("observations", "rewards", "terminations", "truncations"), got, want):
        np.testing.assert_array_equal(g, w, err_msg=name)
    assert got[0].dtype == np.float32
    assert got[3][LIMIT - 1].all()  # every env truncated, then reset by the next step
    assert not got[3][LIMIT].any() and (got[1][LIMIT] == 0).all()
    assert all(vec.observation_space.contains(obs) for obs in got[0])


@pytest.mark.parametrize("task", TASKS)
def test_same_results_and_infos_as_gymnasium_sync_vector_env(closing, task):
    """Gymnasium's reference vector env over separate GantryEnvs, compared with its own
    equivalence check (exact), infos included, in each autoreset mode."""
    factory, num_envs = TASKS[task], 4
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
        vec = closing(VectorEnv(factory, num_envs, 2, autoreset_mode=mode))
        ref = closing(SyncVectorEnv([lambda: gg.GantryEnv(factory()) for _ in range(num_envs)], autoreset_mode=mode))
        assert vec.metadata["autoreset_mode"] == ref.metadata["autoreset_mode"] == mode
        assert vec.single_observation_space == ref.single_observation_space
        assert vec.single_action_space == ref.single_action_space
        assert vec.observation_space == ref.observation_space and vec.action_space == ref.action_space
        assert data_equivalence(vec.reset(seed=3), ref.reset(seed=3), exact=True)
        for row in random_actions(vec.single_action_space, num_envs, LIMIT + 3, seed=4):
            assert data_equivalence(vec.step(row), ref.step(row), exact=True), mode
        # Seeds as a list.
        seeds = [5, 0, 9, 2]
        assert data_equivalence(vec.reset(seed=seeds), ref.reset(seed=seeds), exact=True)


def test_same_step_autoreset_reports_the_final_observation(closing):
    vec = closing(VectorEnv(TASKS["ArmReach"], 2, 2, autoreset_mode="SameStep"))
    obs, _ = vec.reset(seed=0)
    actions = np.zeros((2, 6))
    for _ in range(LIMIT - 1):
        last, _, _, truncated, info = vec.step(actions)
        assert not truncated.any() and "final_obs" not in info
    obs, _, _, truncated, info = vec.step(actions)
    assert truncated.all() and info["_final_obs"].all()
    # The final observation ends the episode (its target); the returned one starts the
    # next (another target).
    final = np.stack(info["final_obs"])
    assert final.shape == (2, 12) and final.dtype == np.float32
    np.testing.assert_array_equal(final[:, 9:], last[:, 9:])
    assert not np.array_equal(obs[:, 9:], last[:, 9:])
    assert info["final_info"]["_distance"].all()


def test_disabled_autoreset_needs_a_masked_reset(closing):
    vec = closing(VectorEnv(TASKS["ArmReach"], 3, 2, autoreset_mode=AutoresetMode.DISABLED))
    obs, _ = vec.reset(seed=0)
    for _ in range(LIMIT):
        obs, _, _, truncated, _ = vec.step(np.zeros((3, 6)))
    assert truncated.all()
    with pytest.raises(RuntimeError, match="reset_mask"):
        vec.step(np.zeros((3, 6)))
    mask = np.array([True, False, True])
    new, info = vec.reset(options={"reset_mask": mask})
    assert not info["_distance"][1] and info["_distance"][0]
    np.testing.assert_array_equal(new[1], obs[1])
    with pytest.raises(RuntimeError, match=r"envs \[1\]"):
        vec.step(np.zeros((3, 6)))
    vec.reset(options={"reset_mask": ~mask})
    vec.step(np.zeros((3, 6)))


def test_cheap_arm_steps_stay_on_one_thread_by_default(closing):
    # ArmReach's steps cost less than handing them to a thread (measured in
    # tools/bench/vector_env.py): one thread per 8 envs unless asked.
    assert closing(gymnasium.make_vec("gantry/ArmReach-v0", num_envs=4)).num_threads == 1
    assert closing(gymnasium.make_vec("gantry/ArmReach-v0", num_envs=4, num_threads=2)).num_threads == 2
    expected = max(1, min(os.cpu_count() or 1, 16 // 8))
    assert closing(gymnasium.make_vec("gantry/ArmReach-v0", num_envs=16)).num_threads == expected


def test_make_vec_gives_a_vector_env_with_the_registered_limit(closing):
    vec = closing(gymnasium.make_vec("gantry/BubbleRobAvoid-v0", num_envs=4, num_threads=2))
    assert isinstance(vec, VectorEnv) and vec.num_envs == 4 and vec.num_threads == 2
    assert vec.get_attr("task")[0].max_episode_steps == gymnasium.spec("gantry/BubbleRobAvoid-v0").max_episode_steps
    obs, _ = vec.reset(seed=1)
    assert obs.shape == (4, 8) and obs.dtype == np.float32

    arm = closing(
        gymnasium.make_vec(
            "gantry/ArmReach-v0", num_envs=2, vectorization_mode="vector_entry_point", max_episode_steps=3
        )
    )
    assert isinstance(arm, VectorEnv) and arm.spec.id == "gantry/ArmReach-v0"
    arm.reset(seed=0)
    truncated = [arm.step(np.zeros((2, 6)))[3] for _ in range(3)]
    assert [t.all() for t in truncated] == [False, False, True]
    # The other modes still build Gymnasium's own vector envs over GantryEnvs.
    sync = closing(gymnasium.make_vec("gantry/ArmReach-v0", num_envs=2, vectorization_mode="sync"))
    assert isinstance(sync, SyncVectorEnv)
    assert gg.VectorEnv is VectorEnv


def test_more_threads_than_envs(closing):
    vec = closing(VectorEnv(TASKS["ArmReach"], 2, num_threads=8))
    assert vec.num_threads == 2
    vec.reset(seed=0)
    assert vec.step(np.zeros((2, 6)))[0].shape == (2, 12)
    with pytest.raises(ValueError, match="num_threads"):
        VectorEnv(TASKS["ArmReach"], 2, num_threads=0)
    with pytest.raises(ValueError, match="num_envs"):
        VectorEnv(TASKS["ArmReach"], 0)


def test_each_env_is_made_and_driven_in_its_own_thread(closing):
    threads: list[int] = []

    class Recording(gg.ArmReach):
        def setup(self, sim: Any) -> None:
            super().setup(sim)
            threads.append(threading.get_ident())

    vec = closing(VectorEnv(lambda: Recording(max_episode_steps=LIMIT), 4, 2))
    vec.reset(seed=0)
    assert len(threads) == 4 and len(set(threads)) == 2 and threading.get_ident() in threads


class Failing(gg.ArmReach):
    """ArmReach whose act fails on its third action once told to."""

    def __init__(self) -> None:
        super().__init__(max_episode_steps=LIMIT)
        self.fail, self.acted = False, 0

    def plan(self, sim: Any) -> None:
        return None  # act in Python, where it fails

    def act(self, sim: Any, action: np.ndarray) -> None:
        self.acted += 1
        if self.fail and self.acted == 3:
            raise ValueError("the task broke")
        super().act(sim, action)


@pytest.mark.parametrize("failing_env", [0, 3])  # in the caller's thread's block, in a worker's
def test_an_error_in_an_env_is_raised_by_the_step_naming_the_env(closing, failing_env):
    vec = closing(VectorEnv(Failing, 4, 2))
    vec.get_attr("task")[failing_env].fail = True
    vec.reset(seed=0)
    vec.step(np.zeros((4, 6)))
    vec.step(np.zeros((4, 6)))
    with pytest.raises(RuntimeError, match=f"env {failing_env} failed: ValueError: the task broke") as raised:
        vec.step(np.zeros((4, 6)))
    assert isinstance(raised.value.__cause__, ValueError)
    # The vector env still answers (no hang) and closes cleanly.
    vec.step(np.zeros((4, 6)))


def test_an_env_that_cannot_be_made_fails_the_constructor_and_leaves_no_thread():
    before = {t.ident for t in threading.enumerate()}

    class Broken(gg.ArmReach):
        scene = "no_such_scene.toml"

    with pytest.raises(RuntimeError, match=r"env \d failed"):
        VectorEnv(lambda: Broken(), 4, 2)
    assert {t.ident for t in threading.enumerate()} == before


def test_close_joins_the_workers_and_is_idempotent():
    vec = VectorEnv(TASKS["BubbleRobAvoid"], 3, 3)
    vec.reset(seed=0)
    workers = [t for t in threading.enumerate() if t.name.startswith("gantry-vector-")]
    assert len(workers) == 2
    vec.close()
    assert vec.closed and not any(t.is_alive() for t in workers)
    vec.close()
    with pytest.raises(RuntimeError, match="closed"):
        vec.step(np.zeros((3, 2)))


def test_bad_actions_give_clear_errors(closing):
    vec = closing(VectorEnv(TASKS["BubbleRobAvoid"], 2, 2))
    with pytest.raises(RuntimeError, match="reset"):
        vec.step(np.zeros((2, 2)))
    vec.reset(seed=0)
    with pytest.raises(ValueError, match=r"shape \(2, 2\)"):
        vec.step(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="finite"):
        vec.step(np.array([[0.0, np.nan], [0.0, 0.0]]))
    with pytest.raises(ValueError, match="2 seeds for 2 envs|seeds"):
        vec.reset(seed=[1, 2, 3])


class ArmReachInPython(gg.ArmReach):
    """ArmReach without its step plan: act and observe in Python, call by call."""

    def plan(self, sim: Any) -> None:
        return None


@pytest.mark.parametrize("num_threads", [1, 2])
def test_arm_reach_step_plan_gives_what_its_python_gives(closing, num_threads):
    """The plan (run in one call with the GIL released) and the task's Python make the
    same calls: the same trajectories, bit for bit, one env and a vector env alike."""
    planned = closing(VectorEnv(TASKS["ArmReach"], 3, num_threads))
    python = closing(VectorEnv(lambda: ArmReachInPython(max_episode_steps=LIMIT), 3, num_threads))
    actions = random_actions(planned.single_action_space, 3, 2 * LIMIT, seed=2)
    for g, w in zip(vector_rollout(planned, 4, actions), vector_rollout(python, 4, actions)):
        np.testing.assert_array_equal(g, w)
    assert planned.get_attr("_plan")[0] is not None and python.get_attr("_plan")[0] is None
    one = closing(gg.GantryEnv(gg.ArmReach(max_episode_steps=LIMIT)))
    other = closing(gg.GantryEnv(ArmReachInPython(max_episode_steps=LIMIT)))
    for env in (one, other):
        env.reset(seed=8)
    for a in actions[:, 0]:
        assert data_equivalence(one.step(a), other.step(a), exact=True)


def test_step_plans_take_registry_functions_only():
    with pytest.raises(ValueError, match="not a registry function"):
        gg.StepPlan(act=[], steps=1, observe=[("sim.step", [])])
    with pytest.raises(ValueError, match="no such function"):
        gg.StepPlan(act=[("sim.setNothing", 1, None, 0, 1.0)], steps=1, observe=[])


def test_a_dropped_vector_env_closes_its_workers():
    """No reference cycle: dropping the last reference closes it at once, in this thread."""
    vec = VectorEnv(TASKS["ArmReach"], 2, 2)
    vec.reset(seed=0)
    workers = [t for t in threading.enumerate() if t.name.startswith("gantry-vector-")]
    assert workers
    del vec
    assert not any(t.is_alive() for t in workers)


class Interrupted(BaseException):
    """What Ctrl-C is to the caller's thread: not an Exception."""


def test_an_interrupted_step_leaves_no_stale_reply(closing):
    """A step interrupted in the caller's thread leaves the worker's answer unread; the
    next command must get its own answer, not that one."""

    class Interrupting(ArmReachInPython):
        interrupt = False

        def act(self, sim: Any, action: np.ndarray) -> None:
            if self.interrupt:
                self.interrupt = False
                raise Interrupted()
            super().act(sim, action)

    vec = closing(VectorEnv(lambda: Interrupting(max_episode_steps=None), 4, 2))
    vec.reset(seed=0)
    vec.get_attr("task")[0].interrupt = True
    with pytest.raises(Interrupted):
        vec.step(np.zeros((4, 6)))
    tasks = vec.get_attr("task")
    assert [type(t) for t in tasks] == [Interrupting] * 4
    assert vec.step(np.zeros((4, 6)))[0].shape == (4, 12)


def test_a_step_plan_does_not_step_through_the_clients_lock(closing):
    """As sim.step() refuses while the client holds sim.acquireLock, so does a plan."""
    env = closing(gg.GantryEnv(gg.ArmReach()))
    env.reset(seed=0)
    env.sim.acquireLock()
    with pytest.raises(Exception, match="acquireLock"):
        env.step(np.zeros(6))
    env.sim.releaseLock()
    env.step(np.zeros(6))


def test_get_attr_call_and_set_attr_reach_every_env(closing):
    vec = closing(VectorEnv(TASKS["ArmReach"], 3, 2))
    vec.reset(seed=0)
    assert vec.call("_checked_action", np.full(6, 3.0))[2].tolist() == [1.0] * 6
    vec.set_attr("marker", [1, 2, 3])
    assert vec.get_attr("marker") == (1, 2, 3)
    vec.set_attr("marker", 7)
    assert vec.get_attr("marker") == (7, 7, 7)
    with pytest.raises(ValueError, match="2 values for 3 envs"):
        vec.set_attr("marker", [1, 2])


class BubbleRobInPython(gg.BubbleRobAvoid):
    """BubbleRobAvoid without its step plan."""

    def plan(self, sim: Any) -> None:
        return None


def test_bubble_rob_step_plan_gives_what_its_python_gives(closing):
    planned = closing(VectorEnv(TASKS["BubbleRobAvoid"], 3, 2))
    python = closing(VectorEnv(lambda: BubbleRobInPython(max_episode_steps=LIMIT), 3, 2))
    actions = random_actions(planned.single_action_space, 3, 2 * LIMIT, seed=5)
    for g, w in zip(vector_rollout(planned, 9, actions), vector_rollout(python, 9, actions)):
        np.testing.assert_array_equal(g, w)
    assert planned.get_attr("_plan")[0] is not None and python.get_attr("_plan")[0] is None
    # The measurement behind the reward, as the infos report it.
    got, want = planned.step(actions[0])[4], python.step(actions[0])[4]
    np.testing.assert_array_equal(got["clearance"], want["clearance"])
    np.testing.assert_array_equal(got["collision"], want["collision"])


def test_bubble_rob_outcomes_are_its_methods_row_by_row(closing):
    """BubbleRobAvoid's batched outcomes give, bit for bit, what its per-env methods
    give, on the numbers its plan observes along a rollout (the rover driving and
    turning) and on rows made from them: tipped over, no distance found, the nose
    seeing something, a collision."""
    env = closing(gg.GantryEnv(gg.BubbleRobAvoid()))
    env.reset(seed=2)
    rows = []
    for a in random_actions(env.action_space, 1, 60, seed=6)[:, 0]:
        a = env._checked_action(a)
        rows.append(env.client._engine_here.run_plan(env._plan, a))
    values = np.array(rows)
    tipped = values[:3].copy()
    tipped[:, 9] = tipped[:, 13] = 0.0  # the body's x axis straight up: no heading
    tipped[:, 27] = 0  # no distance found
    near = values[-3:].copy()
    near[:, 0], near[:, 1] = 1.0, [0.02, 0.1, 0.149]  # the nose sees something
    near[:, 27], near[:, 34] = 1.0, [0.001, 0.005, 0.2]  # touching, at, beyond the clearance
    values = np.vstack([values, tipped, near])
    actions = np.zeros((len(values), 2), dtype=np.float32)
    task = env.task
    out = task.outcomes(values, actions)
    one = gg.BubbleRobAvoid()
    for r in range(len(values)):
        obs = one.observation(values[r])
        np.testing.assert_array_equal(out.observations[r], obs)
        assert out.rewards[r] == one.reward(None, obs, actions[r])
        assert out.terminated[r] == one.terminated(None, obs)
        assert {k: v[r].item() for k, v in out.infos.items()} == one.info(None, obs)
    assert out.observations[:, 0].any() and out.terminated.any() and not out.terminated.all()


def test_arm_reach_outcomes_are_its_methods_row_by_row():
    """Task.outcomes (the vector env's one numpy pass over a block) gives, bit for bit,
    what observation, reward, terminated and info give env by env, near the tolerance
    too."""
    task = gg.ArmReach()
    rng = np.random.default_rng(5)
    values = rng.uniform(-1.0, 1.0, size=(200, 12))
    # Tips at, just inside and just outside the tolerance from their targets.
    values[:60, 6:9] = values[:60, 9:12] + rng.normal(size=(60, 3)) * task.tolerance / 2
    values[0, 6:9] = values[0, 9:12]
    actions = rng.uniform(-1.0, 1.0, size=(200, 6)).astype(np.float32)
    out = task.outcomes(values, actions)
    assert 0 < out.terminated.sum() < 200
    one = gg.ArmReach()
    for r in range(len(values)):
        obs = np.asarray(one.observation(values[r]), dtype=np.float32)
        np.testing.assert_array_equal(out.observations[r], obs)
        assert out.rewards[r] == one.reward(None, obs, actions[r])
        assert out.terminated[r] == one.terminated(None, obs)
        assert {k: v[r].item() for k, v in out.infos.items()} == one.info(None, obs)


class CountingArmReach(gg.ArmReach):
    """ArmReach counting the calls of its per-env reward and of its batched outcomes."""

    def __init__(self, **options: Any):
        super().__init__(**options)
        self.rewards = self.batches = 0

    def reward(self, sim: Any, obs: np.ndarray, action: np.ndarray) -> float:
        self.rewards += 1
        return super().reward(sim, obs, action)

    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> gg.Outcomes:
        self.batches += 1
        return super().outcomes(values, actions)


def test_a_block_computes_its_outcomes_in_one_pass(closing):
    vec = closing(VectorEnv(lambda: CountingArmReach(max_episode_steps=LIMIT), 6, 2))
    vec.reset(seed=1)
    for _ in range(5):
        vec.step(np.zeros((6, 6)))
    tasks = vec.get_attr("task")
    # No per-env reward. One call per block and step, on the block's first task; at the
    # first step a block learns that its task batches from its first env alone.
    assert all(t.rewards == 0 for t in tasks)
    assert [t.batches for t in tasks] == [5, 1, 0, 5, 1, 0]


class BadOutcomes(gg.ArmReach):
    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> gg.Outcomes:
        good = super().outcomes(values, actions)
        return good._replace(rewards=good.rewards[:-1])


def test_outcomes_of_the_wrong_shape_are_a_clear_error(closing):
    vec = closing(VectorEnv(BadOutcomes, 4, 2))
    vec.reset(seed=0)
    message = r"env 0 failed: ValueError: BadOutcomes.outcomes: rewards must be a \(\d,\) float64 array, got \(\d,\)"
    with pytest.raises(RuntimeError, match=message):
        vec.step(np.zeros((4, 6)))


def test_a_failing_plan_on_a_parked_worker_names_its_env_and_leaves_the_env_usable(closing):
    """Once blocks batch their outcomes, the worker threads run their plans parked
    outside Python (PlanServer); a plan failing there is raised by the step, naming the
    env, and every other command still gets its own answer."""
    vec = closing(VectorEnv(lambda: BreakableArm(max_episode_steps=None), 4, 2))
    vec.reset(seed=0)
    for _ in range(3):
        vec.step(np.zeros((4, 6)))
    assert [w.parked for w in vec._workers] == [True]
    # Env 3 (the worker's) loses the target its plan observes, removed in its own thread.
    vec.set_attr("breaker", [None, None, None, vec.get_attr("task")[3].remove_target])
    vec.call("breaker")
    with pytest.raises(RuntimeError, match=r"env 3 failed: Exception: .*sim\.getObjectPosition"):
        vec.step(np.zeros((4, 6)))
    # The caller's block took its step; the failed block's outcomes were not taken.
    assert vec.get_attr("_steps") == (4, 4, 3, 3)
    with pytest.raises(RuntimeError, match="env 3 failed"):
        vec.step(np.zeros((4, 6)))


class BreakableArm(gg.ArmReach):
    """ArmReach that can lose the target dummy its observation reads."""

    def setup(self, sim: Any) -> None:
        super().setup(sim)
        self.sim = sim

    def remove_target(self) -> None:
        self.sim.removeObjects([self.target_dummy])


class InterruptingOutcomes(gg.ArmReach):
    interrupt = False

    def outcomes(self, values: np.ndarray, actions: np.ndarray) -> gg.Outcomes:
        if self.interrupt:
            self.interrupt = False
            raise Interrupted()
        return super().outcomes(values, actions)


def test_an_interrupted_parked_step_leaves_no_stale_batch(closing):
    """A parked step interrupted in the caller's thread leaves the worker's numbers
    unread; the next step must get its own batch, not that one."""
    vec = closing(VectorEnv(lambda: InterruptingOutcomes(max_episode_steps=None), 4, 2))
    twin = closing(VectorEnv(lambda: gg.ArmReach(max_episode_steps=None), 4, 2))
    actions = random_actions(vec.single_action_space, 4, 6, seed=3)
    for env in (vec, twin):
        env.reset(seed=5)
    for row in actions[:3]:
        vec.step(row)
        twin.step(row)
    vec.get_attr("task")[0].interrupt = True
    with pytest.raises(Interrupted):
        vec.step(actions[3])
    twin.step(actions[3])
    # The interrupted step moved the simulations, not the vector env's books: the next
    # observations must still be those of its own batch (the twin's next step).
    got, want = vec.step(actions[4]), twin.step(actions[4])
    np.testing.assert_array_equal(got[0], want[0])


def test_a_worker_that_cannot_serve_its_plans_answers_with_the_reason():
    """Engine.serve_plans refuses a client that paces itself to the wall clock, and
    answers each batch with the reason until released, so that no caller waits for
    ever."""
    from gantry._gantry import Engine, PlanServer

    server = PlanServer()
    done = threading.Event()

    def worker() -> None:
        client = gantry_client(realtime=True)
        plan = client_plan(client)
        Engine.serve_plans(server, [client._engine_here], [plan])
        client.close()
        done.set()

    thread = threading.Thread(target=worker)
    thread.start()
    server.step(1, np.zeros((1, 6), dtype=np.float32))
    with pytest.raises(Exception, match="runs in real time"):
        while server.collect(1, 1.0) is None:
            pass
    server.release()
    thread.join(10)
    assert done.is_set()


def gantry_client(**options: Any) -> Any:
    import gantry

    return gantry.Client("fk_arm", scripts=False, autostart=True, **options)


def client_plan(client: Any) -> Any:
    task = gg.ArmReach()
    task.setup(client.require("sim"))
    return task.plan(client.require("sim"))
