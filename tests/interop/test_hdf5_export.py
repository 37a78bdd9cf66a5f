"""The HDF5 exports read with h5py, as robomimic's and Minari's readers read them: the documented
shapes, dtypes and attributes, actions within [-1, 1], masks from the episode split.

Run by CTest (Python.hdf5_export) with the dicestack executable in DICESTACK_EXE."""
import json
import os
import subprocess

import h5py
import numpy as np
import pytest

EXE = os.environ.get("DICESTACK_EXE", "dicestack")
SOURCE = os.environ.get("DICESTACK_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
OBS_KEYS = ["cup_pose", "cup_vel", "die0_pose", "die0_vel", "die1_pose", "die1_vel", "die2_pose", "die2_vel"]
STATE_INDEX = {"cup_pose": [0, 1, 2], "cup_vel": [21, 22, 23]}
for _i in range(3):
    STATE_INDEX[f"die{_i}_pose"] = [3 + 6 * _i + k for k in range(3)]
    STATE_INDEX[f"die{_i}_vel"] = [6 + 6 * _i + k for k in range(3)]


def run(*args, check=True):
    p = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, timeout=240)
    if check and p.returncode != 0:
        raise AssertionError(f"dicestack {' '.join(map(str, args))} failed ({p.returncode}): {p.stderr}")
    return p


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Seven scripted-expert episodes (a short time limit), written by `dicestack record`."""
    root = tmp_path_factory.mktemp("hdf5")
    world = json.loads(run("config").stdout)
    world["episode"]["max_steps"] = 50
    (root / "world.json").write_text(json.dumps(world))
    run("record", "--expert", "scripted", "--episodes", 7, "--seed", 3, "--threads", 1,
        "--world", root / "world.json", "--out", root / "demos")
    return root


@pytest.fixture(scope="module")
def robomimic_file(recorded):
    out = recorded / "demos.hdf5"
    run("dataset", "export", recorded / "demos", "--format", "robomimic", "--out", out)
    return out


@pytest.fixture(scope="module")
def minari_dir(recorded):
    out = recorded / "minari"
    run("dataset", "export", recorded / "demos", "--format", "minari", "--out", out)
    return out


def test_robomimic_layout(robomimic_file, recorded):
    meta = json.loads((recorded / "demos" / "meta.json").read_text())
    with h5py.File(robomimic_file, "r") as f:
        data = f["data"]
        demos = sorted(data.keys(), key=lambda k: int(k[5:]))
        assert demos == [f"demo_{i}" for i in range(7)]
        env = json.loads(data.attrs["env_args"])
        assert env["env_name"] == "dicestack/DiceStack-v0"
        assert env["type"] == 2
        assert env["env_kwargs"]["world"]["episode"]["max_steps"] == 50
        limits = np.array(env["action_limits"])
        assert limits.tolist() == env["env_kwargs"]["world"]["action"]["limit"]
        total = 0
        for i, name in enumerate(demos):
            g = data[name]
            steps = meta["episodes"][i]["steps"]
            assert g.attrs["num_samples"] == steps
            total += steps
            assert g["actions"].shape == (steps, 3) and g["actions"].dtype == np.float64
            assert np.all(g["actions"][()] >= -1.0) and np.all(g["actions"][()] <= 1.0)
            assert g["states"].shape == (steps, 24)
            assert g["rewards"].shape == (steps,)
            assert np.all(g["rewards"][()] <= 0.0)  # minus a distance
            assert g["dones"].shape == (steps,)
            assert g["dones"][()].tolist() == [0] * (steps - 1) + [1]
            states = g["states"][()]
            for key in OBS_KEYS:
                assert g["obs"][key].shape == (steps, 3)
                assert g["next_obs"][key].shape == (steps, 3)
                np.testing.assert_array_equal(g["obs"][key][()], states[:, STATE_INDEX[key]])
                np.testing.assert_array_equal(g["next_obs"][key][:-1], states[1:, STATE_INDEX[key]])
            # The world-unit actions divided by the limits are the actions.
            np.testing.assert_allclose(g["dicestack/actions"][()] / limits, g["actions"][()], rtol=0, atol=1e-15)
            np.testing.assert_array_equal(g["next_obs"]["cup_pose"][-1], meta["episodes"][i]["final_state"][:3])
        assert data.attrs["total"] == total
        train = sorted(x.decode("utf-8") for x in np.array(f["mask/train"]))
        valid = sorted(x.decode("utf-8") for x in np.array(f["mask/valid"]))
        assert valid == ["demo_4"]  # episode i is a test episode when i % 5 == 4
        assert sorted(train + valid) == sorted(demos)


def test_minari_layout(minari_dir, recorded):
    meta = json.loads((recorded / "demos" / "meta.json").read_text())
    m = json.loads((minari_dir / "data" / "metadata.json").read_text())
    assert m["data_format"] == "hdf5"
    assert m["minari_version"] == "0.5.3"
    assert m["total_episodes"] == 7
    assert m["total_steps"] == sum(e["steps"] for e in meta["episodes"])
    assert m["dataset_id"] == "dicestack/demos-v0"
    obs_space = json.loads(m["observation_space"])  # Python's json reads its Infinity
    assert obs_space["type"] == "Box" and obs_space["shape"] == [24] and obs_space["dtype"] == "float64"
    assert np.isinf(obs_space["high"][2])
    act_space = json.loads(m["action_space"])
    assert act_space["shape"] == [3] and act_space["high"] == [20.0, 20.0, 10.0]
    # Gymnasium's EnvSpec.to_json, which minari's recover_environment() makes with gymnasium.make.
    spec = json.loads(m["env_spec"])
    assert spec["id"] == "dicestack/DiceStack-v0" and spec["entry_point"] == "dicestack.env:DiceStackEnv"
    assert spec["kwargs"]["world"] == meta["world"] and spec["additional_wrappers"] == []
    with h5py.File(minari_dir / "data" / "main_data.hdf5", "r") as f:
        assert sorted(f.keys(), key=lambda k: int(k[8:])) == [f"episode_{i}" for i in range(7)]
        for i in range(7):
            g = f[f"episode_{i}"]
            steps = meta["episodes"][i]["steps"]
            assert g.attrs["id"] == i and g.attrs["total_steps"] == steps
            assert g["observations"].shape == (steps + 1, 24)
            assert g["actions"].shape == (steps, 3)
            assert g["rewards"].shape == (steps,)
            for flag in ("terminations", "truncations"):
                assert g[flag].shape == (steps,) and g[flag].dtype == np.bool_
            assert bool(g["terminations"][-1]) == meta["episodes"][i]["terminated"]
            assert bool(g["truncations"][-1]) == meta["episodes"][i]["truncated"]
            assert not g["terminations"][:-1].any() and not g["truncations"][:-1].any()
            np.testing.assert_array_equal(g["observations"][-1], meta["episodes"][i]["final_state"])
            limits = np.array(act_space["high"])
            assert np.all(np.abs(g["actions"][()]) <= limits)


def test_round_trips_through_the_command_line(robomimic_file, minari_dir, recorded):
    run("import", "robomimic", robomimic_file, "--out", recorded / "back_r")
    run("import", "minari", minari_dir, "--out", recorded / "back_m")
    original = sorted(p.name for p in (recorded / "demos").iterdir())
    for back in ("back_r", "back_m"):
        assert sorted(p.name for p in (recorded / back).iterdir()) == original
        for name in original:
            if name.endswith(".csv"):
                assert (recorded / back / name).read_text() == (recorded / "demos" / name).read_text()


def test_bad_file_is_refused_naming_the_path(robomimic_file, tmp_path):
    bad = tmp_path / "bad.hdf5"
    bad.write_bytes(robomimic_file.read_bytes())
    with h5py.File(bad, "a") as f:
        f["data/demo_2/actions"][1, 0] = np.nan
    p = run("import", "robomimic", bad, "--out", tmp_path / "x", check=False)
    assert p.returncode == 1, p.stderr
    assert "data/demo_2/actions: row 1 column 0 is NaN" in p.stderr
    assert "HDF5-DIAG" not in p.stderr and not (tmp_path / "x").exists()


def test_the_human_recordings_export_for_minari_under_their_name(tmp_path):
    run("dataset", "export", "human", "--format", "minari", "--out", tmp_path / "human")
    m = json.loads((tmp_path / "human" / "data" / "metadata.json").read_text())
    assert m["dataset_id"] == "dicestack/human-v0"
    assert m["total_episodes"] == 68
    with h5py.File(tmp_path / "human" / "data" / "main_data.hdf5", "r") as f:
        assert len(f.keys()) == 68
        assert f["episode_0"]["observations"].shape[0] == f["episode_0"]["actions"].shape[0] + 1


def test_a_version_one_set_names_the_episodes_that_do_not_replay(tmp_path):
    good = os.path.join(SOURCE, "tests", "datasets", "data", "good")
    p = run("dataset", "export", good, "--format", "robomimic", "--out", tmp_path / "g.hdf5", check=False)
    assert p.returncode == 1
    assert "2 of 2 episodes have no final state" in p.stderr and "episode_0000, episode_0001" in p.stderr
    assert "--skip-incomplete" in p.stderr
    assert not (tmp_path / "g.hdf5").exists()


def as_version_one(src, dst, tamper=None):
    """Copies a set as format version 1 (no reward column, no final state or end flags);
    `tamper` names a file whose third row's cup_x is moved by 1 mm."""
    dst.mkdir()
    meta = json.loads((src / "meta.json").read_text())
    meta["version"] = 1
    for e in meta["episodes"]:
        for key in ("final_state", "terminated", "truncated"):
            del e[key]
        lines = (src / e["file"]).read_text().splitlines()
        rows = [line.rsplit(",", 1)[0] for line in lines]
        if e["file"] == tamper:
            cells = rows[3].split(",")
            cells[1] = repr(float(cells[1]) + 1e-3)
            rows[3] = ",".join(cells)
        (dst / e["file"]).write_text("\n".join(rows) + "\n")
    (dst / "meta.json").write_text(json.dumps(meta, indent=1))


