"""Errors are Python exceptions with pixelgym's messages, never a crash."""

import numpy as np
import pytest

import pixelgym


def made(env_id="CartPoleSwingup-v0", **kwargs):
    env = pixelgym.make(env_id, **kwargs)
    env.reset(seed=0)
    return env


def test_unknown_id_suggests_the_closest():
    with pytest.raises(ValueError, match=r'unknown env id "CartPoleSwingUp-v0"; did you mean '
                                         r"CartPoleSwingup-v0"):
        pixelgym.make("CartPoleSwingUp-v0")
    with pytest.raises(ValueError, match="unknown env id"):
        pixelgym.make_vec("Nope-v9", 2)


def test_unknown_kwarg_is_a_value_error_listing_the_valid_ones():
    with pytest.raises(ValueError, match=r'CartPoleSwingup-v0: unknown kwarg "widht"; did you mean '
                                         r"width\? valid kwargs: .*width \(int, default 84\)"):
        pixelgym.make("CartPoleSwingup-v0", widht=64)


def test_a_mistyped_wrapper_suggests_the_closest_and_the_docs_words_work():
    with pytest.raises(ValueError, match=r'unknown wrapper "grayscal"; did you mean grayscale\?'):
        pixelgym.make("CartPoleSwingup-v0", wrap=["grayscal"])
    grey = pixelgym.make("CartPoleSwingup-v0", obs_mode="pixels", wrap=["greyscale"])
    assert grey.observation_space["pixels"].shape == (84, 84)


def test_kwarg_of_the_wrong_type_is_a_type_error_with_the_registry_message():
    with pytest.raises(TypeError) as error:
        pixelgym.make("CartPoleSwingup-v0", width="64")
    assert str(error.value) == 'CartPoleSwingup-v0: kwarg "width" must be an int, got string "64"'
    with pytest.raises(TypeError, match='kwarg "shadows" must be a bool, got int 1'):
        pixelgym.make_vec("CartPoleSwingup-v0", 2, shadows=1)
    with pytest.raises(TypeError, match=r'kwarg "width" must be a bool, int, float or str, got list'):
        pixelgym.make("CartPoleSwingup-v0", width=[64])
    # An int where a float is declared is converted, as Python would.
    pixelgym.make("CartPoleSwingup-v0", obs_mode="state")


def test_a_bad_kwarg_value_is_a_value_error():
    with pytest.raises(ValueError, match='obs_mode'):
        pixelgym.make("GridWorld-v0", obs_mode="rgba")
    with pytest.raises(ValueError, match="max_episode_steps"):
        pixelgym.make("GridWorld-v0", max_episode_steps=-1)
    with pytest.raises(ValueError, match="render_mode"):
        pixelgym.make("GridWorld-v0", render_mode="human")


def test_bad_wrapper_specs_and_vector_options():
    with pytest.raises(ValueError, match="resize"):
        pixelgym.make("CartPoleSwingup-v0", wrap=["resize=64y64"])
    with pytest.raises(ValueError, match="unknown wrapper|known"):
        pixelgym.make_vec("CartPoleSwingup-v0", 2, wrap=["blur"])
    with pytest.raises(ValueError, match="NextStep"):
        pixelgym.make_vec("GridWorld-v0", 2, autoreset_mode="Sometimes")
    with pytest.raises(ValueError, match="mode"):
        pixelgym.make_vec("GridWorld-v0", 2, mode="processes")
    with pytest.raises(ValueError, match="num_envs"):
        pixelgym.make_vec("GridWorld-v0", 0)


def test_counts_out_of_range_or_of_the_wrong_type_name_the_argument():
    # Issue 42: 2**40 gave pybind11's "incompatible constructor arguments" listing the overloads.
    for value in (2**40, 2**31, -1, -2**40):
        with pytest.raises(ValueError) as error:
            pixelgym.make_vec("GridWorld-v0", value)
        assert str(error.value) == (f"make_vec: num_envs must be from 1 to 2147483647, got "
                                    f"num_envs = {value}")
    with pytest.raises(ValueError, match=r"num_threads must be from 0 to 2147483647, got "
                                         r"num_threads = 1099511627776"):
        pixelgym.make_vec("GridWorld-v0", 2, num_threads=2**40)
    for value in ("4", 4.0, True, None):
        with pytest.raises(TypeError, match=r"make_vec: num_envs must be an int, got "):
            pixelgym.make_vec("GridWorld-v0", value)
    assert pixelgym.make_vec("GridWorld-v0", np.int64(2), mode="sync").num_envs == 2


