"""Training, models, policies and evaluation from Python: the command line's code paths, with
the same results as the command line."""
import json
import subprocess

import numpy as np
import pytest

import dicestack
from conftest import short_world


@pytest.fixture(scope="module")
def few(builtin_episodes):
    return builtin_episodes[:10]


@pytest.fixture(scope="module")
def knn(few):
    return dicestack.train("knn", demos=few, params={"k": 2})


def test_train_bc_returns_a_model(knn):
    assert knn.regressor == "knn" and knn.params["k"] == "2"
    assert knn.features == "state" and knn.input_dim == 24 and len(knn.input_names) == 24
    assert knn.record["learner"] == "bc" and knn.record["split"] == "episodes"
    assert knn.training["train_error"] >= 0 and knn.training["test_error"] > 0
    assert knn.path is None


def test_predict_and_policy_agree(knn, few):
    states = few[0].states[:20]
    predicted = knn.predict(states)
    assert predicted.shape == (20, 3) and predicted.dtype == np.float64
    policy = knn.policy()
    policy.reset(seed=0)
    np.testing.assert_array_equal(policy.act(states[0]), predicted[0])
    assert policy.t == 0


def test_policy_keeps_the_history_its_feature_map_reads(few):
    model = dicestack.train("knn", demos=few, features="state+clock", split="none")
    assert model.features == "state+clock" and model.input_dim == 25
    states = few[1].states[:15]
    rows = np.column_stack([states, np.arange(len(states))])
    expected = model.predict(rows)
    policy = model.policy()
    acted = np.array([policy(s) for s in states])
    np.testing.assert_array_equal(acted, expected)
    policy.reset()
    np.testing.assert_array_equal(policy(states[0]), expected[0])


def test_save_load_round_trip(knn, few, tmp_path):
    path = tmp_path / "knn.dsm"
    knn.save(path)
    loaded = dicestack.load_model(path)
    assert loaded.path == str(path) and loaded.training is None
    np.testing.assert_array_equal(loaded.predict(few[2].states), knn.predict(few[2].states))


def test_train_writes_out_and_refuses_a_users_file(few, tmp_path):
    out = tmp_path / "m.dsm"
    model = dicestack.train("linear_svr", demos=few, out=out, seed=1)
    assert out.exists() and model.path == str(out)
    mine = tmp_path / "mine.txt"
    mine.write_text("not a model")
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.train("knn", demos=few, out=mine)
    assert mine.read_text() == "not a model"


def test_evaluate_reports_the_clis_keys_and_values(knn, few, tmp_path, cli):
    path = tmp_path / "knn.dsm"
    knn.save(path)
    ours = dicestack.evaluate(dicestack.load_model(path), episodes=3, seed=4)
    theirs = json.loads(subprocess.run([cli, "evaluate", "--model", str(path), "--episodes", "3", "--seed", "4",
                                        "--json"], check=True, capture_output=True, text=True).stdout)
    assert set(ours) == set(theirs)
    for key in ("episodes", "stacked_rate", "wall_contact_rate", "realistic_success_rate", "dice_in_cup_mean",
                "mean_episode_length", "model", "regressor", "features"):
        assert ours[key] == theirs[key], key


def test_evaluate_with_demos_and_threads(knn, few):
    one = dicestack.evaluate(knn, episodes=3, seed=2, threads=1, demos=few)
    two = dicestack.evaluate(knn, episodes=3, seed=2, threads=2, demos=few)
    for key in ("stacked_rate", "realistic_success_rate", "dice_in_cup_mean", "train_error", "test_error"):
        assert one[key] == two[key], key
    assert one["episodes"] == 3 and "split" in one


def test_expert_refuses_an_env_of_another_world():
    expert = dicestack.expert("mpc")
    env = dicestack.DiceStackEnv()
    env.reset(seed=0)
    expert(env)
    world = dicestack.default_world()
    world["episode"]["max_steps"] = 20
    other = dicestack.DiceStackEnv(world=world)
    other.reset(seed=0)
    with pytest.raises(ValueError, match="one expert per world"):
        expert(other)


