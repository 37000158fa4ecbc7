"""The GIL is released while C++ steps: a Python thread runs during a vector step."""

import sys
import threading
import time

import numpy as np
import pytest

import pixelgym


def ran_during(call, trials=20):
    """Whether a Python thread, woken just before `call()`, ran in the first half of the call, in
    any of `trials` tries. The switch interval is raised to 10 s meanwhile, so that the
    interpreter never takes the GIL from the calling thread by itself: the other thread can run
    during the call only if the call releases the GIL. The first half: converting the results
    after the C++ step may release the GIL too (numpy's copy does, even for 4 numbers), so a
    thread running near the end proves nothing about the step."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(10.0)
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
                return True
    finally:
        sys.setswitchinterval(previous)
    return False


@pytest.mark.parametrize("mode", ["async", "sync"])
def test_a_python_thread_runs_while_the_vector_env_steps(mode):
    # 8 envs of 256x256 frames make a step long enough (over 10 ms) for the thread to be
    # scheduled in its first half even on a loaded machine.
    envs = pixelgym.make_vec("ArmReach-v0", 8, mode=mode, num_threads=2, width=256, height=256)
    envs.reset(seed=0)
    actions = np.zeros((8, 7), np.float32)
    assert ran_during(lambda: envs.step(actions))
    assert ran_during(lambda: envs.reset(seed=1))
    envs.close()


def test_a_python_thread_runs_while_a_single_env_steps():
    env = pixelgym.make("ArmReach-v0", width=256, height=256)
    env.reset(seed=0)
    assert ran_during(lambda: env.step(np.zeros(7, np.float32)))


def test_the_check_fails_for_a_call_that_holds_the_gil():
    def busy():  # pure Python: holds the GIL throughout
        end = time.monotonic() + 0.01
        while time.monotonic() < end:
            pass

    assert not ran_during(busy, trials=3)
