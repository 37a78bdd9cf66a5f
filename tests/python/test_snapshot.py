"""Snapshots: exact, picklable, and only for the world they were taken in."""
import copy
import pickle

import numpy as np
import pytest

import dicestack
from conftest import random_actions, short_world


def continue_with(env, actions):
    return [env.step(a) for a in actions]


def assert_same_steps(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x[0], y[0])
        assert x[1:] == y[1:]


@pytest.fixture
def midway(rng):
    """An environment 40 steps into a noisy episode (the snapshot must carry the noise stream)."""
    world = dicestack.default_world()
    world["physics"]["action_noise"] = 0.2
    env = dicestack.DiceStackEnv(world=world)
    env.reset(seed=11)
    for a in random_actions(rng, 40):
        env.step(a)
    return env


def test_restore_continues_bit_for_bit(midway, rng):
    snap = midway.snapshot()
    assert snap.t == 40
    np.testing.assert_array_equal(snap.state, midway.state)
    actions = random_actions(rng, 60)
    first = continue_with(midway, actions)
    midway.restore(snap)
    assert midway.t == 40
    assert_same_steps(first, continue_with(midway, actions))


def test_pickled_snapshot_restores_into_a_fresh_env(midway, rng):
    snap = midway.snapshot()
    data = pickle.dumps(snap)
    actions = random_actions(rng, 60)
    first = continue_with(midway, actions)
    fresh = dicestack.DiceStackEnv(world=midway.world)
    fresh.restore(pickle.loads(data))
    assert_same_steps(first, continue_with(fresh, actions))
    again = copy.deepcopy(snap)
    assert again.t == snap.t and again.world_hash == snap.world_hash


def test_restore_keeps_the_seed_stream(env):
    env.reset(seed=5)
    snap = env.snapshot()
    next_start, _ = env.reset()
    env.restore(snap)
    np.testing.assert_array_equal(env.reset()[0], next_start)


def test_restoring_into_another_world_is_refused(midway):
    snap = midway.snapshot()
    other = dicestack.DiceStackEnv(world=short_world(50))
    with pytest.raises(ValueError, match="another world"):
        other.restore(pickle.loads(pickle.dumps(snap)))


def test_damaged_snapshot_bytes_are_refused(midway):
    state = list(midway.snapshot().__getstate__())
    record = bytearray(state[2])
    record[len(record) // 2] ^= 0x10
    state[2] = bytes(record)
    snap = dicestack.Snapshot.__new__(dicestack.Snapshot)
    with pytest.raises(ValueError, match="checksum"):
        snap.__setstate__(tuple(state))
    with pytest.raises(ValueError, match="not a dicestack snapshot"):
        dicestack.Snapshot.__new__(dicestack.Snapshot).__setstate__((99,))
