#!/usr/bin/env python3
"""Python-side steps per second of pixelgym's vector env against the C++ figure for the same
config, and against a Python loop over single envs, in interleaved rounds of one run.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_vector_bench.py \\
        [--id CartPoleSwingup-v0] [--num-envs 8] [--threads 2] [--steps 4000] [--rounds 5]

Each round measures, one after the other:
- C++: `build/examples/pixelgym bench ID --num-envs N --threads T --steps S` (make_vec's
  AsyncVectorEnv stepped from C++ with precomputed random actions), its `steps_per_s=`;
- Python vector: pixelgym.make_vec(ID, N, num_threads=T) stepped from Python with numpy random
  actions (np.random.Generator.uniform / integers);
- Python loop: N pixelgym.make(ID) envs stepped one after the other in a Python loop, numpy
  random actions, resetting those that end.
All three draw a pool of 64 random batches before timing and cycle through it, as the C++ bench
does, so that the figures compare stepping and not random number generation (drawing a batch of
8 float32 actions with numpy each step costs about 10-30 us, some 2-5% of a step here).
Total env steps per second (84x84 pixels + state by default), medians over the rounds, and the
ratios to C++ in the same rounds. The issue's target: Python vector >= 0.9x C++.
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import time
import warnings

import numpy as np

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import pixelgym

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
POOL = 64  # random action batches drawn before timing, as `pixelgym bench` does


def random_actions(space, rng, batch):
    """A batch of random actions from numpy for a Box or Discrete space (pixelgym's or
    gymnasium's: both have shape/dtype, low/high or n/start)."""
    if hasattr(space, "n"):
        return rng.integers(space.start, space.start + space.n, batch)
    return rng.uniform(space.low, space.high, (batch, *space.shape)).astype(space.dtype)


def cpp_steps_per_s(cli, env_id, num_envs, threads, steps):
    out = subprocess.run([cli, "bench", env_id, "--num-envs", str(num_envs), "--threads",
                          str(threads), "--steps", str(steps)], check=True, capture_output=True,
                         text=True).stdout
    return float(re.search(r"steps_per_s=(\d+)", out).group(1))


def python_vector_steps_per_s(env_id, num_envs, threads, steps):
    envs = pixelgym.make_vec(env_id, num_envs, num_threads=threads)
    rng = np.random.default_rng(0)
    envs.reset(seed=0)
    space = envs.single_action_space
    pool = [random_actions(space, rng, num_envs) for _ in range(POOL)]
    for t in range(20):  # warm up, as the C++ bench does
        envs.step(pool[t % POOL])
    batches = (steps + num_envs - 1) // num_envs
    start = time.perf_counter()
    for t in range(batches):
        envs.step(pool[t % POOL])
    seconds = time.perf_counter() - start
    envs.close()
    return batches * num_envs / seconds


def python_loop_steps_per_s(env_id, num_envs, steps):
    envs = [pixelgym.make(env_id) for _ in range(num_envs)]
    rng = np.random.default_rng(0)
    for i, env in enumerate(envs):
        env.reset(seed=i)
    space = envs[0].action_space
    pool = [random_actions(space, rng, num_envs) for _ in range(POOL)]
    batches = (steps + num_envs - 1) // num_envs

    def run(count):
        for t in range(count):
            for env, action in zip(envs, pool[t % POOL]):
                _, _, terminated, truncated, _ = env.step(action)
                if terminated or truncated:
                    env.reset()

    run(20)
    start = time.perf_counter()
    run(batches)
    seconds = time.perf_counter() - start
    for env in envs:
        env.close()
    return batches * num_envs / seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--id", default="CartPoleSwingup-v0")
    parser.add_argument("--num-envs", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--steps", type=int, default=4000, help="env steps per measurement")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--cli", default=os.path.join(ROOT, "build", "examples", "pixelgym"))
    args = parser.parse_args()

    rows = {"C++ (pixelgym bench)": [], "Python vector": [], "Python loop of single envs": []}
    for round_index in range(args.rounds):
        cpp = cpp_steps_per_s(args.cli, args.id, args.num_envs, args.threads, args.steps)
        vector = python_vector_steps_per_s(args.id, args.num_envs, args.threads, args.steps)
        loop = python_loop_steps_per_s(args.id, args.num_envs, args.steps)
        for name, value in zip(rows, (cpp, vector, loop)):
            rows[name].append(value)
        print(f"round {round_index + 1}: C++ {cpp:,.0f}  Python vector {vector:,.0f} "
              f"({vector / cpp:.2f}x)  Python loop {loop:,.0f} ({loop / cpp:.2f}x)", flush=True)

    cpp = rows["C++ (pixelgym bench)"]
    print(f"\n{args.id}, {args.num_envs} envs, {args.threads} threads, {args.steps} env steps per "
          f"measurement, medians of {args.rounds} rounds (env steps/s, ratio to C++ in the same "
          "rounds):")
    for name, values in rows.items():
        ratios = [value / base for value, base in zip(values, cpp)]
        print(f"  {name:28s} {statistics.median(values):>10,.0f}   "
              f"{statistics.median(ratios):.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
