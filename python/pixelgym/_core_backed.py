"""What pixelgym's Env and VectorEnv share: the C++ object behind them, ``self._core``."""


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
