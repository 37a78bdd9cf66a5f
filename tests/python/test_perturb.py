"""Perturbed worlds from Python: DiceStackEnv(perturb=...), the reset option, the
vector env's per-environment draws, evaluate(perturb=...), and bad perturbations refused."""
import json

import numpy as np
import pytest

import dicestack
from conftest import random_actions, short_world

DRAW_KEYS = {"dice_friction", "cup_friction", "walls_friction", "dice_mass", "cup_segment_mass", "gravity_y",
             "action_bias", "action_noise_std", "action_delay", "observation_noise_std", "observation_delay",
             "start_shift", "start_cup_lift", "start_cup_tilt", "noise_seed"}


def episode(env, seed, actions, options=None):
    obs, info = env.reset(seed=seed, options=options)
    observations, states = [obs], [env.state]
    for a in actions:
        obs, *_ = env.step(a)
        observations.append(obs)
        states.append(env.state)
    return np.array(observations), np.array(states), info


def test_none_is_the_nominal_world_exactly(rng):
    actions = random_actions(rng, 30)
    plain = episode(dicestack.DiceStackEnv(), 4, actions)
    none = episode(dicestack.DiceStackEnv(perturb="none"), 4, actions)
    assert np.array_equal(plain[0], none[0]) and "perturbation" not in none[2]


def test_a_perturbed_episode_reports_its_draw_and_hides_the_true_state(rng):
    env = dicestack.DiceStackEnv(perturb="hard")
    observations, states, info = episode(env, 7, random_actions(rng, 20))
    assert set(info["perturbation"]) == DRAW_KEYS
    assert info["perturbation"]["action_delay"] == 6
    assert not np.array_equal(observations, states)  # sensing noise and delay: the policy sees another state
    again = episode(dicestack.DiceStackEnv(perturb="hard"), 7, random_actions(np.random.default_rng(1234), 20))
    other = dicestack.DiceStackEnv(perturb="hard").reset(seed=8)[1]["perturbation"]
    assert info["perturbation"] != other  # each episode its own draw
    assert json.dumps(info["perturbation"]) == json.dumps(dicestack.DiceStackEnv(perturb="hard").reset(seed=7)[1]["perturbation"])
    assert again[2]["perturbation"] == info["perturbation"]


def test_the_reset_option_perturbs_one_episode(rng):
    actions = random_actions(rng, 25)
    env = dicestack.DiceStackEnv()
    perturbed = episode(env, 2, actions, options={"perturb": {"friction": 0.6, "dice_mass": 0.8}})
    assert perturbed[2]["perturbation"]["dice_mass"] != dicestack.default_world()["dice"]["mass"]
    after = episode(env, 2, actions)
    fresh = episode(dicestack.DiceStackEnv(), 2, actions)
    assert np.array_equal(after[1], fresh[1]) and not np.array_equal(perturbed[1], fresh[1])


def test_the_vector_env_gives_each_environment_its_own_draw(rng):
    world = short_world(30)
    actions = random_actions(rng, 12)
    vec = dicestack.DiceStackVectorEnv(3, world=world, perturb="medium", threads=2)
    obs, _ = vec.reset(seed=[11, 12, 13])
    rows = [obs]
    for a in actions:
        rows.append(vec.step(np.tile(a, (3, 1)))[0])
    rows = np.array(rows)
    for i, seed in enumerate([11, 12, 13]):
        one = episode(dicestack.DiceStackEnv(world=world, perturb="medium"), seed, actions)[0]
        assert np.array_equal(rows[:, i], one)
    assert not np.array_equal(rows[:, 0], rows[:, 1])


def test_drawn_delays_give_each_episode_its_own_delay():
    env = dicestack.DiceStackEnv(perturb={"action_delay": 3, "delays_drawn": True})
    delays = [env.reset(seed=s)[1]["perturbation"]["action_delay"] for s in range(40)]
    assert set(delays) == {0, 1, 2, 3}
    assert env.reset(seed=5)[1]["perturbation"]["action_delay"] == delays[5]


@pytest.mark.parametrize("perturb, message", [
    ("extreme", "none, easy, medium, hard"),
    ({"friction": 1.5}, "\"friction\""),
    ({"action_delay": 1000}, "\"action_delay\""),
    ({"wind": 0.1}, "unknown field \"wind\""),
    ({"delays_drawn": True}, "\"delays_drawn\" draws each episode's delays"),
])
def test_bad_perturbations_are_refused_naming_the_field(perturb, message):
    with pytest.raises(ValueError, match=message.replace('"', '.')):
        dicestack.DiceStackEnv(perturb=perturb)
    env = dicestack.DiceStackEnv()
    with pytest.raises(ValueError, match=message.replace('"', '.')):
        env.reset(seed=0, options={"perturb": perturb})


