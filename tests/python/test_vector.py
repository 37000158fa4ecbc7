"""The C++ vector env from Python: seeding, autoreset modes, threads, wrappers."""

import numpy as np
import pytest
from conftest import same

import pixelgym

LIMIT = 6  # episodes of 6 steps, so that autoresets happen within a few steps


def row(obs, i):
    return {key: value[i].copy() for key, value in obs.items()}


def single_envs(env_id, n, seed, **kwargs):
    """n single envs, env i reset with seed + i: what vector env i must match."""
    envs = [pixelgym.make(env_id, max_episode_steps=LIMIT, **kwargs) for _ in range(n)]
    first = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    return envs, first


@pytest.mark.parametrize("mode,threads", [("async", 2), ("async", 1), ("sync", 0),
                                          ("process", 2)])
def test_next_step_autoreset_matches_single_envs_byte_for_byte(mode, threads):
    n = 3
    envs = pixelgym.make_vec("CartPoleSwingup-v0", n, mode=mode, num_threads=threads,
                             num_workers=threads, max_episode_steps=LIMIT, width=32, height=32)
    assert envs.num_workers == (threads if mode == "process" else 0)
    assert envs.autoreset_mode == "NextStep"
    assert str(envs.metadata["autoreset_mode"]).endswith(("NextStep", "NEXT_STEP"))
    singles, first = single_envs("CartPoleSwingup-v0", n, 10, width=32, height=32)
    obs, infos = envs.reset(seed=10)
    assert all(same(row(obs, i), first[i]) for i in range(n))
    rng = np.random.default_rng(0)
    ended = np.zeros(n, bool)
    for step in range(2 * LIMIT + 2):
        actions = rng.uniform(-1, 1, (n, 1)).astype(np.float32)
        obs, rewards, terminated, truncated, infos = envs.step(actions)
        for i, env in enumerate(singles):
            if ended[i]:
                # The step after an episode ended: env i is reset (unseeded), its action ignored.
                expected, _ = env.reset()
                assert rewards[i] == 0.0 and not terminated[i] and not truncated[i]
            else:
                expected, reward, term, trunc, _ = env.step(actions[i])
                assert (rewards[i], terminated[i], truncated[i]) == (reward, term, trunc)
            assert same(row(obs, i), expected), f"env {i} at step {step}"
        ended = terminated | truncated
        assert ended.any() == (step % (LIMIT + 1) == LIMIT - 1)
    envs.close()


def test_sync_async_and_process_give_identical_results():
    results = []
    for mode in ("sync", "async", "process"):
        envs = pixelgym.make_vec("ReacherEasy-v0", 4, mode=mode, num_threads=2, num_workers=3,
                                 max_episode_steps=LIMIT)
        obs, _ = envs.reset(seed=1)
        trace = [row(obs, i) for i in range(4)]
        rng = np.random.default_rng(2)
        for _ in range(15):
            obs, rewards, term, trunc, _ = envs.step(rng.uniform(-1, 1, (4, 2)).astype(np.float32))
            trace += [row(obs, i) for i in range(4)] + [rewards.copy(), term | trunc]
        results.append(trace)
        envs.close()
    for other in results[1:]:
        assert all(same(a, b) for a, b in zip(results[0], other))


def test_same_step_autoreset_reports_the_final_observation():
    n = 2
    envs = pixelgym.make_vec("PendulumSwingup-v0", n, autoreset_mode="SameStep",
                             max_episode_steps=LIMIT, obs_mode="state")
    singles, _ = single_envs("PendulumSwingup-v0", n, 0, obs_mode="state")
    envs.reset(seed=0)
    actions = np.full((n, 1), 0.5, np.float32)
    for step in range(LIMIT):
        obs, rewards, terminated, truncated, infos = envs.step(actions)
        last = [env.step(actions[i]) for i, env in enumerate(singles)]
        if step < LIMIT - 1:
            assert "final_obs" not in infos
            continue
        assert truncated.all() and infos["_final_obs"].all()
        for i, env in enumerate(singles):
            assert same(infos["final_obs"][i], last[i][0])  # the episode's last observation
            assert rewards[i] == last[i][1]
            assert same(row(obs, i), env.reset()[0])  # and already the next episode's first


def test_disabled_autoreset_needs_a_masked_reset():
    envs = pixelgym.make_vec("GridWorld-v0", 2, autoreset_mode="Disabled", max_episode_steps=2)
    envs.reset(seed=0)
    envs.step(np.array([2, 2]))
    obs, _, _, truncated, _ = envs.step(np.array([2, 2]))
    assert truncated.all() and list(obs) == [2, 2]  # right twice
    with pytest.raises(pixelgym.ResetNeeded):
        envs.step(np.array([0, 0]))
    obs, _ = envs.reset(options={"reset_mask": np.array([True, False])})
    assert list(obs) == [0, 2]  # only env 0 was reset
    with pytest.raises(pixelgym.ResetNeeded):
        envs.step(np.array([0, 0]))  # env 1 still ended
    obs, _ = envs.reset(options={"reset_mask": np.array([False, True])})
    assert list(obs) == [0, 0]
    envs.step(np.array([2, 2]))


