#!/usr/bin/env python3
"""Writes the bad-input corpus: one folder per failure kind, each with its input and a case.json
that says how to run dicestack on it and what the error must say (tests/apps/test_corpus.cpp
runs them all). The folders are committed; rerun this only to add or change cases:

    /usr/bin/python3 tests/corpus/make_corpus.py build/apps/dicestack [KIND ...]

It needs a built dicestack to fit the small models the model cases edit. Cases already in the
corpus that this script does not make (the hand-made demonstration sets under demos/) are kept;
each of those has its case.json written here too.
"""
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
GOOD = os.path.join(HERE, "..", "datasets", "data", "good")
EXE = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else None


def write_case(category, name, why, run, expect, files=None, names_file=True, env=None):
    """One case: `files` maps a relative path to bytes/str (None: a folder)."""
    root = os.path.join(HERE, category, name)
    if files is not None:
        shutil.rmtree(root, ignore_errors=True)
        os.makedirs(root)
        for rel, content in files.items():
            path = os.path.join(root, rel)
            if content is None:
                os.makedirs(path, exist_ok=True)
                continue
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "wb") as f:
                f.write(content.encode() if isinstance(content, str) else content)
    case = {"why": why, "run": run, "expect": expect}
    if not names_file:
        case["names_file"] = False
    if env:
        case["env"] = env
    with open(os.path.join(root, "case.json"), "w") as f:
        json.dump(case, f, indent=1)
        f.write("\n")


def read(path, mode="r"):
    with open(path, mode) as f:
        return f.read()


# --- demonstration sets --------------------------------------------------------------------

def good_set():
    files = {}
    for name in sorted(os.listdir(GOOD)):
        files["set/" + name] = read(os.path.join(GOOD, name))
    return files


def good_meta():
    return json.loads(read(os.path.join(GOOD, "meta.json")))


def with_meta(edit):
    files = good_set()
    meta = good_meta()
    edit(meta)
    files["set/meta.json"] = json.dumps(meta, indent=1)
    return files


def with_episode(name, edit):
    files = good_set()
    files["set/" + name] = edit(files["set/" + name])
    return files


def replace_line(text, index, new):
    lines = text.split("\n")
    lines[index] = new
    return "\n".join(lines)


def replace_cell(text, row, column, value):
    lines = text.split("\n")
    cells = lines[row].split(",")
    cells[column] = value
    lines[row] = ",".join(cells)
    return "\n".join(lines)


