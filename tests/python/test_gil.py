"""The GIL is released while C++ steps: a Python thread runs during a vector step."""

import sys
import threading
import time

import numpy as np
import pytest

import pixelgym


def ran_during(call, trials=20):
    """Whether a Python thread, woken just before `call()`, ran in the first half of the call, in
    any of `trials` tries; with, for the message of a failed check, where each try's thread ran
    (ms after the call began) against the call's length. The switch interval is raised to 10 s
    meanwhile, so that the interpreter never takes the GIL from the calling thread by itself: the
    other thread can run during the call only if the call releases the GIL. The first half:
    converting the results after the C++ step may release the GIL too (numpy's copy does, even
    for 4 numbers), so a thread running near the end proves nothing about the step."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(10.0)
    tries = []
    try:
        for _ in range(trials):
            go = threading.Event()
            ran_at = []
            thread = threading.Thread(target=lambda: (go.wait(), ran_at.append(time.monotonic())))
            thread.start()
            time.sleep(0.01)  # the thread is now waiting on the event
            go.set()
            called_at = time.monotonic()
            call()
            returned_at = time.monotonic()
            thread.join()
            if called_at < ran_at[0] < called_at + 0.5 * (returned_at - called_at):
                return True, ""
            ran_ms, call_ms = 1e3 * (ran_at[0] - called_at), 1e3 * (returned_at - called_at)
            tries.append(f"{ran_ms:.2f} ms into a {call_ms:.2f} ms call")
    finally:
        sys.setswitchinterval(previous)
    return False, "the thread ran only late in each try: " + ", ".join(tries)


# The calls are made long (8 ms and more here) so that the thread's wake-up is a small part of
# their first half, and the vector env steps on one worker, leaving the second core to the thread.
# ctest runs this file alone (RUN_SERIAL in tests/python/CMakeLists.txt): another test loading both
# cores could delay the thread past the first half of every try.
@pytest.mark.parametrize("mode", ["async", "sync"])
def test_a_python_thread_runs_while_the_vector_env_steps(mode):
    envs = pixelgym.make_vec("ArmReach-v0", 8, mode=mode, num_threads=1, width=512, height=512)
    envs.reset(seed=0)
    actions = np.zeros((8, 7), np.float32)
    ran, where = ran_during(lambda: envs.step(actions))
    assert ran, where
    ran, where = ran_during(lambda: envs.reset(seed=1))
    assert ran, where
    envs.close()


def test_a_python_thread_runs_while_a_single_env_steps():
    env = pixelgym.make("ArmReach-v0", width=1024, height=1024)
    env.reset(seed=0)
    ran, where = ran_during(lambda: env.step(np.zeros(7, np.float32)))
    assert ran, where


def test_the_check_fails_for_a_call_that_holds_the_gil():
    def busy():  # pure Python: holds the GIL throughout
        end = time.monotonic() + 0.01
        while time.monotonic() < end:
            pass

    ran, where = ran_during(busy, trials=3)
    assert not ran
    assert where.count(" ms call") == 3, where
