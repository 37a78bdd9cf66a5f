"""Demonstrations as numpy arrays: the built-in set, and our folder format written and read back
(the library's ownership rule included)."""
import numpy as np
import pytest

import dicestack


def test_builtin_set_shapes(builtin_episodes):
    assert len(builtin_episodes) == 80
    for e in builtin_episodes:
        assert e.states.dtype == np.float64 and e.states.shape == (len(e), 24)
        assert e.actions.dtype == np.float64 and e.actions.shape == (len(e), 3)
        assert len(e.sources) == len(e) and e.source == "expert"
        assert e.realistic_success and e.dice_in_cup == 3
        assert isinstance(e.seed, int)
        # Format v2: the state after the last action, a reward per step, the end flags.
        assert e.final_state.shape == (24,) and e.rewards.shape == (len(e),)
        assert e.observations.shape == (len(e) + 1, 24)
        assert e.terminated and not e.truncated
    assert builtin_episodes[0].name == "episode_0000"


def test_save_and_load_round_trip(tmp_path, builtin_episodes):
    episodes = builtin_episodes[:3]
    folder = tmp_path / "set"
    dicestack.save_demos(episodes, folder, description="three of the built-in set")
    back = dicestack.load_demos(folder)
    assert [e.name for e in back] == ["episode_0000", "episode_0001", "episode_0002"]
    for a, b in zip(episodes, back):
        np.testing.assert_array_equal(a.states, b.states)
        np.testing.assert_array_equal(a.actions, b.actions)
        assert a.sources == b.sources and a.seed == b.seed
        assert (a.stacked, a.wall_contact, a.dice_in_cup) == (b.stacked, b.wall_contact, b.dice_in_cup)
        np.testing.assert_array_equal(a.final_state, b.final_state)
        np.testing.assert_array_equal(a.rewards, b.rewards)
        assert (a.terminated, a.truncated) == (b.terminated, b.truncated)
    dicestack.save_demos(back[:1], folder)  # our own set may be replaced
    assert len(dicestack.load_demos(folder)) == 1


def test_episodes_made_in_python_save(tmp_path, rng):
    env = dicestack.DiceStackEnv()
    obs, _ = env.reset(seed=3)
    states, actions = [], []
    for _ in range(5):
        action = rng.uniform(-1, 1, 3) * [1.0, 0.1, 0.5]
        states.append(obs)
        actions.append(action)
        obs, *_ = env.step(action)
    dicestack.save_demos([dicestack.Episode(states, actions, seed=3)], tmp_path / "mine")
    (back,) = dicestack.load_demos(tmp_path / "mine")
    assert back.source == "policy" and back.seed == 3
    np.testing.assert_array_equal(back.states, np.array(states))


def test_transitions_match_the_environment(builtin_episodes):
    """The stored final state and rewards are what stepping the world with the actions gives."""
    e = builtin_episodes[0]
    env = dicestack.DiceStackEnv()
    obs, _ = env.reset(seed=e.seed)
    np.testing.assert_array_equal(obs, e.states[0])
    rewards = []
    for t, action in enumerate(e.actions):
        obs, reward, terminated, truncated, _ = env.step(action)
        rewards.append(reward)
    np.testing.assert_array_equal(obs, e.final_state)
    np.testing.assert_array_equal(np.array(rewards), e.rewards)
    assert (terminated, truncated) == (e.terminated, e.truncated)


def test_transitions_are_all_or_nothing(tmp_path, builtin_episodes):
    e = builtin_episodes[0]
    no_final = dicestack.Episode(e.states, e.actions, seed=e.seed, rewards=e.rewards)
    with pytest.raises(ValueError, match="final_state and rewards go together"):
        dicestack.save_demos([no_final], tmp_path / "a")
    short = dicestack.Episode(e.states, e.actions, final_state=e.final_state, rewards=e.rewards[:-1])
    with pytest.raises(ValueError, match="rewards"):
        dicestack.save_demos([short], tmp_path / "b")
    without = dicestack.Episode(e.states, e.actions, seed=e.seed)
    dicestack.save_demos([without], tmp_path / "c")
    (back,) = dicestack.load_demos(tmp_path / "c")
    assert back.final_state is None and back.rewards is None and back.observations is None