def demo_cases():
    validate = "dataset validate {case}/set"
    # The hand-made sets (committed before this script): case.json only.
    for name, expect in {
        "action_out_of_range": "episode_0001.csv:3: column \"dvx\" = 25 is outside [-20, 20]",
        "bad_world": "meta.json \"world\": field \"physics.substeps\" must be in [1, 1000], got 0",
        "broken_meta": "meta.json: not valid JSON",
        "empty_episode": "episode_0001.csv: no steps",
        "extra_file": "episode_0002.csv: not listed in meta.json",
        "file_escapes": "\"file\" must name a file inside the folder",
        "inf": "episode_0001.csv:3: column \"dw\" is infinite",
        "missing_file": "meta.json: lists episode_0009.csv, which does not exist",
        "nan": "episode_0001.csv:3: column \"cup_x\" is NaN",
        "newer_version": "meta.json: format version 99 is newer than this dicestack reads",
        "no_meta": "meta.json: missing; not a dicestack demonstration folder",
        "not_a_number": "episode_0001.csv:3: column \"die2_vy\": \"1.2.3\" is not a number",
        "row_columns": "episode_0001.csv:3: row has 30 columns, expected 29",
        "seed_negative": "\"seed\" must be an unsigned integer, got -1",
        "steps_fraction": "\"steps\" must be an unsigned integer, got 3.5",
        "steps_mismatch": "says episode_0000.csv has 7 steps; the file has 4",
        "t_gap": "episode_0001.csv:3: column \"t\" is 5, expected 1",
        "truncated": "episode_0001.csv:4: row has 17 columns",
        "unknown_source": "column \"source\": \"robot\" is not one of",
        "version_fraction": "\"version\" must be an integer, got 1.9",
        "version_huge": "\"version\" must be an integer, got 4294967297",
        "wrong_columns": "episode_0001.csv:1: header has 28 columns, expected 29",
        "wrong_format": "format \"robomimic\" is not dicestack-demos",
        "wrong_header_name": "episode_0001.csv:1: column 15 is \"die1_vz\", expected \"die1_vy\"",
    }.items():
        write_case("demos", name, "hand-made demonstration set", validate, [expect])

    ep = "episode_0001.csv"
    cases = [
        ("empty_csv", "an episode file of zero bytes", with_episode(ep, lambda t: ""), f"{ep}"),
        ("duplicate_column", "a header naming cup_x twice",
         with_episode(ep, lambda t: replace_line(t, 0, t.split("\n")[0].replace("cup_y", "cup_x"))), f"{ep}:1: column 3 is \"cup_x\", expected \"cup_y\""),
        ("t_starts_at_one", "the first row's step is 1", with_episode(ep, lambda t: replace_cell(t, 1, 0, "1")),
         f"{ep}:2: column \"t\" is 1, expected 0"),
        ("t_fraction", "a step number 0.5", with_episode(ep, lambda t: replace_cell(t, 1, 0, "0.5")), f"{ep}:2: column \"t\""),
        ("t_negative", "a step number -1", with_episode(ep, lambda t: replace_cell(t, 1, 0, "-1")), f"{ep}:2: column \"t\""),
        ("empty_cell", "an empty state cell", with_episode(ep, lambda t: replace_cell(t, 2, 4, "")), f"{ep}:3: column \"die0_x\""),
        ("hex_number", "a state written 0x10", with_episode(ep, lambda t: replace_cell(t, 2, 5, "0x10")), f"{ep}:3: column \"die0_y\""),
        ("trailing_text", "a number followed by text", with_episode(ep, lambda t: replace_cell(t, 2, 6, "0.5abc")), f"{ep}:3: column \"die0_angle\""),
        ("overflow_number", "a state of 1e999", with_episode(ep, lambda t: replace_cell(t, 2, 7, "1e999")), f"{ep}:3: column \"die0_vx\""),
        ("blank_line", "a blank line between rows", with_episode(ep, lambda t: replace_line(t, 2, "")), f"{ep}:3"),
        ("binary_garbage", "bytes that are not text", with_episode(ep, lambda t: "\x00\x01\xff\xfe" * 64), f"{ep}:1"),
        ("long_line", "a 100 KB row (the message must not echo it)",
         with_episode(ep, lambda t: replace_cell(t, 2, 8, "9" * 100_000 + "x")), f"{ep}:3: column \"die0_vy\""),
        ("source_empty", "a row without a source", with_episode(ep, lambda t: replace_cell(t, 2, 28, "")), f"{ep}:3: column \"source\""),
        ("meta_not_object", "meta.json holds an array", {**good_set(), "set/meta.json": "[]"}, "meta.json"),
        ("meta_empty", "meta.json of zero bytes", {**good_set(), "set/meta.json": ""}, "meta.json: not valid JSON"),
        ("meta_deep", "meta.json nested 10,000 levels", {**good_set(), "set/meta.json": "[" * 10000 + "]" * 10000},
         "meta.json: JSON nested deeper than 64 levels"),
        ("episodes_not_array", "\"episodes\" is an object", with_meta(lambda m: m.update(episodes={})), "meta.json"),
        ("episode_entry_not_object", "an episode entry is a number", with_meta(lambda m: m.update(episodes=[1, 2])), "meta.json"),
        ("duplicate_entry", "one file listed twice", with_meta(lambda m: m["episodes"].__setitem__(1, dict(m["episodes"][0]))),
         "episode_0000.csv"),
        ("missing_world", "no world config", with_meta(lambda m: m.pop("world")), "meta.json"),
        ("world_overlapping_dice", "the world's dice overlap",
         with_meta(lambda m: m["world"]["dice"].update(start_x=[4.08, 4.2, 4.93])), "field \"dice.start_x[1]\" overlaps die 0"),
        ("world_newer_version", "the world config is of a newer version",
         with_meta(lambda m: m["world"].update(format="dicestack-world", version=9)), "format version 9 is newer"),
        ("file_absolute", "an episode file given as an absolute path",
         with_meta(lambda m: m["episodes"][0].update(file="/etc/passwd")), "\"file\" must name a file inside the folder"),
        ("file_not_csv", "an episode file that is not a .csv",
         with_meta(lambda m: m["episodes"][0].update(file="meta.json")), "meta.json:1: header has 1 columns"),
        ("seed_huge", "a seed beyond 2^64", with_meta(lambda m: m["episodes"][0].update(seed=18446744073709551616)),
         "\"seed\" must be an unsigned integer"),
        ("steps_negative", "a negative step count", with_meta(lambda m: m["episodes"][0].update(steps=-4)),
         "\"steps\" must be an unsigned integer, got -4"),
        ("outcome_wrong_type", "an outcome flag that is text",
         with_meta(lambda m: m["episodes"][0]["outcome"].update(stacked="yes")), "\"stacked\" must be true or false"),
        ("description_not_text", "a description that is a number", with_meta(lambda m: m.update(description=5)),
         "\"description\" must be a string"),
        ("episode_is_folder", "an episode file that is a folder",
         {**{k: v for k, v in good_set().items() if k != "set/" + ep}, "set/" + ep + "/README": "a folder, not a file\n"}, ep),
    ]
    for name, why, files, expect in cases:
        write_case("demos", name, why, validate, [expect], files=files)


