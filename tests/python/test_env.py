"""DiceStackEnv under the Gymnasium contract: signatures, spaces, dtypes, seeding, rendering.
Debian has no gymnasium package, so these are our own checks of what
gymnasium.utils.env_checker.check_env checks (that test runs too where gymnasium is installed)."""
import inspect

import numpy as np
import pytest

import dicestack
from conftest import random_actions, short_world

INFO_KEYS = {"t", "distance", "wall_contact_step", "dice_in_cup", "dice_in_cup_now", "stacked", "stacked_steps",
             "wall_contact", "realistic_success"}


def test_reset_and_step_signatures_are_gymnasiums():
    reset = inspect.signature(dicestack.DiceStackEnv.reset).parameters
    assert reset["seed"].kind is inspect.Parameter.KEYWORD_ONLY and reset["seed"].default is None
    assert reset["options"].kind is inspect.Parameter.KEYWORD_ONLY and reset["options"].default is None
    assert list(inspect.signature(dicestack.DiceStackEnv.step).parameters) == ["self", "action"]
    init = inspect.signature(dicestack.DiceStackEnv.__init__).parameters
    assert init["world"].default is None and init["render_mode"].default is None


def test_reset_and_step_return_gymnasium_tuples(env, rng):
    obs, info = env.reset(seed=0)
    assert isinstance(obs, np.ndarray) and obs.dtype == np.float64 and obs.shape == (24,)
    assert isinstance(info, dict) and set(info) == INFO_KEYS
    result = env.step(random_actions(rng, 1)[0])
    assert len(result) == 5
    obs, reward, terminated, truncated, info = result
    assert obs.dtype == np.float64 and obs.shape == (24,)
    assert type(reward) is float and type(terminated) is bool and type(truncated) is bool
    assert set(info) == INFO_KEYS and info["t"] == 1


def test_spaces_hold_every_observation_and_sample(env, rng):
    assert env.observation_space.shape == (24,) and env.observation_space.dtype == np.float64
    assert env.action_space.shape == (3,) and env.action_space.dtype == np.float64
    assert np.array_equal(env.action_space.low, -env.action_space.high)
    np.testing.assert_array_equal(env.action_space.high, [20.0, 20.0, 10.0])
    env.action_space.seed(3)
    for _ in range(20):
        assert env.action_space.contains(env.action_space.sample())
    obs, _ = env.reset(seed=5)
    assert env.observation_space.contains(obs)
    for action in random_actions(rng, 60):
        obs, *_ = env.step(action)
        assert env.observation_space.contains(obs)


def test_metadata_and_rgb_render(env):
    assert "rgb_array" in env.metadata["render_modes"]
    assert env.metadata["render_fps"] == 30
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (700, 900, 3) and frame.dtype == np.uint8
    assert frame.std() > 0  # a picture, not a blank
    assert dicestack.DiceStackEnv().render() is None
    with pytest.raises(ValueError, match="render_mode"):
        dicestack.DiceStackEnv(render_mode="human")


def test_same_seed_same_trajectory(rng):
    actions = random_actions(rng, 80)

    def run():
        env = dicestack.DiceStackEnv()
        steps = [env.reset(seed=42)]
        steps += [env.step(a) for a in actions]
        return steps

    a, b = run(), run()
    np.testing.assert_array_equal(a[0][0], b[0][0])
    for x, y in zip(a[1:], b[1:]):
        np.testing.assert_array_equal(x[0], y[0])
        assert x[1:] == y[1:]


def test_seeding_follows_gymnasium(env):
    obs_1, _ = env.reset(seed=123)
    obs_2, _ = env.reset()
    obs_3, _ = env.reset(seed=123)
    obs_4, _ = env.reset()
    np.testing.assert_array_equal(obs_1, obs_3)
    np.testing.assert_array_equal(obs_2, obs_4)
    assert not np.array_equal(obs_1, obs_2)
    obs_5, _ = env.reset(seed=456)
    assert not np.array_equal(obs_1, obs_5)
    assert env.np_random is not None