def test_reset_seeds_env_i_with_seed_plus_i_or_a_list():
    envs = pixelgym.make_vec("CartPoleBalance-v0", 3, obs_mode="state")
    obs, _ = envs.reset(seed=20)
    obs = {key: value.copy() for key, value in obs.items()}  # the next reset overwrites the batch
    for i in range(3):
        single, _ = pixelgym.make("CartPoleBalance-v0", obs_mode="state").reset(seed=20 + i)
        assert same(row(obs, i), single)
    listed, _ = envs.reset(seed=[22, 20, 21])
    assert same(row(listed, 0), row(obs, 2)) and same(row(listed, 1), row(obs, 0))
    assert same(row(listed, 2), row(obs, 1))


def test_wrappers_threads_and_spaces():
    envs = pixelgym.make_vec("CartPoleSwingup-v0", 4, num_threads=2,
                             wrap=["resize=64x64", "grayscale", "frame_stack=3"])
    assert envs.num_envs == 4 and envs.num_threads == 2
    assert envs.single_observation_space["pixels"].shape == (3, 64, 64)
    assert envs.observation_space["pixels"].shape == (4, 3, 64, 64)
    assert envs.action_space.shape == (4, 1)
    obs, _ = envs.reset(seed=0)
    assert obs["pixels"].shape == (4, 3, 64, 64) and obs["pixels"].dtype == np.uint8
    assert obs in envs.observation_space
    obs, rewards, terminated, truncated, _ = envs.step(envs.action_space.sample())
    assert rewards.dtype == np.float64 and terminated.dtype == bool and rewards.shape == (4,)
    assert pixelgym.make_vec("GridWorld-v0", 3, mode="sync").num_threads == 1


def test_step_async_then_step_wait_equals_step():
    a = pixelgym.make_vec("AcrobotSwingup-v0", 2, num_threads=2, obs_mode="state")
    b = pixelgym.make_vec("AcrobotSwingup-v0", 2, num_threads=2, obs_mode="state")
    a.reset(seed=3)
    b.reset(seed=3)
    actions = np.array([[0.5], [-0.5]], np.float32)
    a.step_async(actions)
    actions[:] = 0  # the actions were copied
    waited = a.step_wait()
    stepped = b.step(np.array([[0.5], [-0.5]], np.float32))
    assert same(waited[0], stepped[0]) and same(waited[1], stepped[1])


def test_copies_make_a_new_vector_env():
    import copy
    import pickle

    envs = pixelgym.make_vec("GridWorld-v0", 2, autoreset_mode="SameStep")
    for made in (copy.deepcopy(envs), pickle.loads(pickle.dumps(envs))):
        assert made.num_envs == 2 and made.autoreset_mode == "SameStep"
        assert list(made.reset(seed=0)[0]) == [0, 0]


def test_obs_mode_rgb_batches_the_image_box():
    envs = pixelgym.make_vec("CartPoleSwingup-v1", 3, num_threads=2, obs_mode="rgb",
                             wrap=["resize=64x64"])
    assert envs.single_observation_space.shape == (64, 64, 3)
    assert envs.observation_space.shape == (3, 64, 64, 3)
    obs, _ = envs.reset(seed=4)
    assert isinstance(obs, np.ndarray) and obs.shape == (3, 64, 64, 3) and obs.dtype == np.uint8
    one = pixelgym.make("CartPoleSwingup-v1", obs_mode="rgb", wrap=["resize=64x64"])
    assert same(obs[2], one.reset(seed=6)[0])
    obs, *_ = envs.step(envs.action_space.sample())
    assert obs.shape == (3, 64, 64, 3) and obs in envs.observation_space


def test_render_gives_each_envs_frame():
    envs = pixelgym.make_vec("CartPoleSwingup-v1", 3, num_threads=2, render_width=32,
                             render_height=24)
    with pytest.raises(pixelgym.ResetNeeded):
        envs.render()
    envs.reset(seed=7)
    frames = envs.render()
    assert isinstance(frames, tuple) and len(frames) == 3
    for i, frame in enumerate(frames):
        one = pixelgym.make("CartPoleSwingup-v1", render_width=32, render_height=24)
        one.reset(seed=7 + i)
        assert same(frame, one.render()), f"env {i}"
    assert pixelgym.make_vec("GridWorld-v0", 2, render_mode=None).render() is None
    envs.close()
    with pytest.raises(pixelgym.ResetNeeded):
        envs.render()