# --- world configs -------------------------------------------------------------------------

def default_world():
    return json.loads(subprocess.run([EXE, "config"], check=True, capture_output=True, text=True).stdout)


def world_cases():
    check = "config --check {case}/world.json"
    rollout = "rollout --steps 5 --world {case}/world.json --json"

    def edited(path, value):
        w = default_world()
        node = w
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
        return json.dumps(w, indent=1)

    def short_arm():
        w = default_world()
        w["embodiment"] = "arm"
        w["arm"]["link_lengths"] = [1.0, 1.0, 0.5]
        return json.dumps(w, indent=1)

    def without(path):
        w = default_world()
        node = w
        for key in path[:-1]:
            node = node[key]
        del node[path[-1]]
        return json.dumps(w, indent=1)

    cases = [
        ("not_json", "text that is not JSON", "gravity = -4", check, "not valid JSON"),
        ("empty", "a file of zero bytes", "", check, "not valid JSON"),
        ("array_root", "a JSON array", "[1, 2]", check, "must be a JSON object"),
        ("deep", "nested 10,000 levels", "[" * 10000 + "]" * 10000, check, "JSON nested deeper than 64 levels"),
        ("missing_field", "no physics.substeps", without(["physics", "substeps"]), check, "field \"physics.substeps\" is missing"),
        ("unknown_field", "a misspelt field", edited(["physics", "gravty"], -9.8), check, "field \"physics.gravty\" is not a world config field"),
        ("wrong_type", "a mass given as text", edited(["dice", "mass"], "heavy"), check, "field \"dice.mass\" must be a number"),
        ("long_value", "a 100 KB string where a number belongs", edited(["dice", "mass"], "x" * 100_000), check, "field \"dice.mass\" must be a number"),
        ("integer_fraction", "substeps of 2.5", edited(["physics", "substeps"], 2.5), check, "field \"physics.substeps\" must be an integer"),
        ("integer_overflow", "substeps of 2^40", edited(["physics", "substeps"], 2 ** 40), check, "field \"physics.substeps\" is out of range"),
        ("non_finite", "a half size of 1e999", edited(["dice", "half_size"], 0.2).replace("0.2,", "1e999,", 1), check, "is not a finite number"),
        ("array_length", "sigma with 2 numbers", edited(["cost", "sigma"], [1.0, 2.0]), check, "field \"cost.sigma\" must be an array of 24 numbers"),
        ("gravity_huge", "gravity of -1e30", edited(["physics", "gravity"], [0.0, -1e30]), rollout, "field \"physics.gravity[1]\" must be in [-100, 100]"),
        ("mass_tiny", "a die of 1e-300 kg", edited(["dice", "mass"], 1e-300), rollout, "field \"dice.mass\" must be in [0.001, 1000]"),
        ("friction_negative", "a negative friction", edited(["cup", "friction"], -0.5), check, "field \"cup.friction\" must be in [0, 10]"),
        ("half_size_huge", "dice 200 m wide", edited(["dice", "half_size"], 100.0), rollout, "field \"dice.start_x[0]\" puts die 0 outside the walls"),
        ("dice_outside", "a die beyond the right wall", edited(["dice", "start_x"], [4.08, 4.51, 12.0]), rollout, "field \"dice.start_x[2]\" puts die 2 outside the walls"),
        ("dice_overlap", "two dice in one place", edited(["dice", "start_x"], [4.08, 4.08, 4.93]), rollout, "field \"dice.start_x[1]\" overlaps die 0"),
        ("dice_in_table", "dice starting inside the table", edited(["dice", "start_y"], 0.5), rollout, "field \"dice.start_y\" puts the dice outside the walls"),
        ("cup_outside", "the cup above the ceiling", edited(["cup", "start_anchor"], [4.0, 9.0]), rollout, "field \"cup.start_anchor\" puts the cup outside the walls"),
        ("walls_crossed", "the left wall right of the right wall", edited(["walls", "left_x"], 9.5), check, "field \"walls.right_x\" must be greater than walls.left_x"),
        ("corner_cut", "corners cut deeper than the die", edited(["dice", "corner_cut"], 0.3), check, "field \"dice.corner_cut\" must be smaller than dice.half_size"),
        ("speed_cap", "Box2D's speed cap below the action limit", edited(["physics", "units_per_metre"], 500.0), check, "field \"physics.units_per_metre\" leaves Box2D's speed cap"),
        ("newer_version", "a world config of version 4", edited(["version"], 4), check, "format version 4 is newer than this dicestack reads (3)"),
        ("embodiment_unknown", "an embodiment that does not exist", edited(["embodiment"], "robot"), check, "field \"embodiment\" must be \"cup\" or \"arm\""),
        ("arm_out_of_reach", "an arm too short to hold the cup at its start", short_arm(), rollout, "field \"arm.link_lengths\" cannot reach the cup's start"),
        ("version_fraction", "version 2.5", edited(["version"], 2.5), check, "field \"version\" must be a positive integer"),
        ("wrong_marker", "another format's marker", edited(["format"], "dicestack-model"), check, "field \"format\" must be \"dicestack-world\""),
    ]
    for name, why, text, run, expect in cases:
        write_case("worlds", name, why, run, [expect], files={"world.json": text})


