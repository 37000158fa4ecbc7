"""What pixelgym's Env and VectorEnv share: the C++ object behind them, ``self._core``."""


def wrap_list(wrap):
    """``wrap=`` as a list of specs: one spec as a string ("grayscale"), or an iterable of them.
    Raises TypeError naming what was given for anything else."""
    if isinstance(wrap, str):
        return [wrap]
    try:
        specs = list(wrap)
    except TypeError:
        raise TypeError(
            f"wrap= takes a wrapper spec (a str such as 'grayscale') or a list of them, "
            f"got {type(wrap).__name__} {wrap!r}") from None
    for spec in specs:
        if not isinstance(spec, str):
            raise TypeError(
                f"wrap= takes wrapper specs as str (such as 'resize=64x64'), got "
                f"{type(spec).__name__} {spec!r} in {wrap!r}")
    return specs


class CoreBacked:
    """Reads shared by Env and VectorEnv from ``self._core`` (a _core.Env or _core.VectorEnv)."""

    @property
    def max_episode_steps(self):
        """The step at which the env truncates (None: no limit)."""
        return self._core.max_episode_steps

    def __repr__(self):
        return f"<pixelgym.{type(self).__name__} {self._core.name}>"

    def __str__(self):
        return self.__repr__()