def test_more_envs_than_the_memory_holds_are_refused_before_any_is_built():
    # Issue 42: make_vec(20000) built envs until the machine ran out of memory.
    with pytest.raises(ValueError, match=r'make_vec\("CartPoleSwingup-v0"\): num_envs = 20000000 '
                                         r"envs would take about .* \(an estimate: .* per env\), "
                                         r"more than the .* available \("):
        pixelgym.make_vec("CartPoleSwingup-v0", 20_000_000)
    with pytest.raises(TypeError, match="thread pool"):
        pixelgym.make_vec("GridWorld-v0", 2, mode="sync").step_async(np.zeros(2, np.int64))


def test_one_wrapper_spec_may_be_given_as_a_string():
    # A str is one spec, not a sequence of one-letter specs ("unknown wrapper 'g'").
    env = pixelgym.make("CartPoleSwingup-v0", wrap="grayscale", obs_mode="pixels")
    assert env.observation_space["pixels"].shape == (84, 84)
    env.close()
    vec = pixelgym.make_vec("CartPoleSwingup-v0", 2, wrap="grayscale", obs_mode="pixels",
                            mode="sync")
    assert vec.single_observation_space["pixels"].shape == (84, 84)
    vec.close()
    assert pixelgym.info("CartPoleSwingup-v0", wrap="grayscale", obs_mode="pixels")
    with pytest.raises(TypeError, match="wrap= takes a wrapper spec"):
        pixelgym.make("CartPoleSwingup-v0", wrap=5)
    with pytest.raises(TypeError, match="got int 3"):
        pixelgym.make("CartPoleSwingup-v0", wrap=["grayscale", 3])


def test_wrong_actions_raise_value_errors_naming_the_space():
    env = made()
    with pytest.raises(ValueError, match=r"not in Box\(-1.0, 1.0, \(1,\), float32\): shape \(2,\)"):
        env.step(np.zeros(2, np.float32))
    with pytest.raises(ValueError, match="not in Box"):
        env.step(np.array([np.nan], np.float32))
    with pytest.raises(ValueError, match="not in Box"):
        env.step(np.array([1.5], np.float32))
    with pytest.raises(ValueError, match="not in Box"):
        env.step(0.5)  # a scalar for a (1,) Box
    with pytest.raises(TypeError, match="expected a numeric array"):
        env.step("left")
    with pytest.raises(TypeError, match="expected a numeric array"):
        env.step(None)
    env.step(np.array([0.5]))  # float64 is cast to the float32 Box
    discrete = made("GridWorld-v0")
    with pytest.raises(ValueError, match=r"not in Discrete\(4\)"):
        discrete.step(4)
    with pytest.raises(ValueError, match=r"not in Discrete\(4\)"):
        discrete.step(1.0)  # a float is not an action of a Discrete space
    with pytest.raises(ValueError, match=r"not in Discrete\(4\)"):
        discrete.step(np.array([1]))
    discrete.step(np.int32(1))


def test_calls_out_of_order_raise_reset_needed():
    env = pixelgym.make("GridWorld-v0")
    with pytest.raises(pixelgym.ResetNeeded, match="reset"):
        env.step(0)
    with pytest.raises(RuntimeError):  # ResetNeeded is a RuntimeError
        env.render()
    envs = pixelgym.make_vec("GridWorld-v0", 2)
    with pytest.raises(pixelgym.ResetNeeded):
        envs.step(np.zeros(2, np.int64))


def test_vector_errors_name_the_env_and_a_full_reset_recovers():
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 4, num_threads=2, obs_mode="state")
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="expected|layout|shape"):
        envs.step(np.zeros((3, 1), np.float32))
    actions = np.zeros((4, 1), np.float32)
    actions[2] = np.nan
    with pytest.raises(ValueError, match=r"env 2 .*not in Box"):
        envs.step(actions)
    with pytest.raises(pixelgym.ResetNeeded):
        envs.step(np.zeros((4, 1), np.float32))
    envs.reset(seed=0)
    envs.step(np.zeros((4, 1), np.float32))


