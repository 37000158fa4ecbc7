"""Shared helpers of the binding's pytest suite (tests/python/, run by ctest with
PYTHONPATH=build/python and Debian's /usr/bin/python3). The tests need numpy alone: with gymnasium
importable they check the gymnasium classes, without it pixelgym's own."""

import warnings

import numpy as np
import pytest

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # GymnasiumMissingWarning, said once on import
    import pixelgym

ENV_IDS = pixelgym.ids()


def leaves(obs):
    """The arrays of an observation (a dict, a tuple or an array), in key order."""
    if isinstance(obs, dict):
        return [leaf for value in obs.values() for leaf in leaves(value)]
    if isinstance(obs, tuple):
        return [leaf for value in obs for leaf in leaves(value)]
    return [np.asarray(obs)]


def same(a, b):
    """Same structure, dtypes, shapes and bytes."""
    if isinstance(a, dict):
        return isinstance(b, dict) and list(a) == list(b) and all(same(a[k], b[k]) for k in a)
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture(params=ENV_IDS)
def env_id(request):
    return request.param
