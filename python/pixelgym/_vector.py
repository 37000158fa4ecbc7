"""pixelgym.VectorEnv: the C++ vector env (a thread pool by default) behind Gymnasium's VectorEnv
API (a gymnasium.vector.VectorEnv when gymnasium is importable)."""

import numpy as np

from . import _core
from . import _gymnasium as gymnasium
from ._core_backed import CoreBacked, wrap_list
from ._random import NumpyRandom, seed_np_random
from ._spaces import to_gymnasium

_MODE_NAMES = {"nextstep": "NextStep", "next_step": "NextStep", "samestep": "SameStep",
               "same_step": "SameStep", "disabled": "Disabled"}

#: What gymnasium's registry calls for make_vec(pixelgym/<ID>, vectorization_mode=
#: "vector_entry_point").
VECTOR_ENTRY_POINT = "pixelgym._vector:make_vec_registered"

if gymnasium is not None:
    _Base = gymnasium.vector.VectorEnv
    _AutoresetMode = getattr(gymnasium.vector, "AutoresetMode", None)  # Gymnasium >= 1.1
else:
    _Base = NumpyRandom
    _AutoresetMode = None


_INT_MAX = 2**31 - 1  # the C++ vector env counts envs and threads in an int


def _count(name, value, minimum):
    """``value`` as an int from ``minimum`` to 2**31 - 1; TypeError or ValueError naming ``name``
    otherwise (pybind11's own error lists overloads instead)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"make_vec: {name} must be an int, got {type(value).__name__} {value!r}")
    value = int(value)
    if not minimum <= value <= _INT_MAX:
        raise ValueError(f"make_vec: {name} must be from {minimum} to {_INT_MAX}, got "
                         f"{name} = {value}")
    return value


def _mode_name(mode):
    text = str(getattr(mode, "value", mode))
    return _MODE_NAMES.get(text.lower(), text)


def _copy_obs(obs):
    if isinstance(obs, dict):
        return {key: _copy_obs(value) for key, value in obs.items()}
    if isinstance(obs, tuple):
        return tuple(_copy_obs(value) for value in obs)
    return obs.copy()


def _row(obs, i):
    """Env i's observation in a batch, copied."""
    if isinstance(obs, dict):
        return {key: _row(value, i) for key, value in obs.items()}
    if isinstance(obs, tuple):
        return tuple(_row(value, i) for value in obs)
    return obs[i].copy()


