"""One env from Python: seeding, byte-identical determinism, time limits, rendering, copies."""

import copy
import importlib.util
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest
from conftest import same

import pixelgym


def rollout(env, seed, steps, action_seed=1):
    """Observations, rewards and flags of `steps` steps from reset(seed), with seeded actions,
    resetting (unseeded) when an episode ends; observations copied."""
    obs, _ = env.reset(seed=seed)
    env.action_space.seed(action_seed)
    trajectory = [copy.deepcopy(obs)]
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        trajectory.append((copy.deepcopy(obs), reward, terminated, truncated))
        if terminated or truncated:
            obs, _ = env.reset()
            trajectory.append(copy.deepcopy(obs))
    return trajectory


def trajectories_equal(a, b):
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        if isinstance(x, tuple):
            if not (same(x[0], y[0]) and x[1:] == y[1:]):
                return False
        elif not same(x, y):
            return False
    return True


def test_same_seed_gives_byte_identical_trajectories(env_id):
    kwargs = {"max_episode_steps": 40}
    a = rollout(pixelgym.make(env_id, **kwargs), seed=7, steps=100)
    b = rollout(pixelgym.make(env_id, **kwargs), seed=7, steps=100)
    assert trajectories_equal(a, b)
    if env_id == "GridWorld-v0":
        return  # GridWorld has no randomness: its start and moves are fixed
    c = rollout(pixelgym.make(env_id, **kwargs), seed=8, steps=100)
    assert not same(a[0], c[0]), "seeds 7 and 8 start alike"
    assert not trajectories_equal(a, c)


def test_reset_options_set_the_visual_variation_from_that_reset_on():
    env = pixelgym.make("CartPoleSwingup-v1", width=48, height=48)
    varied = pixelgym.make("CartPoleSwingup-v1", width=48, height=48, variation=0.3)
    plain = pixelgym.make("CartPoleSwingup-v1", width=48, height=48)
    obs, _ = env.reset(seed=3, options={"variation": 0.3})
    assert same(obs, varied.reset(seed=3)[0])
    assert not same(obs, plain.reset(seed=3)[0])
    assert same(env.reset(seed=4)[0], varied.reset(seed=4)[0])
    with pytest.raises(ValueError, match=r"variation must be in \[0, 1\], got 2"):
        env.reset(seed=1, options={"variation": 2.0})
    with pytest.raises(ValueError, match='unknown kwarg "colour"'):
        env.reset(seed=1, options={"colour": 0.1})
    assert same(env.reset(seed=5, options={"variation": 0})[0], plain.reset(seed=5)[0])


def test_reset_with_the_same_seed_repeats_and_unseeded_reset_continues():
    env = pixelgym.make("PendulumSwingup-v0", obs_mode="state")
    first, _ = env.reset(seed=3)
    second, _ = env.reset()
    assert not same(first, second)
    again, _ = env.reset(seed=3)
    assert same(first, again)
    assert same(second, env.reset()[0])


def test_np_random_is_seeded_with_the_env_and_seeds_a_first_unseeded_reset():
    env = pixelgym.make("PendulumSwingup-v0", obs_mode="state")
    env.reset(seed=11)
    draws = env.np_random.integers(0, 2**32, 4)
    env.reset(seed=11)
    assert np.array_equal(env.np_random.integers(0, 2**32, 4), draws)
    assert np.array_equal(np.random.default_rng(11).integers(0, 2**32, 4), draws)
    # A first reset without a seed takes the C++ seed from np_random.
    a, b = (pixelgym.make("PendulumSwingup-v0", obs_mode="state") for _ in range(2))
    a.np_random = np.random.default_rng(5)
    b.np_random = np.random.default_rng(5)
    assert same(a.reset()[0], b.reset()[0])


def test_episodes_truncate_at_spec_max_episode_steps():
    env = pixelgym.make("CartPoleSwingup-v0", obs_mode="state", max_episode_steps=5)
    assert env.spec.max_episode_steps == 5 and env.spec.id == "pixelgym/CartPoleSwingup-v0"
    env.reset(seed=0)
    flags = [env.step(np.zeros(1, np.float32))[3] for _ in range(5)]
    assert flags == [False] * 4 + [True]
    with pytest.raises(pixelgym.ResetNeeded):
        env.step(np.zeros(1, np.float32))
    assert pixelgym.make("CartPoleSwingup-v0", action_repeat=4).spec.max_episode_steps == 250
    assert pixelgym.make("CartPoleSwingup-v0", max_episode_steps=0).spec.max_episode_steps is None


def test_render_is_an_rgb_frame_of_the_requested_size():
    env = pixelgym.make("CartPoleSwingup-v0", render_width=96, render_height=64)
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (64, 96, 3) and frame.dtype == np.uint8
    assert frame.std() > 0
    assert pixelgym.make("CartPoleSwingup-v0", render_mode=None).render() is None


def test_close_twice_is_allowed_and_calls_after_close_raise():
    env = pixelgym.make("GridWorld-v0")
    env.reset(seed=0)
    env.close()
    env.close()
    assert env.closed
    with pytest.raises(pixelgym.ResetNeeded):
        env.reset()