# --- model files ---------------------------------------------------------------------------

def nlohmann_dump(value):
    """nlohmann::json::dump() with no indent: sorted keys, no spaces, shortest round-trip floats."""
    return json.dumps(value, separators=(",", ":"), sort_keys=True, ensure_ascii=False)


def fnv1a(data):
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def split_model(blob):
    newline = blob.index(b"\n")
    return json.loads(blob[:newline]), blob[newline + 1:]


def seal(header, payload):
    """The model file with payload_bytes, payload_fnv1a and checksum recomputed (format 2)."""
    header = dict(header)
    header["payload_bytes"] = len(payload)
    header["payload_fnv1a"] = "%016x" % fnv1a(payload)
    header.pop("checksum", None)
    header["checksum"] = "%016x" % fnv1a(nlohmann_dump(header).encode() + b"\n" + payload)
    return nlohmann_dump(header).encode() + b"\n" + payload


SMALL = {"knn": [], "linear_svr": ["max_iter=20"], "mlp": ["layers=1", "width=4", "max_iter=5"],
         "random_forest": ["trees=2", "max_depth=3"], "gbt": ["trees=2", "max_depth=2"], "rbf_svr": ["epsilon=2"]}


def fit_models():
    models = {}
    with tempfile.TemporaryDirectory() as tmp:
        # The 7 rows of the good set leave an SVR without support vectors: rbf_svr gets a recording.
        recorded = os.path.join(tmp, "recorded")
        subprocess.run([EXE, "record", "--expert", "scripted", "--episodes", "1", "--seed", "0", "--out", recorded],
                       check=True, capture_output=True)
        for name, sets in SMALL.items():
            out = os.path.join(tmp, name + ".dsm")
            demos = recorded if name in ("rbf_svr", "gbt") else GOOD
            args = [EXE, "train", "--regressor", name, "--demos", demos, "--out", out]
            for s in sets:
                args += ["--set", s]
            subprocess.run(args, check=True, capture_output=True)
            models[name] = read(out, "rb")
            header, payload = split_model(models[name])
            assert seal(header, payload) == models[name], f"{name}: resealing does not reproduce the file"
    return models