def test_a_users_folder_is_never_replaced(tmp_path, builtin_episodes):
    folder = tmp_path / "notes"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.save_demos(builtin_episodes[:1], folder)
    assert (folder / "notes.txt").read_text() == "mine"


def test_bad_episodes_and_folders(tmp_path):
    with pytest.raises(ValueError, match="shape"):
        dicestack.save_demos([dicestack.Episode(np.zeros((3, 24)), np.zeros((3, 2)))], tmp_path / "a")
    with pytest.raises(ValueError, match="states, 2 actions"):
        dicestack.save_demos([dicestack.Episode(np.zeros((3, 24)), np.zeros((2, 3)))], tmp_path / "b")
    with pytest.raises(ValueError, match="not one of human"):
        dicestack.save_demos([dicestack.Episode(np.zeros((1, 24)), np.zeros((1, 3)), sources=["robot"])], tmp_path / "c")
    with pytest.raises(FileNotFoundError):
        dicestack.load_demos(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError):
        dicestack.load_demos(tmp_path / "empty")
    with pytest.raises(TypeError):
        dicestack.save_demos([{"states": []}], tmp_path / "d")


def test_a_minari_export_recovers_its_environment(tmp_path, cli, builtin_episodes):
    """What minari's recover_environment() does with the export's env_spec (gymnasium.make of
    the spec: entry point and kwargs) gives an environment that replays the stored episode."""
    import importlib
    import json
    import subprocess

    h5py = pytest.importorskip("h5py")
    dicestack.save_demos(builtin_episodes[:2], tmp_path / "set")
    subprocess.run([cli, "dataset", "export", str(tmp_path / "set"), "--format", "minari", "--out", str(tmp_path / "mn")],
                   check=True, capture_output=True)
    spec = json.loads(json.loads((tmp_path / "mn" / "data" / "metadata.json").read_text())["env_spec"])
    assert spec["id"] == dicestack.ENV_ID and spec["additional_wrappers"] == []
    module, name = spec["entry_point"].split(":")
    env = getattr(importlib.import_module(module), name)(**spec["kwargs"])
    with h5py.File(tmp_path / "mn" / "data" / "main_data.hdf5", "r") as f:
        observations, actions = f["episode_1/observations"][()], f["episode_1/actions"][()]
    obs, _ = env.reset(options={"state": observations[0]})
    for a in actions:
        obs, *_ = env.step(a)
    np.testing.assert_array_equal(obs, observations[-1])


def test_an_arm_set_keeps_its_links_and_joint_torques(tmp_path, cli):
    import subprocess

    subprocess.run([cli, "record", "--expert", "scripted", "--episodes", "2", "--embodiment", "arm", "--threads", "1",
                    "--out", str(tmp_path / "arm")], check=True, capture_output=True)
    episodes = dicestack.load_demos(tmp_path / "arm")
    for e in episodes:
        assert e.link_angles.shape == (len(e), 3) and e.link_rates.shape == (len(e), 3)
        assert e.joint_torques.shape == (len(e), 4) and np.any(e.joint_torques[:, 0])
        assert e.final_link_angles.shape == (3,) and e.final_link_rates.shape == (3,)
    import json

    world = json.loads((tmp_path / "arm" / "meta.json").read_text())["world"]
    dicestack.save_demos(episodes, tmp_path / "again", world=world)
    for a, b in zip(episodes, dicestack.load_demos(tmp_path / "again")):
        for field in ("link_angles", "link_rates", "joint_torques", "final_link_angles", "final_link_rates"):
            assert np.array_equal(getattr(a, field), getattr(b, field))
    with pytest.raises(ValueError, match="link_angles and link_rates go together"):
        dicestack.save_demos([dicestack.Episode(np.zeros((1, 24)), np.zeros((1, 3)), link_angles=np.zeros((1, 3)))],
                             tmp_path / "bad")
    assert all(e.link_angles is None for e in dicestack.load_demos("builtin")[:2])
    # An episode in joint torques: four columns of actions, kept as such.
    torques = dicestack.Episode(episodes[0].states[:3], np.full((3, 4), 5.0), link_angles=episodes[0].link_angles[:3],
                                link_rates=episodes[0].link_rates[:3])
    dicestack.save_demos([torques], tmp_path / "torques", world=world)
    (back,) = dicestack.load_demos(tmp_path / "torques")
    assert back.actions.shape == (3, 4) and np.all(back.actions == 5.0) and back.joint_torques is None