def test_deepcopy_and_pickle_make_a_new_env_from_the_same_spec():
    env = pixelgym.make("CartPoleSwingup-v0", width=32, height=32, wrap=["grayscale"])
    first, _ = env.reset(seed=4)
    for made in (copy.deepcopy(env), pickle.loads(pickle.dumps(env))):
        assert made is not env and made.spec.kwargs == env.spec.kwargs
        assert made.observation_space["pixels"].shape == (32, 32)
        with pytest.raises(pixelgym.ResetNeeded):  # a new env: the episode is not copied
            made.step(np.zeros(1, np.float32))
        assert same(made.reset(seed=4)[0], first)


def test_the_core_objects_refuse_pickling_with_a_type_error():
    with pytest.raises(TypeError):
        pickle.dumps(pixelgym._core.Env("GridWorld-v0"))


def test_the_registered_entry_points_make_envs_from_the_spec_kwargs():
    env = pixelgym.make("GridWorld-v0", max_episode_steps=7, obs_mode="pixels", width=16, height=16)
    assert env.spec.kwargs["pixelgym_id"] == "GridWorld-v0"
    module, name = env.spec.entry_point.split(":")
    made = getattr(importlib.import_module(module), name)(**env.spec.kwargs)
    assert made.spec.max_episode_steps == 7 and made.observation_space["pixels"].shape == (16, 16, 3)
    module, name = env.spec.vector_entry_point.split(":")
    envs = getattr(importlib.import_module(module), name)(num_envs=2, **env.spec.kwargs)
    assert envs.num_envs == 2 and envs.max_episode_steps == 7


def test_without_gymnasium_one_warning_says_how_to_get_it():
    script = ("import pixelgym; mro = type(pixelgym.make('GridWorld-v0')).__mro__; "
              "print(pixelgym.HAVE_GYMNASIUM, [c.__name__ for c in mro])")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=dict(os.environ, PIXELGYM_NO_GYMNASIUM="1"), check=True)
    assert out.stdout.strip() == "False ['Env', 'CoreBacked', 'NumpyRandom', 'object']"
    assert out.stderr.count("GymnasiumMissingWarning") == 1
    assert "pip install gymnasium" in out.stderr


def test_obs_mode_rgb_is_the_image_box_that_obs_mode_pixels_holds_under_its_key():
    rgb = pixelgym.make("CartPoleSwingup-v1", obs_mode="rgb", width=64)
    pixels = pixelgym.make("CartPoleSwingup-v1", obs_mode="pixels", width=64)
    space = rgb.observation_space
    assert space.shape == (84, 64, 3) and space.dtype == np.uint8
    assert not isinstance(space, dict) and not hasattr(space, "spaces")
    assert space == pixels.observation_space["pixels"]
    a, b = rollout(rgb, 3, 12), rollout(pixels, 3, 12)
    assert len(a) == len(b)
    for x, y in zip(a, b):
        x, y = (x[0], y[0]) if isinstance(x, tuple) else (x, y)
        assert isinstance(x, np.ndarray) and same(x, y["pixels"])
    assert trajectories_equal(a, rollout(pixelgym.make("CartPoleSwingup-v1", obs_mode="rgb",
                                                       width=64), 3, 12))


def test_pixelgym_wrappers_take_the_rgb_image_box():
    env = pixelgym.make("CartPoleSwingup-v1", obs_mode="rgb",
                        wrap=["resize=48x40", "grayscale", "frame_stack=3"])
    assert env.observation_space.shape == (3, 48, 40)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 48, 40) and obs.dtype == np.uint8 and obs in env.observation_space


def test_gymnasiums_own_image_wrappers_take_the_rgb_image_box():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.error import DependencyNotInstalled
    from gymnasium.wrappers import FrameStackObservation, GrayscaleObservation, ResizeObservation

    rgb = pixelgym.make("CartPoleSwingup-v1", obs_mode="rgb")
    # ResizeObservation asserts that the observation is a uint8 [0, 255] image Box, then needs
    # OpenCV's Python module (cv2): the Dict of obs_mode "pixels" fails its assertions.
    with pytest.raises(AssertionError):
        ResizeObservation(pixelgym.make("CartPoleSwingup-v1", obs_mode="pixels"), (64, 48))
    if importlib.util.find_spec("cv2") is None:
        with pytest.raises(DependencyNotInstalled, match="cv2"):
            ResizeObservation(rgb, (64, 48))
        env = rgb
        shape = (84, 84)
    else:
        env = ResizeObservation(rgb, (64, 48))
        shape = (64, 48)
        assert env.observation_space.shape == (64, 48, 3)
        obs, _ = env.reset(seed=0)
        assert obs.shape == (64, 48, 3) and obs.dtype == np.uint8 and obs in env.observation_space
    env = FrameStackObservation(GrayscaleObservation(env), 4)
    env.reset(seed=0)
    obs, *_ = env.step(env.action_space.sample())
    assert obs.shape == (4, *shape) and obs in env.observation_space
    from gymnasium.utils.env_checker import check_env

    check_env(gymnasium.make("pixelgym/CartPoleSwingup-v1", obs_mode="rgb").unwrapped,
              skip_render_check=True)


def test_render_mode_human_is_refused_naming_the_modes_offered():
    for make in (pixelgym.make, lambda *a, **k: pixelgym.make_vec(*a, 2, **k)):
        with pytest.raises(ValueError, match=r"render_mode must be 'rgb_array' \(the default\) "
                                             r"or None, got 'human': pixelgym renders off-screen"):
            make("CartPoleSwingup-v1", render_mode="human")
