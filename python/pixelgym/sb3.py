"""Stable-Baselines3's VecEnv over pixelgym's C++ vector env (needs stable_baselines3 and
gymnasium).

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor
    from pixelgym.sb3 import make_sb3_vec

    venv = VecMonitor(make_sb3_vec("CartPoleBalance-v1", num_envs=8, num_threads=2))
    PPO("MultiInputPolicy", venv).learn(10_000)

    # The image alone, a uint8 (84, 84, 3) Box, for SB3's CnnPolicy:
    venv = VecMonitor(make_sb3_vec("CartPoleBalance-v1", num_envs=8, obs_mode="rgb"))
    PPO("CnnPolicy", venv).learn(10_000)

SB3 does not take a gymnasium.vector.VectorEnv; its own VecEnv protocol resets an ended env in
the same step and hands the episode's last observation over in ``infos[i]["terminal_observation"]``.
``SB3VecEnv`` speaks that protocol over a pixelgym VectorEnv made with
``autoreset_mode="SameStep"``, stepping all envs in C++ (``step_async`` starts the thread pool
and returns). Observations are copied out of the vector env's buffers (SB3 keeps the last
observation across a step, as its DummyVecEnv does). ``render()`` tiles the envs' frames
(``get_images``) as SB3's VecEnvs do, so ``VecVideoRecorder`` records it.
"""

import numpy as np

from ._vector import VectorEnv

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv as _VecEnv
except ImportError as error:  # pragma: no cover - depends on the machine
    raise ImportError(
        "pixelgym.sb3 needs stable_baselines3 (pip install stable-baselines3) and gymnasium"
    ) from error


def _copy(obs):
    if isinstance(obs, dict):
        return {key: value.copy() for key, value in obs.items()}
    return obs.copy()


class SB3VecEnv(_VecEnv):
    """SB3's VecEnv protocol over ``venv``, a pixelgym VectorEnv with SameStep autoreset."""

    def __init__(self, venv):
        if not isinstance(venv, VectorEnv):
            raise TypeError(f"SB3VecEnv: expected a pixelgym.VectorEnv, got {type(venv).__name__}")
        if venv.autoreset_mode != "SameStep":
            raise ValueError(
                "SB3VecEnv: SB3 resets an ended env in the same step; make the vector env with "
                f'autoreset_mode="SameStep", got "{venv.autoreset_mode}"'
            )
        self.venv = venv
        self._pending = None
        super().__init__(venv.num_envs, venv.single_observation_space, venv.single_action_space)
        # SB3's VecEnv sets metadata to its render modes alone; VecVideoRecorder plays frames at
        # metadata["render_fps"] (30 when absent): the envs' own rate.
        self.metadata["render_fps"] = venv.metadata["render_fps"]

    def reset(self):
        seeds = self._seeds
        seed = None
        if all(s is not None for s in seeds):
            # SB3's seed(s) gives env i the seed s + i, as pixelgym's reset(seed=s) does.
            if all(s == seeds[0] + i for i, s in enumerate(seeds)):
                seed = seeds[0]
            else:
                seed = list(seeds)
        elif any(s is not None for s in seeds):
            seed = list(seeds)
        if any(options != self._options[0] for options in self._options):
            raise ValueError("SB3VecEnv: the C++ vector env resets every env with the same options; "
                             f"got different ones per env: {self._options}")
        options = self._options[0]
        obs, infos = self.venv.reset(seed=seed, options=options or None)
        self.reset_infos = [self._env_info(infos, i) for i in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return _copy(obs)

    def step_async(self, actions):
        if self.venv._core.is_async:
            self.venv.step_async(actions)
            self._pending = None
        else:
            self._pending = actions

    def step_wait(self):
        if self._pending is None:
            obs, rewards, terminated, truncated, infos = self.venv.step_wait()
        else:
            obs, rewards, terminated, truncated, infos = self.venv.step(self._pending)
            self._pending = None
        dones = terminated | truncated
        env_infos = []
        final_obs = infos.get("final_obs")
        for i in range(self.num_envs):
            info = self._env_info(infos.get("final_info", {}), i) if dones[i] else \
                self._env_info(infos, i)
            if dones[i]:
                info["terminal_observation"] = final_obs[i]
                info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            env_infos.append(info)
        return _copy(obs), rewards.astype(np.float32), dones, env_infos

    @staticmethod
    def _env_info(infos, i):
        """Env i's entries of batched infos (those whose "_key" mask is set for it)."""
        out = {}
        for key, value in infos.items():
            if key.startswith("_") or key in ("final_obs", "final_info"):
                continue
            mask = infos.get("_" + key)
            if mask is not None and not mask[i]:
                continue
            out[key] = SB3VecEnv._env_info(value, i) if isinstance(value, dict) else value[i]
        return out

    def close(self):
        self.venv.close()

    def get_attr(self, attr_name, indices=None):
        """The vector env's attribute (render_mode, metadata, ...) once per env: the C++ envs
        share their settings."""
        return [getattr(self.venv, attr_name)] * len(self._indices(indices))

    def set_attr(self, attr_name, value, indices=None):
        raise AttributeError(
            f"SB3VecEnv: the C++ envs have no Python attributes to set; got {attr_name!r}")

    def env_method(self, method_name, *method_args, indices=None, **method_kwargs):
        """Calls a method on each env of ``indices`` and returns the results, as SB3's
        DummyVecEnv does. The C++ envs offer ``render`` (each env's (H, W, 3) uint8 frame) and
        ``get_wrapper_attr(name)`` (as get_attr); stepping or resetting one env of the batch
        alone is not possible."""
        indices = self._indices(indices)
        if method_name == "render" and not method_args and not method_kwargs:
            frames = self._frames()
            return [frames[i] for i in indices]
        if method_name == "get_wrapper_attr":
            return self.get_attr(*method_args, indices=indices, **method_kwargs)
        raise AttributeError(
            f"SB3VecEnv: env_method({method_name!r}): the C++ envs offer 'render' and "
            "'get_wrapper_attr' (step and reset go through the VecEnv as a whole)")

    def env_is_wrapped(self, wrapper_class, indices=None):
        return [False] * len(self._indices(indices))

    def get_images(self):
        """Each env's current frame, (H, W, 3) uint8; SB3's VecEnv.render() tiles them into one
        image (render_mode "rgb_array")."""
        return list(self._frames())

    def _frames(self):
        if self.venv.render_mode != "rgb_array":
            raise ValueError(
                f"SB3VecEnv: the envs render with render_mode='rgb_array', got "
                f"{self.venv.render_mode!r}")
        return self.venv.render()

    def _indices(self, indices):
        if indices is None:
            return range(self.num_envs)
        if isinstance(indices, int):
            return [indices]
        return list(indices)


def make_sb3_vec(id, num_envs=8, **make_vec_kwargs):
    """An SB3VecEnv over ``pixelgym.make_vec(id, num_envs, autoreset_mode="SameStep",
    **make_vec_kwargs)`` (num_threads, wrap, env kwargs...)."""
    return SB3VecEnv(VectorEnv(id, num_envs, autoreset_mode="SameStep", **make_vec_kwargs))


__all__ = ["SB3VecEnv", "make_sb3_vec"]