def test_a_version_one_set_is_completed_by_replay(recorded, robomimic_file, tmp_path):
    as_version_one(recorded / "demos", tmp_path / "v1")
    run("dataset", "validate", tmp_path / "v1")
    run("dataset", "export", tmp_path / "v1", "--format", "robomimic", "--out", tmp_path / "v1.hdf5")
    with h5py.File(tmp_path / "v1.hdf5", "r") as a, h5py.File(robomimic_file, "r") as b:
        for i in range(7):
            for key in ("rewards", "next_obs/cup_pose", "next_obs/die2_vel", "actions", "states"):
                np.testing.assert_array_equal(a[f"data/demo_{i}/{key}"][()], b[f"data/demo_{i}/{key}"][()])
            assert a[f"data/demo_{i}"].attrs["dicestack_truncated"] == b[f"data/demo_{i}"].attrs["dicestack_truncated"]
    # An edited state does not replay: named, and left out only when asked.
    as_version_one(recorded / "demos", tmp_path / "edited", tamper="episode_0002.csv")
    p = run("dataset", "export", tmp_path / "edited", "--format", "minari", "--out", tmp_path / "m", check=False)
    assert p.returncode == 1 and "1 of 7 episodes have no final state" in p.stderr and "episode_0002" in p.stderr
    p = run("dataset", "export", tmp_path / "edited", "--format", "minari", "--out", tmp_path / "m", "--skip-incomplete")
    assert "left out 1 episodes without a final state (they do not replay): episode_0002" in p.stdout
    assert json.loads((tmp_path / "m" / "data" / "metadata.json").read_text())["total_episodes"] == 6
