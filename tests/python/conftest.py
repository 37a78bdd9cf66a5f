"""Shared fixtures of the Python suites: the package under test comes from the build tree
(CTest sets PYTHONPATH to build/python)."""
import os

import numpy as np
import pytest

import dicestack


def short_world(max_steps):
    """The paper's world with a shorter time limit, as a dict."""
    world = dicestack.default_world()
    world["episode"]["max_steps"] = max_steps
    return world


@pytest.fixture
def env():
    e = dicestack.DiceStackEnv(render_mode="rgb_array")
    yield e
    e.close()


@pytest.fixture(scope="session")
def builtin_episodes():
    return dicestack.load_demos("builtin")


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


def random_actions(rng, n, scale=(1.0, 0.1, 0.5)):
    """Actions in the optimisers' range (x in [-1, 1]^3 times the world's action scale)."""
    return rng.uniform(-1.0, 1.0, size=(n, 3)) * np.asarray(scale)


@pytest.fixture(scope="session")
def cli():
    """The dicestack executable of the same build, when CTest names it."""
    exe = os.environ.get("DICESTACK_EXE")
    if not exe or not os.path.exists(exe):
        pytest.skip("DICESTACK_EXE not set: run through CTest to compare with the command line")
    return exe
