"""pixelgym from Python: pixel RL environments (Bullet physics, OSMesa rendering) in C++.

    import pixelgym
    env = pixelgym.make("CartPoleSwingup-v1")          # a gymnasium.Env when gymnasium is installed
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

    envs = pixelgym.make_vec("CartPoleSwingup-v1", num_envs=8, num_threads=2)  # the C++ thread pool

When gymnasium is importable, ``make`` returns a ``gymnasium.Env`` and ``make_vec`` a
``gymnasium.vector.VectorEnv`` with ``gymnasium.spaces`` spaces, and every env is registered with
gymnasium as ``pixelgym/<ID>`` (``gymnasium.make("pixelgym/CartPoleSwingup-v1")``,
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``). Without gymnasium the same
classes and methods work, with pixelgym's own space classes. Setting PIXELGYM_NO_GYMNASIUM=1
makes pixelgym ignore an installed gymnasium.

Zero copy. Observations are numpy arrays viewing pixelgym's own memory (their ``base`` is a
``pixelgym.Buffer``), not copies. A single env's observations are fresh memory each step. A
vector env's observation batch is one set of buffers that **every reset and step overwrites**:
keep what must outlive the next call with ``obs.copy()`` (or ``make_vec(..., copy=True)``).
Rewards, flags and infos are always copies.
"""

import os as _os
import sys as _sys
import warnings as _warnings

try:
    import numpy as _numpy  # noqa: F401
except ImportError as _error:
    raise ImportError(
        f"pixelgym needs numpy, which this Python ({_sys.executable}) cannot import: install it "
        "into the same environment with `python -m pip install \"numpy<2\"` (the wheel lists it; "
        "pip installs it unless given --no-deps or no index), or, for Debian's /usr/bin/python3, "
        "`apt install python3-numpy` (a venv made with `python3 -m venv --system-site-packages` "
        "sees it)", name="numpy") from _error

from . import _core
from ._core import Buffer

try:
    if _os.environ.get("PIXELGYM_NO_GYMNASIUM", "") not in ("", "0"):
        raise ImportError("PIXELGYM_NO_GYMNASIUM is set")
    import gymnasium as _gymnasium
except ImportError:
    _gymnasium = None

#: True when pixelgym's classes are gymnasium's (gymnasium is importable).
HAVE_GYMNASIUM = _gymnasium is not None


class GymnasiumMissingWarning(UserWarning):
    """Issued once, on import, when gymnasium is not importable."""


if HAVE_GYMNASIUM:

    class ResetNeeded(RuntimeError, _gymnasium.error.ResetNeeded):
        """A call out of order: step or render before reset, step after the episode ended."""

else:

    class ResetNeeded(RuntimeError):
        """A call out of order: step or render before reset, step after the episode ended."""

    _warnings.warn(
        "pixelgym: gymnasium is not installed, so pixelgym.make and make_vec return pixelgym's "
        "own classes (same methods, pixelgym spaces). `pip install gymnasium` (>= 1.0) makes "
        "them gymnasium.Env and gymnasium.vector.VectorEnv subclasses with gymnasium.spaces, "
        "and registers every env as pixelgym/<ID>.",
        GymnasiumMissingWarning,
        stacklevel=2,
    )

_core._set_reset_needed_type(ResetNeeded)

from . import _env, _vector  # noqa: E402
from ._env import Env, make  # noqa: E402
from ._vector import VectorEnv, make_vec  # noqa: E402
from ._core_backed import wrap_list as _wrap_list  # noqa: E402


def ids():
    """Every registered env id, sorted."""
    return _core.ids()


def info(id, wrap=(), **kwargs):
    """What ``make(id, wrap=wrap, **kwargs)`` gives, without making it (no world, no GL context):
    a dict with the spaces (pixelgym's own), max_episode_steps, cameras, metadata, and the kwargs
    the env accepts (name, type, default, doc). Raises as ``make`` does."""
    return _core.describe(id, kwargs, _wrap_list(wrap))


def wrapper_specs():
    """The ``wrap=`` spec forms (the CLI's ``--wrap``): (name, usage, summary) for each wrapper."""
    return _core.wrapper_specs()


def register_gymnasium_envs():
    """Registers every pixelgym env with gymnasium as ``pixelgym/<ID>`` (entry_point and
    vector_entry_point); done on import when gymnasium is importable, and harmless to repeat."""
    if not HAVE_GYMNASIUM:
        raise ImportError("register_gymnasium_envs needs gymnasium: pip install gymnasium")
    for env_id in ids():
        name = "pixelgym/" + env_id
        if name in _gymnasium.registry:
            continue
        # No max_episode_steps here: the C++ env truncates at its own limit (which kwargs such as
        # action_repeat change), and env.spec reports that limit. The pixelgym id travels as the
        # kwarg pixelgym_id (gymnasium.make's own first argument is named id).
        _gymnasium.register(
            id=name,
            entry_point=_env.ENTRY_POINT,
            vector_entry_point=_vector.VECTOR_ENTRY_POINT,
            kwargs={"pixelgym_id": env_id},
        )


if HAVE_GYMNASIUM:
    register_gymnasium_envs()

__all__ = [
    "Buffer",
    "Env",
    "GymnasiumMissingWarning",
    "HAVE_GYMNASIUM",
    "ResetNeeded",
    "VectorEnv",
    "ids",
    "info",
    "make",
    "make_vec",
    "register_gymnasium_envs",
    "wrapper_specs",
]