def test_reset_from_a_given_state(env, rng):
    start, _ = env.reset(seed=9)
    for a in random_actions(rng, 10):
        env.step(a)
    obs, info = env.reset(options={"state": start})
    np.testing.assert_array_equal(obs, start)
    assert info["t"] == 0
    with pytest.raises(ValueError, match="unknown reset option"):
        env.reset(options={"start": "paper"})


def test_a_state_outside_the_world_is_refused_naming_the_body(env):
    start, _ = env.reset(seed=3)
    far = np.array(start)
    far[:] = 1e9
    with pytest.raises(ValueError, match="the cup is beyond the walls"):
        env.reset(options={"state": far})
    inside = np.array(start)
    inside[9:12] = inside[3:6]  # die 1 where die 0 is
    with pytest.raises(ValueError, match="die 0 and die 1 overlap|die 1 and die 0 overlap"):
        env.reset(options={"state": inside})


def test_an_action_past_the_limits_is_clipped_before_the_worlds_own_noise():
    # As in the C++ rollout: the same episode as the action at the limits, noise and all.
    world = dicestack.default_world()
    world["physics"]["action_noise"] = 0.5
    far, edge = dicestack.DiceStackEnv(world=world), dicestack.DiceStackEnv(world=world)
    far.reset(seed=3)
    edge.reset(seed=3)
    limit = np.array(world["action"]["limit"], dtype=float)
    for _ in range(10):
        np.testing.assert_array_equal(far.step(limit * 100)[0], edge.step(limit)[0])
        np.testing.assert_array_equal(far.step(-limit * 100)[0], edge.step(-limit)[0])


def test_time_limit_truncates():
    env = dicestack.DiceStackEnv(world=short_world(5))
    env.reset(seed=0)
    flags = [env.step(np.zeros(3))[2:4] for _ in range(5)]
    assert flags == [(False, False)] * 4 + [(False, True)]


def test_expert_episode_terminates_with_realistic_success():
    env = dicestack.DiceStackEnv()
    expert = dicestack.expert("mpc")
    env.reset(seed=0)
    for _ in range(400):
        _, _, terminated, truncated, info = env.step(expert(env))
        if terminated or truncated:
            break
    assert terminated and info["realistic_success"] and info["stacked"] and not info["wall_contact"]


def test_scripted_expert_acts_in_the_action_space(env):
    expert = dicestack.expert("scripted")
    assert expert.name == "scripted"
    env.reset(seed=2)
    action = expert.act(env)
    assert action.shape == (3,) and action.dtype == np.float64 and env.action_space.contains(action)


def test_world_from_dict_file_and_default(tmp_path):
    world = short_world(7)
    path = tmp_path / "w.json"
    import json
    path.write_text(json.dumps(world))
    assert dicestack.DiceStackEnv(world=world).world == world
    assert dicestack.DiceStackEnv(world=path).world == world
    assert dicestack.DiceStackEnv().world == dicestack.default_world()


def test_paper_starts_are_the_papers_start_shifted_by_at_most_two_centimetres():
    env = dicestack.DiceStackEnv(start="paper")
    assert env.world["randomization"]["shift"] == 0.02 and env.world["randomization"]["cup_lift"] == 0.0
    firsts = [env.reset(seed=s)[0] for s in range(20)]
    shifts = [o[0] - firsts[0][0] for o in firsts]
    assert max(abs(s) for s in shifts) <= 0.04 + 1e-9 and len(set(shifts)) > 1
    for o in firsts:
        assert o[1] == pytest.approx(firsts[0][1]) and o[2] == pytest.approx(firsts[0][2])  # height and angle as the paper's
        assert np.allclose(o[[3, 9, 15]] - o[0], firsts[0][[3, 9, 15]] - firsts[0][0], atol=1e-6)  # the whole scene moves
    with pytest.raises(ValueError, match='unknown start distribution "papers"'):
        dicestack.DiceStackEnv(start="papers")
    with pytest.raises(TypeError, match="start must be"):
        dicestack.DiceStackEnv(start=1)


def test_context_manager_and_unwrapped(env):
    with dicestack.DiceStackEnv() as e:
        e.reset(seed=0)
    assert env.unwrapped is env


