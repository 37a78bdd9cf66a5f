"""DiceStackVectorEnv: batched shapes, Gymnasium's next-step autoreset, and the same results as
stepping DiceStackEnvs one by one, whatever the thread count."""
import time

import numpy as np
import pytest

import dicestack
from conftest import random_actions, short_world


def sequential(num_envs, world, seed, actions):
    """What the vector env must give, computed one environment at a time."""
    envs = [dicestack.DiceStackEnv(world=world) for _ in range(num_envs)]
    first = [e.reset(seed=seed + i) for i, e in enumerate(envs)]
    done = [False] * num_envs
    steps = []
    for row in actions:
        out = []
        for i, e in enumerate(envs):
            if done[i]:
                obs, info = e.reset()
                out.append((obs, 0.0, False, False, info))
                done[i] = False
            else:
                out.append(e.step(row[i]))
                done[i] = out[-1][2] or out[-1][3]
        steps.append(out)
    return first, steps


def test_reset_and_step_shapes():
    venv = dicestack.DiceStackVectorEnv(3)
    obs, info = venv.reset(seed=0)
    assert obs.shape == (3, 24) and obs.dtype == np.float64
    assert info["t"].shape == (3,) and info["_t"].all()
    obs, rewards, terminated, truncated, info = venv.step(np.zeros((3, 3)))
    assert obs.shape == (3, 24) and rewards.shape == (3,) and rewards.dtype == np.float64
    assert terminated.dtype == np.bool_ and truncated.dtype == np.bool_
    assert (info["t"] == 1).all()
    assert venv.single_observation_space.shape == (24,) and venv.observation_space.shape == (3, 24)
    assert venv.single_action_space.shape == (3,) and venv.action_space.shape == (3, 3)
    assert venv.metadata["autoreset_mode"] is not None


@pytest.mark.parametrize("threads", [1, 2])
def test_equals_stepping_one_by_one_with_autoreset(rng, threads):
    world = short_world(12)  # several autoresets in 40 steps
    n, seed = 3, 70
    actions = random_actions(rng, 40 * n).reshape(40, n, 3)
    first, steps = sequential(n, world, seed, actions)
    venv = dicestack.DiceStackVectorEnv(n, world=world, threads=threads)
    obs, info = venv.reset(seed=seed)
    np.testing.assert_array_equal(obs, np.stack([f[0] for f in first]))
    resets = 0
    for row, expected in zip(actions, steps):
        obs, rewards, terminated, truncated, info = venv.step(row)
        for i, (e_obs, e_reward, e_term, e_trunc, e_info) in enumerate(expected):
            np.testing.assert_array_equal(obs[i], e_obs)
            assert rewards[i] == e_reward and terminated[i] == e_term and truncated[i] == e_trunc
            for key, value in e_info.items():
                assert info[key][i] == value, key
            resets += e_info["t"] == 0
    assert resets >= 2 * n


def test_seed_list_and_unseeded_reset():
    venv = dicestack.DiceStackVectorEnv(2)
    a, _ = venv.reset(seed=[5, 9])
    b, _ = venv.reset(seed=5)
    np.testing.assert_array_equal(a[0], b[0])
    assert not np.array_equal(a[1], b[1])
    c, _ = venv.reset()
    assert c.shape == (2, 24)


def test_bad_arguments():
    with pytest.raises(ValueError, match="num_envs"):
        dicestack.DiceStackVectorEnv(0)
    venv = dicestack.DiceStackVectorEnv(2)
    venv.reset(seed=0)
    with pytest.raises(ValueError, match=r"shape \(2, 3\)"):
        venv.step(np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        venv.step(np.zeros(3))
    with pytest.raises(ValueError, match="NaN"):
        venv.step(np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]]))
    with pytest.raises(ValueError, match="2 seeds"):
        venv.reset(seed=[1, 2, 3])
    with pytest.raises(ValueError, match="threads"):
        dicestack.DiceStackVectorEnv(2, threads=-1)


def test_a_count_that_cannot_fit_is_refused_at_once_saying_what_it_needs():
    start = time.monotonic()
    for count in (10**6, 10**12):
        with pytest.raises(ValueError, match=rf"DiceStackVectorEnv: {count} environments would need up to .* this machine has"):
            dicestack.DiceStackVectorEnv(count)
    assert time.monotonic() - start < 5
