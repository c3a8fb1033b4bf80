"""Vector environments in one process (issue 33, item 3): steps per second of
``gantry.gym.VectorEnv`` with 1 and 2 threads, on ``gantry/BubbleRobAvoid-v0``
and ``gantry/ArmReach-v0``, in one run on one machine.

For each task and each number of envs, the 1-thread and 2-thread vector envs are timed
in alternation, ``--rounds`` times, each round ``--steps`` vector steps of fixed random
actions (the same for both) after a warm-up; the figure is the median env steps per
second (vector steps times envs), and the speed-up is the ratio of the medians. For
reference, the same envs stepped one after the other in a plain loop (``GantryEnv.step``)
give the serial rate.

Two figures say what the speed-up can be. The *ceiling*: two bare simulations of the
task's scene advancing in two threads (``Client.advance``, no Python between steps)
against one after the other, timed in the same rounds: what the machine's free cores
give (2.0 on an idle two-core machine; less when other work shares them). The *bound*:
in a one-thread vector env, the time per env step with the GIL held (the task's Python,
the envs' bookkeeping) against the time with it released (the step plans: act calls,
steps and observe calls; or, for a task without a plan, its physics steps); Python runs
one thread at a time, so two threads give at most (held + released) / held.

Target: 2 threads at least 1.8x one thread on both tasks. Needs a quiet machine with two
free cores (a ceiling near 2).

    .venv/bin/python tools/bench/vector_env.py [--envs 4 16 64] [--steps 300] [--rounds 5] \
        [--ceiling-steps 1000] [--json target/bench/vector_env.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import threading
import time
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

import gantry
import gantry.gym as gg
import gantry.vector as gv

REPO = Path(__file__).resolve().parents[2]
TASKS = {"BubbleRobAvoid": "gantry/BubbleRobAvoid-v0", "ArmReach": "gantry/ArmReach-v0"}
SCENES = {"BubbleRobAvoid": "bubble_rob", "ArmReach": "fk_arm"}
TARGET_SPEEDUP = 1.8


def actions(env_id: str, num_envs: int, steps: int, seed: int = 0) -> np.ndarray:
    """``steps`` rows of ``num_envs`` random actions, the same on every call."""
    probe = gymnasium.make(env_id)
    probe.action_space.seed(seed)
    out = np.array([[probe.action_space.sample() for _ in range(num_envs)] for _ in range(steps)])
    probe.close()
    return out


def vector_rate(env: gg.VectorEnv, batch: np.ndarray) -> float:
    """Env steps per second over ``batch`` (one row of actions per vector step)."""
    env.reset(seed=0)
    t0 = time.perf_counter()
    for a in batch:
        env.step(a)
    return len(batch) * env.num_envs / (time.perf_counter() - t0)


def serial_rate(envs: list[gymnasium.Env], batch: np.ndarray) -> float:
    """The same steps on separate envs in a plain loop, with autoreset by hand."""
    for i, env in enumerate(envs):
        env.reset(seed=i)
    t0 = time.perf_counter()
    for a in batch:
        for env, ai in zip(envs, a):
            _, _, terminated, truncated, _ = env.step(ai)
            if terminated or truncated:
                env.reset()
    return len(batch) * len(envs) / (time.perf_counter() - t0)


def ceiling(scene: str, steps: int) -> float:
    """Two bare simulations advancing ``steps`` steps in two threads, against one after
    the other: the speed-up the machine's free cores allow."""

    def run(out: list[float], start: threading.Barrier | None) -> None:
        client = gantry.Client(scene, realtime=False, scripts=False)
        client.advance(10)
        if start is not None:
            start.wait()  # both made: the timed parts overlap
        t0 = time.perf_counter()
        client.advance(steps)
        out.append(time.perf_counter() - t0)
        client.close()

    alone: list[float] = []
    run(alone, None)
    run(alone, None)
    together: list[float] = []
    start = threading.Barrier(2)
    threads = [threading.Thread(target=run, args=(together, start)) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return sum(alone) / max(together)


def released_share(env_id: str, num_envs: int, batch: np.ndarray) -> dict[str, float]:
    """Microseconds per env step, in a one-thread vector env of ``num_envs`` envs, with
    the GIL released (the block's step plans, or else the envs' physics steps) and held
    (everything else: the task's Python, the env's and vector env's bookkeeping). Calls
    that release the GIL on their own (BubbleRob's proximity sensor and distance query)
    count as held, so the bound is a lower one."""
    released = [0.0]
    clock = time.perf_counter
    original = gv.Engine
    run_plans = original.run_plans

    class TimedEngine:
        @staticmethod
        def run_plans(*args: Any) -> Any:
            t0 = clock()
            try:
                return run_plans(*args)
            finally:
                released[0] += clock() - t0

    env: Any = gymnasium.make_vec(env_id, num_envs=num_envs, num_threads=1)
    for e in env._local.envs:
        step = e.sim.step

        def timed_step(step: Any = step) -> None:
            t0 = clock()
            step()
            released[0] += clock() - t0

        e.sim.step = timed_step
    gv.Engine = TimedEngine  # type: ignore[assignment,misc]
    try:
        vector_rate(env, batch[: len(batch) // 10])
        released[0] = 0.0
        env.reset(seed=0)
        t0 = clock()
        for a in batch:
            env.step(a)
        total = clock() - t0
    finally:
        gv.Engine = original  # type: ignore[misc]
        env.close()
    steps = len(batch) * num_envs
    return {"step_us": released[0] / steps * 1e6, "python_us": (total - released[0]) / steps * 1e6}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--envs", type=int, nargs="+", default=[4, 16, 64])
    parser.add_argument("--steps", type=int, default=300, help="vector steps per timed run")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--ceiling-steps", type=int, default=1000, help="steps per bare simulation for the ceiling")
    parser.add_argument("--json", type=Path, default=REPO / "target" / "bench" / "vector_env.json")
    args = parser.parse_args()

    results: dict[str, Any] = {"target_speedup": TARGET_SPEEDUP, "tasks": {}}
    for name, env_id in TASKS.items():
        task: dict[str, Any] = {"profile": released_share(env_id, 8, actions(env_id, 8, 300)), "runs": []}
        prof = task["profile"]
        prof["bound"] = (prof["step_us"] + prof["python_us"]) / prof["python_us"]
        print(
            f"{name}: one env step = {prof['step_us']:.1f} us GIL released (plan or physics) "
            f"+ {prof['python_us']:.1f} us GIL held: 2 threads at most {prof['bound']:.2f}x"
        )
        for n in args.envs:
            batch = actions(env_id, n, args.steps)
            one = gymnasium.make_vec(env_id, num_envs=n, num_threads=1)
            two = gymnasium.make_vec(env_id, num_envs=n, num_threads=2)
            serial = [gymnasium.make(env_id) for _ in range(n)]
            warm = batch[: max(1, args.steps // 10)]
            vector_rate(one, warm), vector_rate(two, warm), serial_rate(serial, warm)
            rates: dict[str, list[float]] = {"serial": [], "1": [], "2": [], "ceiling": []}
            for _ in range(args.rounds):
                rates["serial"].append(serial_rate(serial, batch))
                rates["1"].append(vector_rate(one, batch))
                rates["2"].append(vector_rate(two, batch))
                rates["ceiling"].append(ceiling(SCENES[name], args.ceiling_steps))
            for env in (one, two, *serial):
                env.close()
            med = {k: statistics.median(v) for k, v in rates.items()}
            run = {
                "num_envs": n,
                "serial_steps_per_s": med["serial"],
                "threads_1_steps_per_s": med["1"],
                "threads_2_steps_per_s": med["2"],
                "speedup_2_over_1": med["2"] / med["1"],
                "ceiling": med["ceiling"],
                "rounds": rates,
            }
            task["runs"].append(run)
            print(
                f"  {n} envs: serial loop {med['serial']:8.0f} steps/s | 1 thread {med['1']:8.0f} | "
                f"2 threads {med['2']:8.0f} steps/s = {run['speedup_2_over_1']:.2f}x "
                f"(ceiling {med['ceiling']:.2f}x)"
            )
        results["tasks"][name] = task
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(results, indent=2))
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
