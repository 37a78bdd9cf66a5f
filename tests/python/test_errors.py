"""Bad arguments raise Python exceptions with the command line's messages; nothing crashes."""
import numpy as np
import pytest

import dicestack


@pytest.fixture
def started():
    env = dicestack.DiceStackEnv()
    env.reset(seed=0)
    return env


@pytest.mark.parametrize("action, message", [
    (np.zeros(2), r"action must have shape \(3,\), got shape \(2,\)"),
    (np.zeros((1, 3)), r"got shape \(1, 3\)"),
    ([np.nan, 0, 0], "element 0 is NaN"),
    (["a", "b", "c"], "action must be numbers"),
])
def test_bad_actions(started, action, message):
    with pytest.raises(ValueError, match=message):
        started.step(action)


def test_step_before_reset():
    with pytest.raises(RuntimeError, match="before calling reset"):
        dicestack.DiceStackEnv().step(np.zeros(3))


def test_bad_world_dict_field():
    world = dicestack.default_world()
    world["physics"]["substeps"] = 0
    with pytest.raises(ValueError) as e:
        dicestack.DiceStackEnv(world=world)
    assert str(e.value) == 'world config <dict>: field "physics.substeps" must be in [1, 1000], got 0'
    world = dicestack.default_world()
    world["physics"]["bogus"] = 1
    with pytest.raises(ValueError, match='"physics.bogus" is not a world config field'):
        dicestack.DiceStackEnv(world=world)
    del world["physics"]
    with pytest.raises(ValueError, match="is missing"):
        dicestack.DiceStackEnv(world=world)
    with pytest.raises(TypeError):
        dicestack.DiceStackEnv(world=3)


def test_missing_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.dsm: cannot open for reading: No such file or directory"):
        dicestack.load_model(tmp_path / "missing.dsm")
    with pytest.raises(FileNotFoundError, match="missing.json: cannot open for reading: No such file or directory"):
        dicestack.DiceStackEnv(world=tmp_path / "missing.json")
    (tmp_path / "folder.dsm").mkdir()
    with pytest.raises(ValueError, match="folder.dsm: read failed: Is a directory"):
        dicestack.load_model(tmp_path / "folder.dsm")


def test_damaged_model_file(tmp_path):
    path = tmp_path / "bad.dsm"
    path.write_text("not a model\n")
    with pytest.raises(ValueError, match="bad.dsm"):
        dicestack.load_model(path)


def test_bad_names_and_settings(builtin_episodes):
    few = builtin_episodes[:5]
    with pytest.raises(ValueError, match='unknown regressor "nope"; registered: gbt, knn'):
        dicestack.train("nope", demos=few)
    with pytest.raises(ValueError, match='unknown learner "nope"'):
        dicestack.train("knn", learner="nope", demos=few)
    with pytest.raises(ValueError, match="k"):
        dicestack.train("knn", demos=few, params={"k": -1})
    with pytest.raises(ValueError, match="split"):
        dicestack.train("knn", demos=few, split="rows")
    with pytest.raises(ValueError, match='unknown expert "nope"'):
        dicestack.expert("nope")
    with pytest.raises(TypeError):
        dicestack.expert("scripted")(object())


def test_bad_seeds_and_counts(started, builtin_episodes):
    with pytest.raises(ValueError, match="seed"):
        started.reset(seed=-1)
    with pytest.raises(ValueError, match="seed"):
        started.reset(seed=2**64)
    with pytest.raises(TypeError, match="seed"):
        started.reset(seed=1.5)
    model = dicestack.train("knn", demos=builtin_episodes[:5])
    with pytest.raises(ValueError, match="episodes"):
        dicestack.evaluate(model, episodes=0)
    with pytest.raises(ValueError, match="initial push"):
        dicestack.evaluate(model, episodes=1, initial_push="up")
    with pytest.raises(ValueError, match=r"shape \(N, 24\)"):
        model.predict(np.zeros((2, 23)))
    with pytest.raises(ValueError, match="observation"):
        model.policy().act(np.zeros(5))


@pytest.mark.parametrize("threads", [-1, 1025, 10**8, 10**30, True, 2.0, "2"])
def test_thread_counts_out_of_range_are_refused_before_any_work(threads):
    with pytest.raises(ValueError, match=r"threads must be (in|a whole number in) \[0, 1024\]"):
        dicestack.DiceStackVectorEnv(2, threads=threads)


def test_a_perturbation_dict_names_the_field_that_is_not_a_finite_value():
    for value in (float("nan"), float("inf"), object()):
        with pytest.raises(ValueError, match='perturbation <dict>: field "gravity" must be a finite number'):
            dicestack.DiceStackEnv(perturb={"gravity": value})
    with pytest.raises(ValueError) as e:
        dicestack.DiceStackEnv(perturb={"friction": [float("nan")] * 100000})
    assert len(str(e.value)) < 200, "a long value is not echoed whole"


def test_demos_that_are_not_recordings_say_what_they_are():
    with pytest.raises(TypeError, match="demos must be .*, got int"):
        dicestack.expert("tracker", demos=42)
    with pytest.raises(TypeError, match="item 1 is a str"):
        dicestack.train("knn", demos=[dicestack.load_demos("builtin")[0], "x"])


def test_training_on_no_episode_names_the_demonstrations():
    with pytest.raises(ValueError, match="<episodes from Python>: no episode to train on"):
        dicestack.train("knn", demos=[], split="none")


def test_an_overlong_value_is_cut_in_the_message(builtin_episodes):
    # A value far longer than any name is shown by its start and end, not in full.
    with pytest.raises(ValueError) as e:
        dicestack.train("knn", demos=builtin_episodes[:2], features="state+" + "v" * 1_000_000)
    assert len(str(e.value)) < 2000 and "characters cut]..." in str(e.value)