class VectorEnv(CoreBacked, _Base):
    """``num_envs`` copies of a pixelgym env stepped as one by the C++ vector env: a thread pool
    (``mode="async"``, ``num_threads`` workers, 0 for one per core), worker processes writing
    into shared memory (``mode="process"``, ``num_workers`` of them, 0 for one per core: envs
    registered in C++ reach them; make it before anything draws on a GPU in this process), or a
    loop on the calling thread (``mode="sync"``). The GIL is released while C++ steps, so other
    Python threads run.

    Gymnasium 1.x's protocol: ``reset(seed=None, options=None) -> (obs, infos)`` resets env i
    with ``seed + i`` (or ``seed[i]`` for a list); ``step(actions) -> (obs, rewards,
    terminations, truncations, infos)``, infos batched with ``_key`` masks. Autoreset follows
    ``autoreset_mode`` ("NextStep", Gymnasium's default; "SameStep", with ``infos["final_obs"]``
    an object array of the ended envs' last observations and ``infos["final_info"]``; or
    "Disabled": reset ended envs with ``reset(options={"reset_mask": mask})``), declared in
    ``metadata["autoreset_mode"]``. ``wrap`` applies pixelgym's wrappers to every env (the CLI's
    ``--wrap`` specs).

    **The observation batch is overwritten by the next reset or step**: the arrays returned are
    views of the vector env's buffers (zero copy; their ``base`` is a ``pixelgym.Buffer``), the
    same arrays every call. Keep one with ``obs.copy()``, or make the env with ``copy=True`` to
    get copies (Gymnasium's default). Rewards, flags and infos are copies.

    With ``mode="async"``, ``step_async(actions)`` starts a step and returns at once;
    ``step_wait()`` collects it, so the caller can compute while the envs step.
    """

    def __init__(self, id, num_envs=1, *, num_threads=0, autoreset_mode="NextStep", wrap=(),
                 mode="async", share_gl_contexts=True, copy=False, render_mode="rgb_array",
                 num_workers=0, **kwargs):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(
                f"{id}: render_mode must be 'rgb_array' (the default) or None, got "
                f"{render_mode!r}: pixelgym renders off-screen (headless, no window) and render() "
                "returns each env's (H, W, 3) uint8 frame"
            )
        wrap = wrap_list(wrap)
        num_envs = _count("num_envs", num_envs, 1)
        num_threads = _count("num_threads", num_threads, 0)
        num_workers = _count("num_workers", num_workers, 0)
        self._core = _core.VectorEnv(id, num_envs, kwargs, wrap, mode, num_threads,
                                     _mode_name(autoreset_mode), share_gl_contexts, num_workers)
        self._id = id
        self._args = dict(num_envs=num_envs, num_threads=num_threads, num_workers=num_workers,
                          autoreset_mode=_mode_name(autoreset_mode), wrap=tuple(wrap),
                          mode=mode, share_gl_contexts=share_gl_contexts, copy=copy,
                          render_mode=render_mode, **kwargs)
        self.copy = copy
        self.num_envs = self._core.num_envs
        self.render_mode = render_mode
        metadata = self._core.metadata
        mode_name = metadata["autoreset_mode"]
        self.metadata = {
            "render_modes": list(metadata["render_modes"]),
            "render_fps": metadata["render_fps"],
            "autoreset_mode": _AutoresetMode(mode_name) if _AutoresetMode else mode_name,
        }
        self.single_observation_space = to_gymnasium(self._core.single_observation_space,
                                                     gymnasium)
        self.single_action_space = to_gymnasium(self._core.single_action_space, gymnasium)
        if gymnasium is not None:
            batch_space = gymnasium.vector.utils.batch_space
            self.observation_space = batch_space(self.single_observation_space, self.num_envs)
            self.action_space = batch_space(self.single_action_space, self.num_envs)
        else:
            self.observation_space = self._core.observation_space
            self.action_space = self._core.action_space
        self.closed = False
        self.spec = None

    def reset(self, *, seed=None, options=None):
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if isinstance(seed, (list, tuple)):
            obs, infos = self._reset_each(list(seed), options, mask)
        else:
            obs, infos = self._core.reset(seed, options, mask)
        if seed is not None and not isinstance(seed, (list, tuple)):
            seed_np_random(self, seed)
        return (_copy_obs(obs) if self.copy else obs), infos

    def _reset_each(self, seeds, options, mask):
        """reset(seed=[s0, s1, ...]): env i seeded with seeds[i] (None: unseeded), one masked
        C++ reset per env (the C++ reset seeds env i with seed + i, so each gets seeds[i] - i,
        modulo 2**64), infos merged."""
        if len(seeds) != self.num_envs:
            raise ValueError(
                f"{self._core.name}.reset: {len(seeds)} seeds given for {self.num_envs} envs"
            )
        selected = (np.ones(self.num_envs, dtype=bool) if mask is None
                    else np.asarray(mask, dtype=bool))
        infos = {}
        obs = None
        for i, env_seed in enumerate(seeds):
            if not selected[i]:
                continue
            one = np.zeros(self.num_envs, dtype=bool)
            one[i] = True
            shifted = env_seed  # None, or what the C++ side refuses with its message
            if isinstance(env_seed, (int, np.integer)) and not isinstance(env_seed, bool) \
                    and env_seed >= 0:
                shifted = (int(env_seed) - i) % 2**64
            obs, env_infos = self._core.reset(shifted, options, one)
            _merge_infos(infos, env_infos)
        return obs, infos

    def step(self, actions):
        obs, rewards, terminations, truncations, infos = self._core.step(actions)
        return self._finish_step(obs, rewards, terminations, truncations, infos)

    def step_async(self, actions):
        """Starts a step (mode="async" only) and returns without waiting; step_wait() collects
        it. The actions are copied: the caller may reuse them at once."""
        self._core.step_async(actions)

    def step_wait(self):
        """The results of the step begun by step_async, as step() returns them."""
        return self._finish_step(*self._core.step_wait())

    def _finish_step(self, obs, rewards, terminations, truncations, infos):
        if "final_obs" in infos:
            # Gymnasium's layout: an object array of the ended envs' last observations.
            batch, mask = infos["final_obs"], infos["_final_obs"]
            final = np.full(self.num_envs, None, dtype=object)
            for i in np.flatnonzero(mask):
                final[i] = _row(batch, i)
            infos["final_obs"] = final
        return (_copy_obs(obs) if self.copy else obs), rewards, terminations, truncations, infos

    def render(self):
        """Each env's current frame, env 0 first: a tuple of num_envs (H, W, 3) uint8 arrays, as
        Gymnasium's SyncVectorEnv.render() gives with render_mode "rgb_array" (None, with a
        warning, when made with render_mode=None). Raises ResetNeeded before the first reset,
        after close() and while a step_async() is pending."""
        if self.render_mode is None:
            if gymnasium is not None:
                gymnasium.logger.warn(
                    f"{self._core.name}: render() was called with render_mode=None; make the "
                    'vector env with render_mode="rgb_array" for frames'
                )
            return None
        return self._core.render()

    def close(self, **kwargs):
        # Also called by __del__ on an object whose __init__ raised (no _core then).
        if getattr(self, "closed", True) or "_core" not in self.__dict__:
            return
        self._core.close()
        self.closed = True

    if gymnasium is None:

        def __del__(self):
            if not getattr(self, "closed", True):
                self.close()

    @property
    def num_threads(self):
        """Threads that run envs (1 for mode="sync")."""
        return self._core.num_threads

    @property
    def num_workers(self):
        """Worker processes that run envs (mode="process"; 0 otherwise)."""
        return self._core.num_workers

    @property
    def autoreset_mode(self):
        """"NextStep", "SameStep" or "Disabled"."""
        return self._core.autoreset_mode

    def __reduce__(self):
        return (_remake, (self._id, self._args))


