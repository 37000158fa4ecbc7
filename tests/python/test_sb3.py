"""pixelgym.sb3 against Stable-Baselines3 itself: CnnPolicy on the image Box (obs_mode="rgb"), and
the VecEnv calls that SB3's render() and VecVideoRecorder make. Skipped where stable_baselines3 is
not importable (CI has neither it nor gymnasium; run by hand with Gymnasium 1.0.0 and SB3 2.4.1)."""

import importlib.util
import sys
import types
import warnings

import numpy as np
import pytest

HAVE_SB3 = all(importlib.util.find_spec(name) is not None
               for name in ("stable_baselines3", "gymnasium"))
# Skipped test by test (a module skipped whole makes pytest exit 5, "no tests ran").
pytestmark = pytest.mark.skipif(not HAVE_SB3, reason="needs stable_baselines3 and gymnasium")

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import pixelgym

    if HAVE_SB3:
        from pixelgym.sb3 import make_sb3_vec
        from stable_baselines3 import PPO
        from stable_baselines3.common.vec_env import VecVideoRecorder
        from stable_baselines3.common.vec_env.base_vec_env import tile_images

ID = "CartPoleBalance-v1"


def test_cnn_policy_trains_on_the_rgb_image_box():
    venv = make_sb3_vec(ID, num_envs=2, num_threads=1, obs_mode="rgb")
    assert venv.observation_space.shape == (84, 84, 3)
    assert venv.observation_space.dtype == np.uint8
    model = PPO("CnnPolicy", venv, n_steps=32, batch_size=32, n_epochs=1, seed=0)
    before = [p.detach().clone() for p in model.policy.parameters()]
    model.learn(total_timesteps=64)
    assert model.num_timesteps >= 64
    assert any(not np.array_equal(a.numpy(), b.detach().numpy())
               for a, b in zip(before, model.policy.parameters())), "no parameter changed"
    venv.close()


def test_cnn_policy_takes_a_single_rgb_env_and_refuses_the_pixels_dict():
    env = pixelgym.make(ID, obs_mode="rgb")
    PPO("CnnPolicy", env, n_steps=16, batch_size=16, n_epochs=1, seed=0).learn(16)
    env.close()
    with pytest.raises(ValueError, match="MultiInputPolicy"):
        PPO("CnnPolicy", pixelgym.make(ID, obs_mode="pixels"))


def vec(num_envs=3):
    venv = make_sb3_vec(ID, num_envs=num_envs, num_threads=1, render_width=40, render_height=24)
    venv.seed(5)
    venv.reset()
    return venv


def test_get_images_are_each_envs_frame_and_render_tiles_them():
    venv = vec()
    frames = venv.get_images()
    assert len(frames) == 3
    for i, frame in enumerate(frames):
        assert frame.shape == (24, 40, 3) and frame.dtype == np.uint8
        one = pixelgym.make(ID, render_width=40, render_height=24)
        one.reset(seed=5 + i)  # SB3's seed(s) gives env i the seed s + i
        assert np.array_equal(frame, one.render()), f"env {i}"
    assert not np.array_equal(frames[0], frames[1])
    tiled = venv.render()
    assert tiled.shape == (48, 80, 3)  # 3 frames on a 2 x 2 grid
    assert np.array_equal(tiled, tile_images(frames))
    assert np.array_equal(venv.render(mode="rgb_array"), tiled)
    venv.close()


def test_env_method_render_and_get_wrapper_attr():
    venv = vec()
    frames = venv.get_images()
    rendered = venv.env_method("render", indices=[2, 0])
    assert len(rendered) == 2
    assert np.array_equal(rendered[0], frames[2]) and np.array_equal(rendered[1], frames[0])
    assert venv.env_method("get_wrapper_attr", "render_mode") == ["rgb_array"] * 3
    assert venv.get_attr("render_mode", indices=1) == ["rgb_array"]
    with pytest.raises(AttributeError, match="'render' and 'get_wrapper_attr'"):
        venv.env_method("step", np.zeros(1))
    venv.close()


class _StandInClip:
    """moviepy's ImageSequenceClip where moviepy is not installed: keeps what it was given."""

    clips = []

    def __init__(self, frames, fps):
        self.frames = [np.array(frame) for frame in frames]
        self.fps = fps
        _StandInClip.clips.append(self)

    def write_videofile(self, path):
        with open(path, "wb") as file:
            file.write(b"stand-in")


@pytest.fixture
def moviepy_or_stand_in(monkeypatch):
    if importlib.util.find_spec("moviepy") is not None:
        return False
    _StandInClip.clips = []
    for name in ("moviepy", "moviepy.video", "moviepy.video.io",
                 "moviepy.video.io.ImageSequenceClip"):
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))
    sys.modules["moviepy.video.io.ImageSequenceClip"].ImageSequenceClip = _StandInClip
    return True


def test_vec_video_recorder_records_the_tiled_frames(tmp_path, moviepy_or_stand_in):
    inner = vec(num_envs=2)
    venv = VecVideoRecorder(inner, str(tmp_path), record_video_trigger=lambda step: step == 0,
                            video_length=4)
    assert venv.frames_per_sec == inner.venv.metadata["render_fps"]
    venv.reset()
    for _ in range(4):
        venv.step(np.zeros((2, 1), dtype=np.float32))
    videos = list(tmp_path.glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 0
    if moviepy_or_stand_in:
        (clip,) = _StandInClip.clips
        assert len(clip.frames) == 5  # the reset frame and one per step
        assert all(frame.shape == (48, 40, 3) for frame in clip.frames)  # 2 frames, one above the other
        assert not np.array_equal(clip.frames[0], clip.frames[-1])
        assert clip.fps == inner.venv.metadata["render_fps"]
    venv.close()
