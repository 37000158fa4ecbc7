#!/usr/bin/env python3
"""Finds the numbers of the scripted controller that tests/envs/tasks/finger_test.cc runs on
FingerSpin-v0.

The controller: the fingertip's target runs round an ellipse (centre x, z from the spinner's
hinge, radii, frequency) counter-clockwise as the camera sees it, and waits `back` m left of the
centre while the spinner turns faster than `rest` rad/s (until it slows to max(16, rest - 15));
the finger's inverse kinematics (links of 0.18 and 0.16 m) turn the target into joint angles,
reached by PD torques (kp, kd). The search is the cross-entropy method over those 9 numbers,
scoring each by its mean return over episodes of seeds 0 and 1 (state only, 1000 control steps),
from the starting mean below (itself the end of an earlier search). Deterministic.

Usage: PYTHONPATH=build/python /usr/bin/python3 tests/envs/tasks/controllers/finger_spin_search.py
Prints the best numbers, in the order of SpinController's fields in the test.
"""
import math

import numpy as np
import pixelgym

L1, L2 = 0.18, 0.16
SEEDS = (0, 1)
ITERATIONS, POPULATION, ELITE = 8, 16, 4


def ik(x, z):
    c2 = max(-1.0, min(1.0, (x * x + z * z - L1 * L1 - L2 * L2) / (2 * L1 * L2)))
    q2 = math.acos(c2)
    return math.atan2(z, x) - math.atan2(L2 * math.sin(q2), L1 + L2 * math.cos(q2)), q2


def episode(env, params, seed):
    cx, cz, rx, rz, frequency, kp, kd, rest, back = params
    obs, _ = env.reset(seed=seed)
    total, phase, resting = 0.0, 0.0, False
    for _ in range(1000):
        rate = obs["joint_vel"][2]
        if rate < -rest:
            resting = True
        if rate > -max(16.0, rest - 15.0):
            resting = False
        if resting:
            x, z = cx - back, cz
        else:
            phase += 2 * math.pi * frequency * 0.02
            x, z = cx + rx * math.cos(phase), cz + rz * math.sin(phase)
        q1, q2 = ik(x + 0.4, z)  # the spinner's hinge is 0.4 m right of the proximal one
        q, qd = obs["joint_pos"], obs["joint_vel"]
        action = np.clip([(kp * (q1 - q[0]) - kd * qd[0]) / 30.0,
                          (kp * (q2 - q[1]) - kd * qd[1]) / 15.0], -1, 1)
        obs, reward, _, _, _ = env.step(action.astype(np.float32))
        total += reward
    return total


def main():
    env = pixelgym.make("FingerSpin-v0", obs_mode="state")
    rng = np.random.default_rng(2)
    mean = np.array([-0.11333, 0.06581, 0.06067, 0.2528, 1.1565, 70.63178, 0.69569, 35.61848,
                     0.12646])
    std = np.array([0.02, 0.03, 0.02, 0.04, 0.3, 15.0, 0.3, 8.0, 0.05])
    best = (-1.0, None)
    for iteration in range(ITERATIONS):
        population = mean + std * rng.standard_normal((POPULATION, len(mean)))
        population[0] = mean
        population[:, 2:7] = np.abs(population[:, 2:7])
        scores = np.array([np.mean([episode(env, p, s) for s in SEEDS]) for p in population])
        elite = population[np.argsort(scores)[-ELITE:]]
        mean, std = elite.mean(0), elite.std(0) + 1e-3 * np.abs(mean)
        if scores.max() > best[0]:
            best = (scores.max(), population[np.argmax(scores)])
        print("iteration %d: best %.0f, mean %.0f" % (iteration, scores.max(), scores.mean()),
              flush=True)
    print("best %.1f:" % best[0], ", ".join("%.5f" % v for v in best[1]))


if __name__ == "__main__":
    main()
