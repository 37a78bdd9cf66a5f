"""register_regressor: scikit-learn estimators (and any object with fit/predict) as regressors of
every learner; their models saved as the model file plus MODEL.pkl, read back only with
allow_pickle=True, refused by the command line."""
import subprocess

import numpy as np
import pytest

import dicestack
from conftest import short_world

pytest.importorskip("sklearn")
from sklearn.ensemble import ExtraTreesRegressor  # noqa: E402
from sklearn.tree import DecisionTreeRegressor  # noqa: E402


def _tree(max_depth=6):
    return DecisionTreeRegressor(max_depth=max_depth)


dicestack.register_regressor("test_tree", _tree, params={"max_depth": 6})
dicestack.register_regressor("test_extra_trees", lambda: ExtraTreesRegressor(n_estimators=3, max_depth=5),
                             description="three extremely randomised trees")


@pytest.fixture(scope="module")
def few(builtin_episodes):
    return builtin_episodes[:10]


@pytest.fixture(scope="module")
def tree(few):
    return dicestack.train("test_tree", learner="bc", demos=few, params={"max_depth": 4}, progress=False)


def test_a_registered_regressor_trains_under_bc(tree, few):
    assert "test_tree" in dicestack.regressor_names() and "knn" in dicestack.regressor_names()
    assert tree.regressor == "test_tree" and tree.params == {"max_depth": "4"}
    assert tree.record["learner"] == "bc"
    assert 0 <= tree.training["train_error"] and tree.training["test_error"] > 0
    predicted = tree.predict(few[0].states)
    assert predicted.shape == (len(few[0].states), 3) and np.isfinite(predicted).all()
    policy = tree.policy()
    np.testing.assert_array_equal(policy.act(few[0].states[0]), predicted[0])


def test_the_training_seed_reaches_random_state(few):
    a = dicestack.train("test_extra_trees", demos=few, seed=1, progress=False)
    b = dicestack.train("test_extra_trees", demos=few, seed=1, progress=False)
    c = dicestack.train("test_extra_trees", demos=few, seed=2, progress=False)
    x = few[3].states
    np.testing.assert_array_equal(a.predict(x), b.predict(x))
    assert not np.array_equal(a.predict(x), c.predict(x))


def test_evaluate_rolls_a_python_regressor_out_on_two_threads(tree):
    one = dicestack.evaluate(tree, episodes=2, seed=3, threads=1, world=short_world(60), progress=False)
    two = dicestack.evaluate(tree, episodes=2, seed=3, threads=2, world=short_world(60), progress=False)
    assert one["regressor"] == "test_tree" and one["episodes"] == 2
    for key in ("stacked_rate", "wall_contact_rate", "dice_in_cup_mean", "mean_episode_length"):
        assert one[key] == two[key], key


def test_dagger_queries_a_python_regressor_from_worker_threads(few):
    model = dicestack.train("test_tree", learner="dagger", demos=few, world=short_world(40), threads=2,
                            options={"iterations": 1, "rollouts": 2, "expert": "scripted"}, progress=False)
    assert model.record["learner"] == "dagger" and model.regressor == "test_tree"


def test_names_are_never_shadowed():
    with pytest.raises(ValueError, match='regressor "knn" registered twice'):
        dicestack.register_regressor("knn", _tree)
    with pytest.raises(ValueError, match='regressor "test_tree" registered twice'):
        dicestack.register_regressor("test_tree", _tree)
    with pytest.raises(TypeError, match="callable"):
        dicestack.register_regressor("test_not_callable", 3)
    with pytest.raises(TypeError, match="bool, int or float"):
        dicestack.register_regressor("test_bad_param", _tree, params={"criterion": "squared_error"})


