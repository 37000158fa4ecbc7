"""Observations are numpy views of pixelgym's memory (no copy), kept alive by their base."""

import gc

import numpy as np

import pixelgym


def test_single_env_observations_view_pixelgym_buffers():
    env = pixelgym.make("CartPoleSwingup-v0")
    obs, _ = env.reset(seed=0)
    for key, array in obs.items():
        assert isinstance(array.base, pixelgym.Buffer), key
        assert not array.flags.owndata
        # The Buffer exposes the same memory through the buffer protocol: no copy was made.
        view = np.asarray(array.base)
        assert np.shares_memory(view, array) and view.shape == array.shape
        assert array.base.dtype == array.dtype.name and array.base.shape == array.shape


def test_a_single_env_step_does_not_overwrite_earlier_observations():
    env = pixelgym.make("CartPoleSwingup-v0")
    first, _ = env.reset(seed=0)
    kept = {key: value.copy() for key, value in first.items()}
    second, *_ = env.step(np.ones(1, np.float32))
    assert not np.shares_memory(first["pixels"], second["pixels"])
    assert all(np.array_equal(first[key], kept[key]) for key in kept)


def test_vector_observations_are_one_buffer_overwritten_by_each_step():
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 2, num_threads=2)
    obs, _ = envs.reset(seed=0)
    assert isinstance(obs["pixels"].base, pixelgym.Buffer)
    kept = obs["pixels"].copy()
    after, *_ = envs.step(np.ones((2, 1), np.float32))
    # The same memory: the step wrote into the arrays the reset returned.
    assert np.shares_memory(obs["pixels"], after["pixels"])
    assert np.array_equal(obs["pixels"], after["pixels"])
    assert not np.array_equal(kept, after["pixels"])  # the copy kept the reset's frame
    assert not np.shares_memory(kept, after["pixels"])


def test_copy_true_returns_copies():
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 2, copy=True)
    obs, _ = envs.reset(seed=0)
    after, *_ = envs.step(np.ones((2, 1), np.float32))
    assert not np.shares_memory(obs["pixels"], after["pixels"])
    assert obs["pixels"].base is None or not isinstance(obs["pixels"].base, pixelgym.Buffer)


def test_the_base_keeps_the_memory_alive_after_the_env_is_gone():
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 2)
    obs, _ = envs.reset(seed=0)
    pixels = obs["pixels"]
    expected = pixels.copy()
    envs.close()
    del envs, obs
    gc.collect()
    # Allocate and touch memory that would reuse a freed block.
    junk = [np.full(pixels.shape, 7, np.uint8) for _ in range(64)]
    assert np.array_equal(pixels, expected)
    del junk
    env = pixelgym.make("GridWorld-v0", obs_mode="pixels")
    frame, _ = env.reset(seed=0)
    pixels = frame["pixels"]
    expected = pixels.copy()
    del env, frame
    gc.collect()
    assert np.array_equal(pixels, expected)