def _merge_infos(total, infos):
    """Adds batched infos (each key with its "_key" mask) into ``total``, row by row."""
    for key, value in infos.items():
        if key.startswith("_"):
            continue
        mask = infos.get("_" + key)
        if isinstance(value, dict):
            _merge_infos(total.setdefault(key, {}), value)
            total.setdefault("_" + key, np.zeros_like(mask))
            total["_" + key] |= mask
            continue
        if key not in total:
            total[key] = np.zeros_like(value)
            total["_" + key] = np.zeros_like(mask)
        total[key][mask] = value[mask]
        total["_" + key] |= mask


def _remake(env_id, args):
    return VectorEnv(env_id, **args)


def make_vec(id, num_envs=1, *, num_threads=0, autoreset_mode="NextStep", wrap=(), mode="async",
             share_gl_contexts=True, copy=False, render_mode="rgb_array", num_workers=0,
             **kwargs):
    """A VectorEnv of ``num_envs`` copies of env ``id`` made with ``kwargs`` (typed C++ kwargs,
    as ``make``) and the pixelgym wrappers in ``wrap``; see VectorEnv. Also gymnasium's
    ``vector_entry_point`` for ``pixelgym/<ID>``."""
    return VectorEnv(id, num_envs, num_threads=num_threads, autoreset_mode=autoreset_mode,
                     wrap=wrap, mode=mode, share_gl_contexts=share_gl_contexts, copy=copy,
                     render_mode=render_mode, num_workers=num_workers, **kwargs)


def make_vec_registered(pixelgym_id, num_envs=1, **kwargs):
    """gymnasium's vector entry point for pixelgym/<ID>: ``make_vec(pixelgym_id, num_envs,
    **kwargs)``."""
    return make_vec(pixelgym_id, num_envs, **kwargs)
