"""Spaces, dtypes and shapes of every registered env, as Python sees them."""

import numpy as np
import pytest
from conftest import ENV_IDS, leaves

import pixelgym


def test_ids_lists_the_registry():
    assert "CartPoleSwingup-v0" in ENV_IDS and "GridWorld-v0" in ENV_IDS
    assert ENV_IDS == sorted(ENV_IDS) and len(ENV_IDS) == len(set(ENV_IDS)) >= 11


def test_pixel_tasks_observe_uint8_pixels_and_float32_state(env_id):
    if env_id == "GridWorld-v0":
        pytest.skip("GridWorld observes a Discrete index (test below)")
    env = pixelgym.make(env_id)
    space = env.observation_space
    assert list(space.keys())[0] == "pixels"
    pixels = space["pixels"]
    assert pixels.shape == (84, 84, 3) and pixels.dtype == np.uint8
    assert np.all(pixels.low == 0) and np.all(pixels.high == 255)
    for key in list(space.keys())[1:]:
        assert space[key].dtype == np.float32, key
        assert len(space[key].shape) == 1, key
    obs, info = env.reset(seed=0)
    assert isinstance(info, dict)
    assert list(obs) == list(space.keys())
    for key, value in obs.items():
        assert isinstance(value, np.ndarray)
        assert value.dtype == space[key].dtype and value.shape == space[key].shape, key
    assert obs in space
    env.close()


def test_action_spaces_and_step_results(env_id):
    env = pixelgym.make(env_id)
    action_space = env.action_space
    if "Discrete" in env_id or env_id == "GridWorld-v0":
        assert type(action_space).__name__ == "Discrete"
        assert action_space.n in (3, 4) and action_space.start == 0
    else:
        assert type(action_space).__name__ == "Box"
        assert action_space.dtype == np.float32 and len(action_space.shape) == 1
        assert np.all(action_space.low == -1) and np.all(action_space.high == 1)
    env.reset(seed=0)
    action_space.seed(0)
    obs, reward, terminated, truncated, info = env.step(action_space.sample())
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    assert isinstance(info, dict)
    assert obs in env.observation_space
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.shape == (256, 256, 3)
    env.close()


def test_gridworld_index_observation_is_an_int64_scalar():
    env = pixelgym.make("GridWorld-v0")
    assert type(env.observation_space).__name__ == "Discrete" and env.observation_space.n == 16
    obs, _ = env.reset(seed=0)
    assert isinstance(obs, np.int64) and obs == 0
    obs, *_ = env.step(2)  # right
    assert isinstance(obs, np.int64) and obs == 1


def test_kwargs_change_the_spaces():
    env = pixelgym.make("CartPoleSwingup-v0", width=64, height=48, obs_mode="pixels")
    assert list(env.observation_space.keys()) == ["pixels"]
    assert env.observation_space["pixels"].shape == (48, 64, 3)
    obs, _ = env.reset(seed=0)
    assert obs["pixels"].shape == (48, 64, 3)
    state = pixelgym.make("CartPoleSwingup-v0", obs_mode="state")
    assert list(state.observation_space.keys()) == ["joint_pos", "joint_vel"]


def test_wrap_specs_change_the_spaces():
    env = pixelgym.make("CartPoleSwingup-v0", wrap=["resize=64x64", "grayscale", "frame_stack=3"])
    assert env.observation_space["pixels"].shape == (3, 64, 64)
    obs, _ = env.reset(seed=0)
    assert obs["pixels"].shape == (3, 64, 64) and obs["pixels"].dtype == np.uint8


def test_info_describes_without_making(env_id):
    described = pixelgym.info(env_id)
    env = pixelgym.make(env_id)
    assert repr(described["observation_space"]) == repr(pixelgym._core.Env(env_id).observation_space)
    assert described["max_episode_steps"] == env.spec.max_episode_steps > 0
    assert described["metadata"]["render_fps"] == env.metadata["render_fps"] > 0
    assert env.metadata["render_modes"] == ["rgb_array"]
    names = [kwarg["name"] for kwarg in described["kwargs"]]
    assert "render_width" in names
    assert pixelgym.info("CartPoleSwingup-v0", action_repeat=2)["max_episode_steps"] == 500


def test_space_sample_seed_and_contains():
    space = pixelgym._core.Env("ArmReach-v0").action_space
    space.seed(3)
    first = [space.sample() for _ in range(5)]
    space.seed(3)
    again = [space.sample() for _ in range(5)]
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    assert all(a.dtype == np.float32 and a.shape == (7,) and a in space for a in first)
    assert space.contains(np.zeros(7, np.float32))
    assert np.zeros(7) not in space  # float64 does not cast safely to float32
    assert [0.0] * 7 in space  # a list takes the space's dtype
    assert np.zeros(6, np.float32) not in space
    assert np.full(7, 2, np.float32) not in space
    assert "shape (6,)" in space.mismatch(np.zeros(6, np.float32))
    assert None not in space and "x" not in space


def test_dict_space_keeps_key_order_and_mismatch_names_keys():
    space = pixelgym._core.Env("ArmPush-v0").observation_space
    assert space.keys() == ["pixels", "joint_pos", "joint_vel", "end_effector_pos", "to_cube",
                            "cube_to_goal"]
    assert [leaf.shape for leaf in leaves(space.sample())][0] == (84, 84, 3)
    with pytest.raises(KeyError):
        space["nope"]
    assert space.sample() in space
    assert {"pixels": np.zeros((84, 84, 3), np.uint8)} not in space


def _samples(space, count=5):
    return [space.sample() for _ in range(count)]


def _same(a, b):
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[key], b[key]) for key in a)
    return np.array_equal(np.asarray(a), np.asarray(b))


def test_pixelgym_spaces_pickle_and_copy_with_their_generator():
    # Issue 42: without gymnasium, make returns pixelgym's own spaces, and pickling one (as
    # multiprocessing, Ray or a checkpoint of an agent does) raised TypeError. A copy equals the
    # original and, as Gymnasium's spaces do, samples what the original would.
    import copy
    import pickle

    grid = pixelgym.make_vec("GridWorld-v0", 3, mode="sync")
    spaces = [pixelgym.info("CartPoleSwingup-v0")["observation_space"],  # Dict of Boxes
              pixelgym.info("CartPoleSwingup-v0")["action_space"],  # Box, float32
              pixelgym.info("GridWorld-v0")["action_space"],  # Discrete
              grid._core.action_space,  # MultiDiscrete
              grid._core.observation_space]
    for space in spaces:
        space.seed(3)
        space.sample()  # the generator moved on from its seed: the copies carry where it is
        copies = [pickle.loads(pickle.dumps(space)),
                  pickle.loads(pickle.dumps(space, protocol=2)),
                  copy.deepcopy(space), copy.copy(space)]
        expected = _samples(space)
        for made in copies:
            assert type(made) is type(space) and made == space and made is not space, space
            assert repr(made) == repr(space)
            assert all(_same(a, b) for a, b in zip(_samples(made), expected)), space
    grid.close()
    # A space never seeded is copied unseeded; it samples elements all the same.
    fresh = pickle.loads(pickle.dumps(pixelgym.info("GridWorld-v0")["action_space"]))
    assert fresh.sample() in fresh
    # A Dict's subspaces are copied with the Dict (each with its own generator).
    obs_space = spaces[0]
    copied = copy.deepcopy(obs_space)
    assert copied["pixels"] is not obs_space["pixels"] and copied["pixels"] == obs_space["pixels"]