def test_gymnasium_registration_and_checker():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("dicestack/DiceStack-v0")
    check_env(env.unwrapped)


def test_the_arm_environment_runs_the_same_task_with_the_same_spaces():
    held = dicestack.DiceStackEnv(embodiment="arm")
    floating = dicestack.DiceStackEnv()
    assert held.observation_space == floating.observation_space and held.action_space == floating.action_space
    obs, _ = held.reset(seed=3)
    assert np.array_equal(obs, floating.reset(seed=3)[0])  # the same start: the arm takes the cup where it stands
    for _ in range(5):
        obs, _, terminated, truncated, _ = held.step(np.array([0.2, 0.1, 0.0]))
    assert held.observation_space.contains(obs) and not terminated and not truncated
    with pytest.raises(ValueError, match="embodiment must be 'cup' or 'arm'"):
        dicestack.DiceStackEnv(embodiment="robot")


def test_the_joint_torque_controller_takes_the_arms_four_torques():
    env = dicestack.DiceStackEnv(embodiment="arm", controller="joint_torque")
    assert env.action_space.shape == (4,) and np.all(env.action_space.high > 100.0)
    _, info = env.reset(seed=3)
    assert info["link_angles"].shape == (3,) and info["link_rates"].shape == (3,)
    held = env.action_space.high * np.array([0.0, 0.0, 0.0, 2.0])  # past the wrist's limit: clipped to it
    for _ in range(3):
        obs, _, _, _, info = env.step(held)
    assert info["joint_torques"][3] == env.action_space.high[3] and not np.any(info["joint_torques"][:3])
    with pytest.raises(ValueError, match=r"action must have shape \(4,\)"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match='needs embodiment "arm"'):
        dicestack.DiceStackEnv(controller="joint_torque")
    with pytest.raises(ValueError, match="controller must be"):
        dicestack.DiceStackEnv(embodiment="arm", controller="torque")
    # The actuation factors act on the torques: late, and noised as a fraction of each limit.
    delayed = dicestack.DiceStackEnv(embodiment="arm", controller="joint_torque", perturb={"action_delay": 2})
    delayed.reset(seed=3)
    assert delayed.pending.shape == (2, 4) and not np.any(delayed.pending)
    delayed.step(held)
    assert np.array_equal(delayed.pending[1], held * np.array([1, 1, 1, 0.5]))  # as clipped
    _, info = env.reset(seed=4, options={"perturb": {"action_noise": 0.1}})
    drawn = info["perturbation"]
    assert np.allclose(drawn["joint_torque_noise_std"], 0.1 * env.action_space.high)
    assert len(drawn["joint_torque_bias"]) == 4
    with pytest.raises(ValueError, match="particle filter"):
        dicestack.DiceStackEnv(embodiment="arm", controller="joint_torque", estimator="particle")
    # Behind the Kalman filter the policy is shown the state its torques land in, and its links.
    behind = dicestack.DiceStackEnv(embodiment="arm", controller="joint_torque", perturb={"action_delay": 2},
                                    estimator="kalman")
    _, shown = behind.reset(seed=3)
    _, now = delayed.reset(seed=3)
    assert behind.pending.shape == (0, 4)
    assert not np.array_equal(shown["link_angles"], now["link_angles"])
    late = dicestack.DiceStackEnv(embodiment="arm", controller="joint_torque", perturb={"observation_delay": 2})
    late.reset(seed=3)
    late.step(held)
    assert late.pending.shape == (0, 4) and late.unseen.shape == (1, 4)
    # The vector env steps the same episodes.
    vec = dicestack.DiceStackVectorEnv(2, embodiment="arm", controller="joint_torque")
    vec.reset(seed=3)
    assert vec.single_action_space.shape == (4,)
    env.reset(seed=3)
    assert np.array_equal(vec.step(np.tile(held, (2, 1)))[0][0], env.step(held)[0])


def test_the_arm_environment_is_registered_and_passes_the_checker():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make(dicestack.ARM_ENV_ID)
    check_env(env.unwrapped)
    check_env(gymnasium.make(dicestack.ARM_ENV_ID, controller="joint_torque").unwrapped)