def test_tracker_follows_the_builtin_recordings_to_a_stack():
    expert = dicestack.expert("tracker", demos="builtin")
    assert expert.name == "tracker"
    env = dicestack.DiceStackEnv()
    env.reset(seed=3)
    for _ in range(env.world["episode"]["max_steps"]):
        _, _, terminated, truncated, info = env.step(expert(env))
        if terminated or truncated:
            break
    assert terminated and info["realistic_success"] and not info["wall_contact"]


def test_tracker_tries_again_after_a_failed_attempt_when_asked_to():
    # A knock at step 20 makes the path chosen at the start fail; with retry=True the tracker
    # chooses again once the failure has come to rest, and stacks before the time limit.
    few = dicestack.load_demos("human")[:8]

    def episode(retry):
        expert = dicestack.expert("tracker", demos=few, retry=retry)
        env = dicestack.DiceStackEnv()
        env.reset(seed=10)
        for t in range(env.world["episode"]["max_steps"]):
            action = np.array([0.3, 0.0, 0.0]) if t == 20 else expert(env)
            _, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
        return info["realistic_success"], t

    once, once_steps = episode(False)
    again, again_steps = episode(True)
    assert not once and once_steps == 399
    assert again and 200 < again_steps < 399, "a second attempt, in time"
    with pytest.raises(TypeError, match="retry must be True or False"):
        dicestack.expert("mpc", retry="yes")


def test_tracker_needs_recordings_and_the_others_read_none():
    with pytest.raises(ValueError, match="give them with demos="):
        dicestack.expert("tracker")
    with pytest.raises(ValueError, match="reads no demonstrations|no recordings|demos"):
        dicestack.expert("mpc", demos="builtin")


def test_the_trackers_preset_and_settings_go_by_the_learners_names(builtin_episodes):
    # The tracker of record and robustness is "plain"; the learners' is "distill"; settings on top.
    few = builtin_episodes[:3]
    settings = {"smooth": 2, "probes": 2, "variants": False, "refine": 0}
    expert = dicestack.expert("tracker", demos=few, preset="distill", settings=settings)
    env = dicestack.DiceStackEnv()
    env.reset(seed=3)
    assert len(expert(env)) == 3
    with pytest.raises(ValueError, match='tracker setting "smoth": unknown; settings: probes'):
        dicestack.expert("tracker", demos=few, settings={"smoth": 2})
    with pytest.raises(ValueError, match='tracker preset "tuned": unknown; presets: plain, distill'):
        dicestack.expert("tracker", demos=few, preset="tuned")
    with pytest.raises(ValueError, match="has no tracker settings"):
        dicestack.expert("mpc", settings={"smooth": 2})


@pytest.mark.parametrize("target", ["osc", "torque"])
def test_a_torque_policy_reads_the_arms_links_beside_each_observation(target):
    world = short_world(30)
    world["embodiment"] = "arm"
    recordings = dicestack.load_demos("human")[:2]
    options = {"expert": "tracker", "episodes": 2, "successes_only": False, "tracker_probes": 1, "tracker_robust": 1,
               "tracker_variants": False, "tracker_refine": 0}
    model = dicestack.train("knn", "dart", demos=recordings, options=options, world=world,
                            features="state+links+clock+start_state@dice+retry/" + target, params={"k": 1})
    assert "train_error" not in model.training  # the recordings hold cup actions: nothing to score
    assert model.predict(np.zeros((2, model.input_dim))).shape == (2, 4)  # torques, or the pose and the posture
    env = dicestack.DiceStackEnv(world=world, controller="joint_torque")
    obs, info = env.reset(seed=3)
    policy = model.policy()
    action = policy.act(obs, link_angles=info["link_angles"], link_rates=info["link_rates"])
    assert action.shape == (4,)
    obs, _, _, _, info = env.step(action)
    assert policy.act(obs, link_angles=info["link_angles"], link_rates=info["link_rates"]).shape == (4,)
    with pytest.raises(ValueError, match="give link_angles and link_rates"):
        model.policy().act(obs)
