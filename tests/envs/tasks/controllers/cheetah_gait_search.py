#!/usr/bin/env python3
"""Finds the open-loop gait that tests/envs/tasks/cheetah_test.cc runs on CheetahRun-v0.

The gait: leg j's action at control step t is clip(amplitude_j * sin(2 pi frequency t 0.01 s +
phase_j) + offset_j, -1, 1), the same for every episode (no feedback). The search is the
cross-entropy method over the 19 numbers (frequency, then amplitude, phase and offset of each of
the six legs), scoring each by its mean return over episodes of seeds 0 and 1 (state only, 1000
control steps). Deterministic: the same numbers each run.

Usage: PYTHONPATH=build/python /usr/bin/python3 tests/envs/tasks/controllers/cheetah_gait_search.py
Prints the best gait as C++ initializers for the test.
"""
import math

import numpy as np
import pixelgym

STEPS = 1000
SEEDS = (0, 1)


def actions(params):
    frequency = params[0]
    amplitude, phase, offset = params[1:7], params[7:13], params[13:19]
    t = np.arange(STEPS)[:, None] * 0.01
    return np.clip(amplitude * np.sin(2 * math.pi * frequency * t + phase) + offset, -1,
                   1).astype(np.float32)


def score(env, params):
    plan = actions(params)
    total = 0.0
    for seed in SEEDS:
        env.reset(seed=seed)
        for t in range(STEPS):
            _, reward, _, _, _ = env.step(plan[t])
            total += reward
    return total / len(SEEDS)


def main():
    env = pixelgym.make("CheetahRun-v0", obs_mode="state")
    rng = np.random.default_rng(0)
    mean = np.concatenate([[2.0], np.full(6, 0.8), np.zeros(6), np.zeros(6)])
    std = np.concatenate([[1.0], np.full(6, 0.3), np.full(6, math.pi), np.full(6, 0.3)])
    best = (-1.0, mean)
    for iteration in range(14):
        population = mean + std * rng.standard_normal((24, 19))
        population[:, 0] = np.clip(population[:, 0], 0.3, 6.0)
        population[:, 1:7] = np.clip(population[:, 1:7], 0.0, 1.5)
        scores = np.array([score(env, p) for p in population])
        elite = population[np.argsort(scores)[-6:]]
        mean, std = elite.mean(axis=0), elite.std(axis=0) + 0.02
        if scores.max() > best[0]:
            best = (float(scores.max()), population[int(np.argmax(scores))])
        print("iteration %d: best %.1f, mean %.1f" % (iteration, scores.max(), scores.mean()),
              flush=True)
    value, params = best
    print("best mean return %.1f" % value)
    print("frequency_hz = %.4f" % params[0])
    for name, part in (("amplitude", params[1:7]), ("phase", params[7:13]),
                       ("offset", params[13:19])):
        print("%s = {%s}" % (name, ", ".join("%.4f" % v for v in part)))


if __name__ == "__main__":
    main()