def test_snapshots_refuse_perturbed_sensing_but_keep_perturbed_physics():
    env = dicestack.DiceStackEnv(perturb={"dice_mass": 0.5})
    env.reset(seed=1)
    env.restore(env.snapshot())
    env = dicestack.DiceStackEnv(perturb={"action_delay": 2})
    env.reset(seed=1)
    with pytest.raises(ValueError, match="perturbed"):
        env.snapshot()


def test_evaluate_takes_a_perturbation(builtin_episodes):
    model = dicestack.train("knn", demos=builtin_episodes[:2], params={"k": 1}, split="none")
    world = short_world(40)
    nominal = dicestack.evaluate(model, 3, seed=1, world=world, threads=1)
    none = dicestack.evaluate(model, 3, seed=1, world=world, threads=1, perturb="none")
    hard = dicestack.evaluate(model, 3, seed=1, world=world, threads=1, perturb="hard")
    assert "perturb" not in nominal and hard["perturb"] == "hard"
    for key in ("dice_in_cup_mean", "realistic_success_rate", "stacked_rate"):
        assert nominal[key] == none[key]


def test_the_leaderboard_rolls_out_in_perturbed_worlds(builtin_episodes, tmp_path):
    demos = tmp_path / "demos"
    dicestack.save_demos(builtin_episodes[:3], demos)
    args = dict(regressors=["knn"], learners=["bc"], demos=demos, episodes=2, seed=3, threads=1, progress=False)
    nominal = dicestack.leaderboard(**args)
    none = dicestack.leaderboard(perturb="none", **args)
    for key in ("dice_in_cup_mean", "wall_contact", "realistic_success"):
        assert [r[key] for r in nominal] == [r[key] for r in none]
    dicestack.leaderboard(perturb="hard", **args)
    with pytest.raises(ValueError, match="none, easy, medium, hard"):
        dicestack.leaderboard(perturb="sideways", **args)
    dicestack.leaderboard(perturb="hard", estimator="kalman", **args)
    with pytest.raises(ValueError, match="none, kalman"):
        dicestack.leaderboard(perturb="hard", estimator="particles", **args)


def test_evaluate_shows_the_policy_the_estimate(builtin_episodes):
    model = dicestack.train("knn", demos=builtin_episodes[:2], params={"k": 1}, split="none")
    world = short_world(40)
    args = dict(world=world, threads=1, perturb={"observation_delay": 2})
    raw = dicestack.evaluate(model, 3, seed=1, **args)
    estimated = dicestack.evaluate(model, 3, seed=1, estimator="kalman", **args)
    assert "estimator" not in raw and estimated["estimator"] == "kalman"
    nominal = dicestack.evaluate(model, 3, seed=1, world=world, threads=1)
    for key in ("dice_in_cup_mean", "realistic_success_rate", "stacked_rate", "mean_episode_length"):
        assert estimated[key] == nominal[key]  # a delay in the nominal world is made up exactly
    plain = dicestack.evaluate(model, 3, seed=1, world=world, threads=1, estimator="kalman")
    for key in ("dice_in_cup_mean", "realistic_success_rate", "stacked_rate"):
        assert nominal[key] == plain[key]  # no sensing factor: the estimator is not used
    own = dicestack.evaluate(model, 3, seed=1, estimator=None, **args)  # the model's own: it names none
    assert "estimator" not in own and own["dice_in_cup_mean"] == raw["dice_in_cup_mean"]
    with pytest.raises(TypeError, match="estimator"):
        dicestack.evaluate(model, 3, estimator=3, **args)


def test_an_expert_acts_through_the_action_delay_and_stacks():
    env = dicestack.DiceStackEnv(perturb={"action_delay": 3})
    env.reset(seed=2)
    assert env.pending.shape == (3, 3) and not env.pending.any()
    assert env.unseen.shape == (0, 3)
    expert = dicestack.expert("mpc")
    chosen, done, info = [], False, {}
    while not done:
        chosen.append(expert(env))
        _, _, terminated, truncated, info = env.step(chosen[-1])
        done = terminated or truncated
        if not done and len(chosen) >= 3:
            assert np.array_equal(env.pending, np.array(chosen[-3:])), "the last three choices, in order"
    assert info["realistic_success"], "a one-step-late controller that does not predict hits a wall"


def test_a_policy_on_an_ahead_map_reads_what_is_pending(builtin_episodes):
    model = dicestack.train("knn", demos=builtin_episodes[:2], features="state+clock/ahead", params={"k": 1},
                            split="none")
    assert dicestack.DiceStackEnv().pending.shape == (0, 3)
    env = dicestack.DiceStackEnv(perturb={"action_delay": 2, "observation_delay": 1})
    obs, _ = env.reset(seed=1)
    reading, blind = model.policy(), model.policy()
    differ = 0
    for _ in range(15):
        assert env.unseen.shape[0] <= 1
        a = reading.act(obs, pending=env.pending, unseen=env.unseen)
        differ += not np.array_equal(a, blind.act(obs))
        obs, *_ = env.step(a)
    assert differ > 0
    with pytest.raises(ValueError, match="pending"):
        model.policy().act(obs, pending=np.zeros((2, 4)))
    with pytest.raises(ValueError, match=r"unseen\[0\]\[1\] must be finite"):
        model.policy().act(obs, unseen=np.array([[0.0, np.nan, 0.0]]))


