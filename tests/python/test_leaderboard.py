"""dicestack.leaderboard(): the command line's leaderboard (one library function builds both),
with Python regressors as rows of their own, returned as dicts and written in the same formats."""
import json
import subprocess

import pytest

import dicestack

pytest.importorskip("sklearn")
from sklearn.neighbors import KNeighborsRegressor  # noqa: E402

dicestack.register_regressor("test_sk_knn", lambda: KNeighborsRegressor(n_neighbors=2, algorithm="kd_tree"))

TIMES = ("fit_s", "us_per_step")


@pytest.fixture(scope="module")
def demos(builtin_episodes, tmp_path_factory):
    path = tmp_path_factory.mktemp("lb") / "demos"
    dicestack.save_demos(builtin_episodes[:10], path)
    return path


@pytest.fixture(scope="module")
def rows(demos):
    return dicestack.leaderboard(["knn", "test_sk_knn"], ["bc"], demos, episodes=2, seed=4, progress=False)


def test_rows_are_dicts_with_the_json_tables_keys(rows):
    assert [(r["regressor"], r["learner"]) for r in rows] == [
        ("knn", "bc"), ("test_sk_knn", "bc"), ("(demonstrations)", "playback")]
    for key in ("features", "train_error", "test_error", "dice_in_cup_mean", "episodes", "stacked", "wall_contact",
                "realistic_success", "stacked_rate", "stacked_ci95", "realistic_success_rate", "fit_s", "us_per_step"):
        assert key in rows[0], key
    assert rows[0]["episodes"] == 2 and rows[1]["episodes"] == 2
    assert rows[2]["train_error"] == -1 and rows[2]["episodes"] == 10
    assert rows[1]["test_error"] > 0


def test_the_same_rows_as_the_command_line(rows, demos, cli):
    p = subprocess.run([cli, "leaderboard", "--demos", str(demos), "--regressors", "knn", "--learners", "bc",
                        "--episodes", "2", "--seed", "4", "--format", "json"], check=True, capture_output=True, text=True)
    theirs = json.loads(p.stdout)["rows"]
    ours = [r for r in rows if r["regressor"] != "test_sk_knn"]
    assert len(ours) == len(theirs)
    for a, b in zip(ours, theirs):
        assert {k: v for k, v in a.items() if k not in TIMES} == {k: v for k, v in b.items() if k not in TIMES}


def test_writes_the_command_lines_formats_and_refuses_a_users_file(demos, tmp_path):
    out = tmp_path / "board.csv"
    rows = dicestack.leaderboard(["knn"], ["bc"], demos, episodes=1, out=out, progress=False)
    lines = out.read_text().splitlines()
    assert lines[0].startswith("regressor,learner,features,train_error") and len(lines) == 1 + len(rows)
    md = tmp_path / "board.md"
    dicestack.leaderboard(["knn"], ["bc"], demos, episodes=1, out=md, progress=False)
    assert md.read_text().startswith("<!-- dicestack leaderboard -->\n")
    assert "| knn | bc |" in md.read_text()
    assert not (tmp_path / "board.md.partial.json").exists()
    mine = tmp_path / "mine.md"
    mine.write_text("my notes")
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.leaderboard(["knn"], ["bc"], demos, episodes=1, out=mine, progress=False)
    assert mine.read_text() == "my notes"


def test_bad_arguments_raise(demos):
    with pytest.raises(ValueError, match='unknown learner "nope"'):
        dicestack.leaderboard(["knn"], ["nope"], demos, progress=False)
    with pytest.raises(ValueError, match='unknown regressor "nope"'):
        dicestack.leaderboard(["nope"], ["bc"], demos, progress=False)
    with pytest.raises(ValueError, match="profile"):
        dicestack.leaderboard(["knn"], ["bc"], demos, profile="slow", progress=False)
    with pytest.raises(ValueError, match="episodes"):
        dicestack.leaderboard(["knn"], ["bc"], demos, episodes=0, progress=False)
    with pytest.raises(FileNotFoundError):
        dicestack.leaderboard(["knn"], ["bc"], demos / "missing", progress=False)
    with pytest.raises(ValueError, match='"episodes" expects an integer'):
        dicestack.leaderboard(["knn"], ["bc", "dart"], demos, options={"episodes": "abc"}, progress=False)
    with pytest.raises(ValueError, match='has an option "iterations"'):
        dicestack.leaderboard(["knn"], ["bc"], demos, options={"iterations": 3}, progress=False)
    # Rows in joint torques need the arm, and bc a set recorded on it in them.
    with pytest.raises(ValueError, match="controller must be"):
        dicestack.leaderboard(["knn"], ["dart"], demos, controller="torque", progress=False)
    with pytest.raises(ValueError, match="--embodiment arm"):
        dicestack.leaderboard(["knn"], ["dart"], demos, controller="joint_torque", progress=False)
    with pytest.raises(ValueError, match="--learners dart:expert=tracker"):
        dicestack.leaderboard(["knn"], ["bc"], demos, embodiment="arm", controller="joint_torque", progress=False)
