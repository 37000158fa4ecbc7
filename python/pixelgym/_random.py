"""np_random as Gymnasium's Env and VectorEnv have it, for pixelgym's classes when gymnasium is
not importable."""

import numpy as np


class NumpyRandom:
    """``np_random``: a numpy Generator for the caller's own randomness, seeded by
    ``reset(seed=...)`` (``seed_np_random``), else from entropy on first use; ``np_random_seed``
    its seed (-1 once set directly); ``unwrapped``: the object itself."""

    _np_random = None
    _np_random_seed = None

    @property
    def np_random(self):
        if self._np_random is None:
            seed_np_random(self, int(np.random.SeedSequence().generate_state(1)[0]))
        return self._np_random

    @np_random.setter
    def np_random(self, value):
        self._np_random, self._np_random_seed = value, -1

    @property
    def np_random_seed(self):
        self.np_random  # noqa: B018 (creates it)
        return self._np_random_seed

    @property
    def unwrapped(self):
        return self


def seed_np_random(obj, seed):
    """Seeds ``obj.np_random`` as Gymnasium's ``reset(seed=seed)`` does (its seeding.np_random is
    numpy's default_rng(seed)); works on gymnasium's classes too."""
    obj._np_random, obj._np_random_seed = np.random.default_rng(seed), seed