def test_bad_seeds():
    env = pixelgym.make("GridWorld-v0")
    with pytest.raises(ValueError, match=r"seed must be in \[0, 2\*\*64\), got -1"):
        env.reset(seed=-1)
    with pytest.raises(TypeError, match="seed must be None or an int"):
        env.reset(seed=1.5)
    with pytest.raises(ValueError, match="3 seeds given for 2 envs"):
        pixelgym.make_vec("GridWorld-v0", 2).reset(seed=[1, 2, 3])
    env.reset(seed=2**64 - 1)
    with pytest.raises(TypeError, match="seed must be None or an int"):
        pixelgym.make_vec("GridWorld-v0", 2).reset(seed=[1, 2.5])
    with pytest.raises(ValueError, match=r"seed must be in \[0, 2\*\*64\), got -3"):
        pixelgym.make_vec("GridWorld-v0", 2).reset(seed=[1, -3])


def test_objects_used_after_close_raise():
    env = made(obs_mode="state")
    env.close()
    for call in (lambda: env.step(np.zeros(1, np.float32)), env.reset, env.render):
        with pytest.raises(pixelgym.ResetNeeded, match="after close"):
            call()
    env.close()  # closing twice is allowed, as in Gymnasium
    for mode in ("sync", "async"):
        envs = pixelgym.make_vec("CartPoleSwingup-v0", 2, mode=mode, obs_mode="state")
        envs.reset(seed=0)
        envs.close()
        with pytest.raises(pixelgym.ResetNeeded, match="after close"):
            envs.step(np.zeros((2, 1), np.float32))
        with pytest.raises(pixelgym.ResetNeeded, match="after close"):
            envs.reset()
        envs.close()
    # step_wait() after close() names the close, even with a step left pending (issue 42; it said
    # "called without a pending step_async()").
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 2, obs_mode="state")
    envs.reset(seed=0)
    envs.step_async(np.zeros((2, 1), np.float32))
    envs.close()
    with pytest.raises(pixelgym.ResetNeeded, match=r"step_wait\(\) called after close\(\)"):
        envs.step_wait()


def test_a_vector_env_stepped_from_two_python_threads_is_serialized():
    import threading

    envs = pixelgym.make_vec("CartPoleSwingup-v0", 4, num_threads=2, obs_mode="state",
                             max_episode_steps=50)
    envs.reset(seed=0)
    errors = []
    steps = [0, 0]

    def run(index):
        try:
            for _ in range(1500):
                obs, rewards, terminated, truncated, _ = envs.step(
                    np.full((4, 1), 0.5 - index, np.float32))
                assert np.all(np.isfinite(rewards)) and np.all(np.isfinite(obs["joint_pos"]))
                steps[index] += 1
        except Exception as error:  # noqa: BLE001: any error is the finding
            errors.append(repr(error))

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    envs.close()
    assert errors == []
    assert steps == [1500, 1500]


# Issue 42: hostile URDFs crashed the interpreter (a stack overflow), hung it (a FIFO) or filled
# its memory (/dev/zero). Each is made in a child interpreter, so that a crash or a hang fails the
# test rather than ending the suite; the child prints the exception it got.
_MAKE_URDF_REACH = """
import sys
import pixelgym
try:
    pixelgym.make("UrdfReach-v0", urdf=sys.argv[1]).reset(seed=0)
except Exception as error:
    print(type(error).__name__ + ": " + str(error))
    sys.exit(3)
"""


def _make_urdf_reach(path):
    import subprocess
    import sys

    try:
        result = subprocess.run(
            [sys.executable, "-c", _MAKE_URDF_REACH, str(path)],
            capture_output=True,
            text=True,
            timeout=60,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"UrdfReach-v0 with urdf={path} did not return in 60 s")
    assert result.returncode == 3, (result.returncode, result.stdout, result.stderr)
    return result.stdout


def test_hostile_urdf_files_are_runtime_errors_naming_the_file(tmp_path):
    import os

    nest = "<x>" * 50000 + "</x>" * 50000
    deep = tmp_path / "unknown_node.urdf"
    deep.write_text('<robot name="r"><link name="a"/><1 "> ' + nest + ' "></robot>')
    fifo = tmp_path / "fifo.urdf"
    os.mkfifo(fifo)
    zero = tmp_path / "zero.urdf"
    zero.symlink_to("/dev/zero")
    cases = [
        (deep, "elements nested more than 100 deep"),
        (fifo, "is a FIFO, not a regular file"),
        (zero, "is a symbolic link to /dev/zero, which is a character device, not a regular file"),
    ]
    for path, problem in cases:
        assert f"RuntimeError: URDF {path}: {problem}" in _make_urdf_reach(path)