def test_the_vector_env_shows_each_environments_pending_actions():
    vec = dicestack.DiceStackVectorEnv(3, perturb={"action_delay": 2, "observation_delay": 1}, threads=1)
    vec.reset(seed=5)
    assert [p.shape for p in vec.pending] == [(2, 3)] * 3 and not any(p.any() for p in vec.pending)
    actions = np.array([[0.1, 0.0, 0.0], [0.2, 0.0, 0.0], [0.3, 0.0, 0.0]])
    vec.step(actions)
    for i, p in enumerate(vec.pending):
        assert np.array_equal(p[-1], actions[i]), "each environment's last choice runs last"
    assert [u.shape for u in vec.unseen] == [(1, 3)] * 3
    nominal = dicestack.DiceStackVectorEnv(2, threads=1)
    nominal.reset(seed=1)
    assert [p.shape for p in nominal.pending] == [(0, 3)] * 2


def test_the_estimator_shows_an_estimate_nearer_the_state_under_a_delay(rng):
    actions = random_actions(rng, 40)
    raw = episode(dicestack.DiceStackEnv(perturb={"observation_delay": 3}), 5, actions)
    estimated = episode(dicestack.DiceStackEnv(perturb={"observation_delay": 3}, estimator="kalman"), 5, actions)
    assert np.array_equal(raw[1], estimated[1])  # the same episode: the estimator changes what is shown, not what runs
    assert np.abs(estimated[0] - estimated[1]).mean() < 0.2 * np.abs(raw[0] - raw[1]).mean()
    nominal = episode(dicestack.DiceStackEnv(estimator="kalman"), 5, actions)
    assert np.array_equal(nominal[0], nominal[1])  # no sensing factor: the state itself
    vec = dicestack.DiceStackVectorEnv(2, perturb={"observation_delay": 3}, estimator="kalman", threads=1)
    obs, _ = vec.reset(seed=[5, 6])
    single, _ = dicestack.DiceStackEnv(perturb={"observation_delay": 3}, estimator="kalman").reset(seed=5)
    assert np.array_equal(obs[0], single)
    for a in actions[:10]:
        obs, *_ = vec.step(np.array([a, a]))
    assert np.array_equal(obs[0], estimated[0][10])  # as the single environment shows it


@pytest.mark.parametrize("estimator, error", [("particles", ValueError), (3, TypeError), ("x" * 100000, ValueError)])
def test_a_bad_estimator_is_refused(estimator, error):
    with pytest.raises(error) as caught:
        dicestack.DiceStackEnv(estimator=estimator)
    assert len(str(caught.value)) < 300


def test_the_particle_filter_runs_behind_the_env_the_same_way_each_time(rng):
    actions = random_actions(rng, 30)
    noisy = {"observation_noise": 0.05}
    raw = episode(dicestack.DiceStackEnv(perturb=noisy), 5, actions)
    first = episode(dicestack.DiceStackEnv(perturb=noisy, estimator="particle:8"), 5, actions)
    again = episode(dicestack.DiceStackEnv(perturb=noisy, estimator="particle:8"), 5, actions)
    assert np.array_equal(raw[1], first[1])  # the same episode runs
    assert np.array_equal(first[0], again[0])  # and the same estimates are shown
    assert not np.array_equal(first[0], raw[0])
    with pytest.raises(ValueError, match="from 1 to 4096"):
        dicestack.DiceStackEnv(perturb=noisy, estimator="particle:0")
    # Counts that fit one by one but not a thousand environments at once: refused before any is made.
    with pytest.raises(ValueError, match="DiceStackVectorEnv: 1000 environments would need"):
        dicestack.DiceStackVectorEnv(1000, perturb=noisy, estimator="particle:4096")
    # Each environment's estimates are its own episode's, whatever the thread count.
    shown = []
    for threads in (1, 2):
        vec = dicestack.DiceStackVectorEnv(2, perturb=noisy, estimator="particle:8", threads=threads)
        obs, _ = vec.reset(seed=[5, 6])
        steps = [obs]
        for a in actions[:10]:
            obs, *_ = vec.step(np.array([a, a]))
            steps.append(obs)
        shown.append(np.array(steps))
    assert np.array_equal(shown[0], shown[1])
    assert np.array_equal(shown[0][:, 0], first[0][:11])  # as the single environment shows it
