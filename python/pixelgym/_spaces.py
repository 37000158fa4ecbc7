"""pixelgym's spaces as gymnasium.spaces, when gymnasium is importable."""

from . import _core


def to_gymnasium(space, gymnasium):
    """The gymnasium.spaces equivalent of a pixelgym space (Box bounds and dtype, Dict keys in
    pixelgym's order); the pixelgym space itself when ``gymnasium`` is None."""
    if gymnasium is None:
        return space
    spaces = gymnasium.spaces
    if isinstance(space, _core.Box):
        return spaces.Box(low=space.low, high=space.high, shape=space.shape, dtype=space.dtype)
    if isinstance(space, _core.Discrete):
        return spaces.Discrete(space.n, start=space.start)
    if isinstance(space, _core.MultiDiscrete):
        return spaces.MultiDiscrete(space.nvec, start=space.start)
    if isinstance(space, _core.MultiBinary):
        return spaces.MultiBinary(space.n)
    if isinstance(space, _core.Dict):
        # A sequence of pairs keeps pixelgym's key order (a plain dict would be sorted).
        return spaces.Dict([(key, to_gymnasium(space[key], gymnasium)) for key in space.keys()])
    if isinstance(space, _core.Tuple):
        return spaces.Tuple([to_gymnasium(sub, gymnasium) for sub in space.spaces])
    raise TypeError(f"pixelgym: no gymnasium space for {space!r}")