def model_cases():
    evaluate = "evaluate --model {case}/m.dsm --episodes 1"
    models = fit_models()
    knn_header, knn_payload = split_model(models["knn"])

    def header_edit(edit):
        h = json.loads(json.dumps(knn_header))
        edit(h)
        return seal(h, knn_payload)

    def payload_edit(name, edit):
        h, p = split_model(models[name])
        return seal(h, edit(p))

    def gbt_edit(edit):
        def apply(p):
            model = json.loads(p)
            edit(model["learner"]["gradient_booster"]["model"])
            return json.dumps(model).encode()
        return payload_edit("gbt", apply)

    def yaml_edit(name, old, new):
        def apply(p):
            j = json.loads(p)
            assert old in j["models"][0], (name, old)
            j["models"][0] = j["models"][0].replace(old, new, 1)
            return json.dumps(j).encode()
        return payload_edit(name, apply)

    def matrix_shape(name, index_of_u64, value):
        def apply(p):
            p = bytearray(p)
            struct.pack_into("<Q", p, 8 * index_of_u64, value)
            return bytes(p)
        return payload_edit(name, apply)

    raw = models["knn"]
    cases = [
        ("empty", "a model file of zero bytes", b"", "m.dsm"),
        ("no_newline", "a header without the line break", raw[:raw.index(b"\n")], "m.dsm"),
        ("header_not_json", "a header that is not JSON", b"{format: model}\n" + knn_payload, "m.dsm"),
        ("header_array", "a header that is a JSON array", b"[1,2,3]\n", "m.dsm"),
        ("header_deep", "a header nested 10,000 levels", b"[" * 10000 + b"]" * 10000 + b"\n", "m.dsm: JSON nested deeper than 64 levels"),
        ("wrong_marker", "a header of another format", header_edit(lambda h: h.update(format="dicestack-demos")), "m.dsm"),
        ("newer_version", "a model of format version 9", header_edit(lambda h: h.update(version=9)), "format version 9 is newer"),
        ("version_fraction", "version 1.5", header_edit(lambda h: h.update(version=1.5)), "m.dsm"),
        ("edited_payload", "a payload byte changed, checksums left", raw[:-3] + bytes([raw[-3] ^ 1]) + raw[-2:], "m.dsm"),
        ("edited_header", "a standardiser mean changed, checksum left",
         raw.replace(b'"mean":[', b'"mean":[1', 1), "m.dsm"),
        ("payload_bytes_beyond", "payload_bytes larger than the file",
         header_edit(lambda h: None)[:0] + nlohmann_dump({**knn_header, "payload_bytes": 2000000000}).encode() + b"\n" + knn_payload, "m.dsm"),
        ("payload_bytes_negative", "payload_bytes of -1",
         nlohmann_dump({**knn_header, "payload_bytes": -1}).encode() + b"\n" + knn_payload, "m.dsm"),
        ("unknown_regressor", "a regressor nobody registered", header_edit(lambda h: h.update(regressor="xgboost_gpu")), "xgboost_gpu"),
        ("unknown_features", "a feature map that does not exist", header_edit(lambda h: h.update(features="state+future")), "state+future"),
        ("features_mismatch", "a feature map wider than the regressor reads", header_edit(lambda h: h.update(features="state+clock")), "feature map \"state+clock\""),
        ("state_dim", "a model for a 23-number state", header_edit(lambda h: h.update(state_dim=23)), "m.dsm"),
        ("standardizer_short", "a standardiser with 2 means", header_edit(lambda h: h["x_standardizer"].update(mean=[0.0, 1.0])), "m.dsm"),
        ("standardizer_zero_sigma", "a standardiser sigma of 0", header_edit(lambda h: h["x_standardizer"]["sigma"].__setitem__(0, 0.0)), "m.dsm"),
        ("knn_shape", "knn: a matrix of 2^31 rows", matrix_shape("knn", 2, 1 << 31), "knn"),
        ("knn_count", "knn: the wrong number of matrices", matrix_shape("knn", 1, 7), "knn"),
        ("linear_svr_truncated", "linear_svr: a payload cut short", payload_edit("linear_svr", lambda p: p[:-8]), "linear_svr"),
        ("linear_svr_trailing", "linear_svr: bytes after the last matrix", payload_edit("linear_svr", lambda p: p + b"xx"), "linear_svr"),
        ("mlp_magic", "mlp: not a matrix payload", payload_edit("mlp", lambda p: b"NOTMATRX" + p[8:]), "mlp"),
        ("mlp_nan", "mlp: a NaN weight", payload_edit("mlp", lambda p: p[:-8] + struct.pack("<d", float("nan"))), "mlp"),
        ("random_forest_garbage", "random_forest: text instead of trees", payload_edit("random_forest", lambda p: b"hello"), "random_forest"),
        ("random_forest_cut", "random_forest: half a payload", payload_edit("random_forest", lambda p: p[: len(p) // 2]), "random_forest"),
        ("gbt_leaf_count", "gbt: tree_info shorter than the trees", gbt_edit(lambda m: m["tree_info"].pop()), "gbt"),
        ("gbt_child", "gbt: a child index out of range", gbt_edit(lambda m: m["trees"][0]["left_children"].__setitem__(0, 99999)), "gbt"),
        ("gbt_split", "gbt: a split on input 10,000", gbt_edit(lambda m: m["trees"][0]["split_indices"].__setitem__(0, 10000)), "gbt"),
        ("gbt_tree_count", "gbt: a tree count of 2^31", gbt_edit(lambda m: m["gbtree_model_param"].update(num_trees="2147483647")), "gbt"),
        ("gbt_leaf_value", "gbt: a NaN-like leaf (1e999)", payload_edit("gbt", lambda p: p.replace(b'"base_weights":[', b'"base_weights":[1e999,', 1)), "gbt"),
        ("gbt_not_json", "gbt: a payload that is not JSON", payload_edit("gbt", lambda p: b"{\"learner\": "), "gbt"),
        ("rbf_svr_width", "rbf_svr: support vectors 3 wide", yaml_edit("rbf_svr", "var_count: 24", "var_count: 3"), "rbf_svr"),
        ("rbf_svr_sv_total", "rbf_svr: sv_total beyond the vectors", yaml_edit("rbf_svr", "sv_total: ", "sv_total: 9"), "rbf_svr"),
        ("rbf_svr_kernel", "rbf_svr: a linear kernel", yaml_edit("rbf_svr", "type: RBF", "type: LINEAR"), "rbf_svr"),
    ]
    for name, why, blob, expect in cases:
        write_case("models", name, why, evaluate, [expect], files={"m.dsm": blob})


# --- learner checkpoints -------------------------------------------------------------------

def checkpoint_cases():
    # A world whose episodes end after 10 steps keeps the checkpoint's data small.
    world = default_world()
    world["episode"]["max_steps"] = 10
    world_text = json.dumps(world, indent=1)
    with tempfile.TemporaryDirectory() as tmp:
        ck = os.path.join(tmp, "ck")
        with open(os.path.join(tmp, "world.json"), "w") as f:
            f.write(world_text)
        subprocess.run([EXE, "train", "--regressor", "knn", "--learner", "dagger", "--option", "iterations=1",
                        "--option", "rollouts=1", "--option", "expert=scripted", "--demos", GOOD, "--checkpoint", ck,
                        "--world", os.path.join(tmp, "world.json"), "--out", os.path.join(tmp, "m.dsm")],
                       check=True, capture_output=True)
        base = {"world.json": world_text}
        for root, _, names in os.walk(ck):
            for n in names:
                full = os.path.join(root, n)
                base["ck/" + os.path.relpath(full, ck)] = read(full, "rb")
    state = json.loads(base["ck/dagger.json"])
    resume = ("train --regressor knn --learner dagger --option iterations=2 --option rollouts=1 --option expert=scripted "
              "--demos {source}/tests/datasets/data/good --world {case}/world.json --checkpoint {case}/ck --resume --out {case}/out.dsm")

    def edited(edit):
        s = json.loads(json.dumps(state))
        edit(s)
        return {**base, "ck/dagger.json": json.dumps(s)}

    cases = [
        ("not_json", "a state that is not JSON", {**base, "ck/dagger.json": "{"}, "dagger.json: not a checkpoint state"),
        ("wrong_marker", "a state of another format", edited(lambda s: s.update(format="dicestack-model")), "dagger.json: not a checkpoint state"),
        ("newer_version", "a state of a version yet to come", edited(lambda s: s.update(version=99)), "dagger.json: format version 99 is newer"),
        ("iteration_text", "an iteration that is text", edited(lambda s: s.update(iteration="one")), "field \"iteration\""),
        ("data_escapes", "data naming a folder outside", edited(lambda s: s.update(data="../../x")), "field \"data\" must be a file name inside the checkpoint folder"),
        ("data_other_iteration", "data of another iteration", edited(lambda s: s.update(data="data-7")), "field \"data\" must name this iteration's folder"),
        ("curve_bad", "a curve point that is text", edited(lambda s: s["curve"].__setitem__(0, "x")), "field \"curve[0].iteration\""),
        ("run_mismatch", "a checkpoint of another seed", edited(lambda s: s["run"].update(seed="99")), "cannot resume a run made with other settings: seed"),
        ("data_missing", "the state's data folder is gone", {k: v for k, v in edited(lambda s: None).items() if "/data-1/" not in k},
         "data-1"),
    ]
    for name, why, files, expect in cases:
        write_case("checkpoints", name, why, resume, [expect], files=files)


# --- robomimic and Minari HDF5 -------------------------------------------------------------

def interop_cases():
    """Exports of a 2-episode, 10-step set, edited with h5py (HDF5 paths must be named)."""
    import h5py
    import numpy as np

    world = default_world()
    world["episode"]["max_steps"] = 10
    scratch = tempfile.TemporaryDirectory()
    tmp = scratch.name
    with open(os.path.join(tmp, "world.json"), "w") as f:
        json.dump(world, f)
    run = lambda *a: subprocess.run([EXE, *a], check=True, capture_output=True)
    run("record", "--expert", "scripted", "--episodes", "2", "--seed", "0", "--world", os.path.join(tmp, "world.json"),
        "--out", os.path.join(tmp, "set"))
    run("dataset", "export", os.path.join(tmp, "set"), "--format", "robomimic", "--out", os.path.join(tmp, "d.hdf5"))
    run("dataset", "export", os.path.join(tmp, "set"), "--format", "minari", "--out", os.path.join(tmp, "mn"))
    robomimic = read(os.path.join(tmp, "d.hdf5"), "rb")
    minari_h5 = read(os.path.join(tmp, "mn", "data", "main_data.hdf5"), "rb")
    minari_meta = read(os.path.join(tmp, "mn", "data", "metadata.json"))

    def edited_h5(original, edit):
        path = os.path.join(tmp, "edit.hdf5")
        with open(path, "wb") as f:
            f.write(original)
        with h5py.File(path, "r+") as h:
            edit(h)
        # h5py leaves freed space behind; repack so the case stays small.
        packed = os.path.join(tmp, "packed.hdf5")
        with h5py.File(path, "r") as src, h5py.File(packed, "w") as dst:
            for k, v in src.attrs.items():
                dst.attrs[k] = v
            for k in src:
                src.copy(src[k], dst, name=k)
        return read(packed, "rb")

    def replace(h, path, data):
        del h[path]
        h[path] = data

    def scaled(h, path, f):
        replace(h, path, f(h[path][()]))

    rm_run = "import robomimic {case}/d.hdf5 --out {case}/out"
    rm_cases = [
        ("not_hdf5", "a text file named .hdf5", b"not an HDF5 file\n", "not an HDF5 file"),
        ("truncated", "the first half of an export", robomimic[: len(robomimic) // 2], "d.hdf5"),
        ("no_data", "no data group", lambda h: h.__delitem__("data"), "data"),
        ("no_env_args", "data lacks env_args", lambda h: h["data"].attrs.__delitem__("env_args"), "env_args"),
        ("env_args_not_json", "env_args that is not JSON", lambda h: h["data"].attrs.__setitem__("env_args", "{"), "env_args"),
        ("other_env", "env_args of another environment",
         lambda h: h["data"].attrs.__setitem__("env_args", json.dumps({**json.loads(h["data"].attrs["env_args"]), "env_name": "Lift"})), "env_name"),
        ("bad_world", "env_kwargs holding an impossible world",
         lambda h: h["data"].attrs.__setitem__("env_args", json.dumps(
             {**json.loads(h["data"].attrs["env_args"]),
              "env_kwargs": {**json.loads(h["data"].attrs["env_args"])["env_kwargs"],
                             "world": {**world, "physics": {**world["physics"], "gravity": [0.0, -1e30]}}}})), "gravity"),
        ("stray_group", "a group that is not demo_<n>", lambda h: h["data"].create_group("notes"), "data/notes"),
        ("no_actions", "a demo without actions", lambda h: h.__delitem__("data/demo_0/actions"), "data/demo_0/actions"),
        ("actions_width", "actions of 2 columns", lambda h: scaled(h, "data/demo_0/actions", lambda a: a[:, :2]), "data/demo_0/actions"),
        ("actions_nan", "a NaN action", lambda h: scaled(h, "data/demo_1/actions", lambda a: np.where(np.arange(a.size).reshape(a.shape) == 4, np.nan, a)),
         "data/demo_1/actions"),
        ("actions_outside", "an action of 3 (actions lie in [-1, 1])", lambda h: scaled(h, "data/demo_0/actions", lambda a: a * 0 + 3), "outside [-1, 1]"),
        ("actions_text", "actions stored as strings", lambda h: replace(h, "data/demo_0/actions", np.array([b"x"] * 10)), "data/demo_0/actions"),
        ("states_short", "states one row short", lambda h: scaled(h, "data/demo_0/states", lambda a: a[:-1]), "data/demo_0/states"),
        ("num_samples_wrong", "num_samples disagreeing with actions", lambda h: h["data/demo_0"].attrs.__setitem__("num_samples", 99), "num_samples"),
        ("obs_disagrees", "an observation that is not the state", lambda h: scaled(h, "data/demo_0/obs/cup_pose", lambda a: a + 1), "data/demo_0/obs/cup_pose"),
        ("no_next_obs", "a missing next_obs key", lambda h: h.__delitem__("data/demo_1/next_obs/die2_vel"), "data/demo_1/next_obs/die2_vel"),
        ("dones_two", "a done flag of 2", lambda h: scaled(h, "data/demo_0/dones", lambda a: a * 0 + 2), "data/demo_0/dones"),
        ("total_wrong", "data/total disagreeing with the demos", lambda h: h["data"].attrs.__setitem__("total", 7), "total"),
        ("newer_version", "a dicestack record of version 9",
         lambda h: h["data"].attrs.__setitem__("dicestack", json.dumps({**json.loads(h["data"].attrs["dicestack"]), "version": 9})), "version 9"),
        ("sources_bad", "per-step sources that do not add up",
         lambda h: h["data/demo_0"].attrs.__setitem__("dicestack_sources", "expert:3"), "dicestack_sources"),
    ]
    for name, why, edit, expect in rm_cases:
        content = edit if isinstance(edit, bytes) else edited_h5(robomimic, edit)
        write_case("interop", "robomimic_" + name, why, rm_run, [expect], files={"d.hdf5": content})

    mn_run = "import minari {case}/mn --out {case}/out"
    mn_files = lambda h5=minari_h5, meta=minari_meta: {"mn/data/main_data.hdf5": h5, "mn/data/metadata.json": meta}
    meta = json.loads(minari_meta)
    mn_cases = [
        ("no_metadata", "main_data.hdf5 without metadata.json", {"mn/data/main_data.hdf5": minari_h5}, "metadata.json"),
        ("metadata_not_json", "metadata.json that is not JSON", mn_files(meta="{"), "metadata.json"),
        ("not_hdf5_storage", "a dataset stored as arrow", mn_files(meta=json.dumps({**meta, "data_format": "arrow"})), "data_format"),
        ("no_main_data", "metadata.json without main_data.hdf5", {"mn/data/metadata.json": minari_meta}, "main_data.hdf5"),
        ("episodes_counted_wrong", "total_episodes of 3 for 2 episodes", mn_files(meta=json.dumps({**meta, "total_episodes": 3})), "total_episodes"),
        ("gap", "episodes numbered 0 and 2", mn_files(h5=edited_h5(minari_h5, lambda h: h.move("episode_1", "episode_2"))), "episode_1"),
        ("observations_short", "T observations instead of T + 1",
         mn_files(h5=edited_h5(minari_h5, lambda h: scaled(h, "episode_0/observations", lambda a: a[:-1]))), "episode_0/observations"),
        ("rewards_nan", "a NaN reward",
         mn_files(h5=edited_h5(minari_h5, lambda h: scaled(h, "episode_1/rewards", lambda a: a * np.nan))), "episode_1/rewards"),
        ("flags_two", "a termination flag of 2",
         mn_files(h5=edited_h5(minari_h5, lambda h: scaled(h, "episode_0/terminations", lambda a: a.astype(np.int64) * 0 + 2))), "episode_0/terminations"),
        ("action_too_big", "an action beyond the world's limit",
         mn_files(h5=edited_h5(minari_h5, lambda h: scaled(h, "episode_0/actions", lambda a: a * 0 + 1e6))), "action.limit"),
    ]
    for name, why, files, expect in mn_cases:
        write_case("interop", "minari_" + name, why, mn_run, [expect], files=files)
    scratch.cleanup()


# --- plugins and command-line values -------------------------------------------------------

def plugin_and_argument_cases():
    regressors = "regressors"
    env = {"DICESTACK_PLUGIN_PATH": "{case}/plugins"}
    write_case("plugins", "text_file", "a text file named like a plugin", regressors, ["libnotes.so"],
               files={"plugins/libnotes.so": "not a library\n"}, env=env)
    write_case("plugins", "empty_file", "an empty .so", regressors, ["libempty.so"], files={"plugins/libempty.so": b""}, env=env)
    # Built plugins: {plugin:TARGET} is replaced by the test with the built file's path.
    for name, target, expect in [("not_a_plugin", "test_not_a_plugin", "not a dicestack plugin"),
                                 ("data_entry", "test_data_entry", "not a function"),
                                 ("null_record", "test_null_record", "null"),
                                 ("abi_mismatch", "test_plugin_abi99", "ABI 99"),
                                 ("duplicate_name", "test_plugin_duplicate", "knn")]:
        write_case("plugins", name, f"the built plugin {target}", regressors, [expect], files={"plugins": None},
                   env={"DICESTACK_PLUGIN_PATH": "{plugin:" + target + "}"}, names_file=False)
    for name, run, expect in [
        ("seed_negative", "rollout --seed -1", "--seed"),
        ("seed_too_big", "rollout --seed 18446744073709551616", "--seed"),
        ("seed_leading_zero", "rollout --seed 007", "--seed"),
        ("episodes_zero", "record --expert scripted --episodes 0 --seed 0 --out {case}/set", "--episodes"),
        ("unknown_feature_map", "train --regressor knn --features state+future --demos {source}/tests/datasets/data/good --out {case}/m.dsm", "state+future"),
        ("unknown_regressor_set", "train --regressor knn --set kk=3 --demos {source}/tests/datasets/data/good --out {case}/m.dsm", "kk"),
        ("bad_option_value", "train --regressor knn --learner dagger --option iterations=many --demos {source}/tests/datasets/data/good --out {case}/m.dsm", "iterations"),
    ]:
        write_case("arguments", name, "a bad command-line value", run, [expect], files={}, names_file=False)


if __name__ == "__main__":
    if not EXE:
        sys.exit("usage: make_corpus.py PATH/TO/dicestack [demos|worlds|models|checkpoints|interop|plugins ...]")
    makers = {"demos": demo_cases, "worlds": world_cases, "models": model_cases, "checkpoints": checkpoint_cases,
              "interop": interop_cases, "plugins": plugin_and_argument_cases}
    chosen = sys.argv[2:] or list(makers)
    for kind in chosen:
        if kind not in makers:
            sys.exit(f"make_corpus: unknown kind {kind!r} (one of {', '.join(makers)})")
        makers[kind]()
    count = sum(1 for c in os.listdir(HERE) if os.path.isdir(os.path.join(HERE, c)) for _ in os.listdir(os.path.join(HERE, c)))
    print(f"make_corpus: {count} cases")
