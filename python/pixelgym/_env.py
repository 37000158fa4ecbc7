"""pixelgym.Env: one C++ env behind Gymnasium's Env API (a gymnasium.Env when gymnasium is
importable)."""

import dataclasses
import types


from . import _core
from . import _gymnasium as gymnasium
from ._core_backed import CoreBacked, wrap_list
from ._random import NumpyRandom, seed_np_random
from ._spaces import to_gymnasium

_RENDER_MODES = (None, "rgb_array")

#: What gymnasium's registry calls to make pixelgym/<ID> (see make_registered).
ENTRY_POINT = "pixelgym._env:make_registered"

if gymnasium is not None:
    _Base = gymnasium.Env
else:
    _Base = NumpyRandom


def _gymnasium_spec(env_id, kwargs, max_episode_steps):
    """The env's spec: a gymnasium EnvSpec that gymnasium.make can make again, or a plain
    namespace with the same fields."""
    fields = dict(
        id="pixelgym/" + env_id,
        entry_point=ENTRY_POINT,
        kwargs=kwargs,
        max_episode_steps=max_episode_steps,
        vector_entry_point="pixelgym._vector:make_vec_registered",  # _vector.VECTOR_ENTRY_POINT
    )
    if gymnasium is not None:
        return gymnasium.envs.registration.EnvSpec(**fields)
    return types.SimpleNamespace(**fields)


class Env(CoreBacked, _Base):
    """One pixelgym env (made in C++ from the registry), with Gymnasium's API.

    ``reset(seed=None, options=None) -> (obs, info)``; ``step(action) -> (obs, reward,
    terminated, truncated, info)``; ``render()`` -> an (H, W, 3) uint8 frame; ``close()``. The
    C++ env truncates its episodes itself at ``spec.max_episode_steps`` (pixelgym's TimeLimit).

    Seeding: ``reset(seed=s)`` seeds the C++ env's generator with s and ``np_random`` (a numpy
    Generator, for the caller's own randomness) as Gymnasium does. The dynamics draw from the C++
    generator; a first ``reset()`` without a seed seeds it from ``np_random``, so setting
    ``env.np_random`` before it makes the run reproducible.

    Observations are numpy arrays viewing memory pixelgym allocated for this step (zero copy;
    their ``base`` is a ``pixelgym.Buffer``); a later step does not change them. Actions are
    checked against the action space in C++: a wrong shape, NaN or out-of-range value raises
    ValueError with pixelgym's message; a float64 action for a float32 Box is cast (numpy's
    "same_kind"). Calls out of order raise ``pixelgym.ResetNeeded``.

    Copies (``copy.deepcopy``, ``pickle``) make a new env from the same id, kwargs and wrappers;
    the episode in progress is not copied (the copy needs ``reset``).
    """

    def __init__(self, id, render_mode="rgb_array", wrap=(), **kwargs):
        if render_mode not in _RENDER_MODES:
            raise ValueError(
                f"{id}: render_mode must be 'rgb_array' (the default) or None, got "
                f"{render_mode!r}: pixelgym renders off-screen (headless, no window) and render() "
                "returns (H, W, 3) uint8 frames; to watch episodes, record a video "
                "(gymnasium.wrappers.RecordVideo, `pixelgym record`)"
            )
        wrap = wrap_list(wrap)
        self._core = _core.Env(id, kwargs, wrap)
        self._id = id
        self._wrap = tuple(wrap)
        self._kwargs = dict(kwargs)
        self.render_mode = render_mode
        metadata = self._core.metadata
        self.metadata = {
            "render_modes": list(metadata["render_modes"]),
            "render_fps": metadata["render_fps"],
        }
        self.observation_space = to_gymnasium(self._core.observation_space, gymnasium)
        self.action_space = to_gymnasium(self._core.action_space, gymnasium)
        spec_kwargs = {"pixelgym_id": id, **self._kwargs}
        if self._wrap:
            spec_kwargs["wrap"] = list(self._wrap)
        if render_mode != "rgb_array":
            spec_kwargs["render_mode"] = render_mode
        self._spec = _gymnasium_spec(id, spec_kwargs, self._core.max_episode_steps)
        self._cpp_seeded = False

    # gymnasium.make sets env.unwrapped.spec to its own EnvSpec without max_episode_steps (it is
    # registered without one: the C++ env truncates itself); this keeps the real limit in it.
    @property
    def spec(self):
        return self._spec

    @spec.setter
    def spec(self, value):
        if value is not None and dataclasses.is_dataclass(value):
            value = dataclasses.replace(value, max_episode_steps=self._core.max_episode_steps)
        self._spec = value

    def reset(self, *, seed=None, options=None):
        cpp_seed = seed
        if seed is None and not self._cpp_seeded:
            cpp_seed = int(self.np_random.integers(0, 2**63))
        obs, info = self._core.reset(cpp_seed, options)
        self._cpp_seeded = True
        if seed is not None:
            seed_np_random(self, seed)
        return obs, info

    def step(self, action):
        return self._core.step(action)

    def render(self):
        if self.render_mode is None:
            if gymnasium is not None:
                gymnasium.logger.warn(
                    f"{self._id}: render() was called with render_mode=None; make the env with "
                    'render_mode="rgb_array" for frames'
                )
            return None
        return self._core.render()

    def close(self):
        self._core.close()

    @property
    def closed(self):
        return self._core.closed

    def __reduce__(self):
        return (_remake, (self._id, self.render_mode, self._wrap, self._kwargs))


def _remake(env_id, render_mode, wrap, kwargs):
    return Env(env_id, render_mode=render_mode, wrap=wrap, **kwargs)


def make(id, render_mode="rgb_array", wrap=(), **kwargs):
    """Makes env ``id`` with its C++ kwargs (``pixelgym.info(id)`` lists them, typed: a wrong
    type raises TypeError, an unknown kwarg or id ValueError, each with pixelgym's message) and
    the pixelgym wrappers in ``wrap`` (the CLI's ``--wrap`` specs, e.g. ``["resize=64x64",
    "grayscale", "frame_stack=3"]``, the first innermost). ``max_episode_steps`` sets the time
    limit (0: none)."""
    return Env(id, render_mode=render_mode, wrap=wrap, **kwargs)


def make_registered(pixelgym_id, **kwargs):
    """gymnasium's entry point for pixelgym/<ID>: ``make(pixelgym_id, **kwargs)`` (the id is not
    passed as ``id``, which gymnasium.make and make_vec take for their own)."""
    return make(pixelgym_id, **kwargs)


# gymnasium.make reads the entry point's render modes to serve render_mode="rgb_array_list"
# (Gymnasium's RenderCollection over "rgb_array"); every pixelgym env renders rgb_array.
make_registered.metadata = {"render_modes": ["rgb_array"]}