def test_the_estimators_own_errors_reach_the_caller(few):
    class NoPredict:
        def fit(self, x, y):
            return self

    class Fails:
        def fit(self, x, y):
            raise ArithmeticError("this estimator cannot fit")

        def predict(self, x):
            return np.zeros((len(x), 3))

    class OneColumn:
        def fit(self, x, y):
            return self

        def predict(self, x):
            return np.zeros(len(x) + 1)

    dicestack.register_regressor("test_no_predict", NoPredict)
    dicestack.register_regressor("test_fails", Fails)
    dicestack.register_regressor("test_one_column", OneColumn)
    with pytest.raises(TypeError, match="no predict"):
        dicestack.train("test_no_predict", demos=few, progress=False)
    with pytest.raises(ArithmeticError, match="cannot fit"):
        dicestack.train("test_fails", demos=few, progress=False)
    with pytest.raises(ValueError, match="MultiOutputRegressor"):
        dicestack.train("test_one_column", demos=few, progress=False)
    with pytest.raises(ValueError, match='unknown parameter "depth"'):
        dicestack.train("test_tree", demos=few, params={"depth": 3}, progress=False)


def test_save_writes_the_pickle_and_load_needs_allow_pickle(tree, few, tmp_path):
    path = tmp_path / "tree.dsm"
    tree.save(path)
    assert path.exists() and (tmp_path / "tree.dsm.pkl").exists()
    with pytest.raises(ValueError, match=r"pickled in .*tree\.dsm\.pkl.*unpickling runs code.*allow_pickle=True"):
        dicestack.load_model(path)
    loaded = dicestack.load_model(path, allow_pickle=True)
    assert loaded.regressor == "test_tree" and loaded.params == {"max_depth": "4"}
    np.testing.assert_array_equal(loaded.predict(few[2].states), tree.predict(few[2].states))
    # Saved again (over its own files), and evaluated as a loaded model.
    loaded.save(path)
    assert dicestack.evaluate(loaded, episodes=1, world=short_world(30), progress=False)["episodes"] == 1


def test_train_out_writes_both_files(few, tmp_path):
    out = tmp_path / "out.dsm"
    model = dicestack.train("test_tree", demos=few, out=out, progress=False)
    assert model.path == str(out) and (tmp_path / "out.dsm.pkl").exists()
    loaded = dicestack.load_model(out, allow_pickle=True)
    np.testing.assert_array_equal(loaded.predict(few[1].states), model.predict(few[1].states))


def test_a_pickle_that_is_not_ours_is_never_replaced_or_read(tree, tmp_path):
    path = tmp_path / "m.dsm"
    mine = tmp_path / "m.dsm.pkl"
    mine.write_bytes(b"my own pickle")
    with pytest.raises(ValueError, match="refusing to replace"):
        tree.save(path)
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.train("test_tree", demos="builtin", out=path, progress=False)
    assert mine.read_bytes() == b"my own pickle" and not path.exists()
    # A pickle swapped for another model's is refused when loading.
    other = tmp_path / "other.dsm"
    tree.save(other)
    data = bytearray((tmp_path / "other.dsm.pkl").read_bytes())
    data[-2] ^= 1
    (tmp_path / "other.dsm.pkl").write_bytes(bytes(data))
    with pytest.raises(ValueError, match="does not match the model file"):
        dicestack.load_model(other, allow_pickle=True)


def test_a_builtin_model_over_a_python_one_removes_its_pickle(tree, few, tmp_path):
    path = tmp_path / "m.dsm"
    tree.save(path)
    dicestack.train("knn", demos=few, params={"k": 2}, progress=False).save(path)
    assert not (tmp_path / "m.dsm.pkl").exists()
    assert dicestack.load_model(path).regressor == "knn"


def test_the_command_line_refuses_a_pickled_model(tree, tmp_path, cli):
    path = tmp_path / "tree.dsm"
    tree.save(path)
    p = subprocess.run([cli, "evaluate", "--model", str(path), "--episodes", "1"], capture_output=True, text=True)
    assert p.returncode == 1
    assert "dicestack: error:" in p.stderr and "pickled in" in p.stderr
    assert "unpickling runs code" in p.stderr and "never from the command line" in p.stderr
    assert "Traceback" not in p.stderr and len(p.stderr) < 600
