"""The pages only the command line made before, from Python: dicestack.view_dataset
(`dicestack dataset view`) and evaluate(report=...) (`dicestack evaluate --report`). Both go
through the same C++ functions as the command line, so they write the same files and refuse the
same things with the same messages. The pages in a browser: test_pages.py."""
import json
import os
import subprocess

import pytest

import dicestack
from conftest import short_world

MARKER = "<!-- dicestack results page -->"


def page_data(page):
    """The JSON a page inlines for its script."""
    text, tag = page.read_text(), '<script type="application/json" id="page-data">'
    start = text.index(tag) + len(tag)
    return json.loads(text[start:text.index("</script>", start)])


@pytest.fixture(scope="module")
def few(builtin_episodes):
    return builtin_episodes[:4]


@pytest.fixture(scope="module")
def few_folder(few, tmp_path_factory):
    path = tmp_path_factory.mktemp("writers") / "four"
    dicestack.save_demos(few, path, description="four <b>built-in</b> episodes")
    return path


@pytest.fixture(scope="module")
def knn(few):
    return dicestack.train("knn", demos=few, split="none", params={"k": 2}, progress=False)


def test_view_dataset_writes_the_clis_page_for_a_folder(few_folder, few, tmp_path):
    page = tmp_path / "view.html"
    assert dicestack.view_dataset(few_folder, page) == os.fspath(page)
    text = page.read_text()
    assert text.startswith(MARKER + "\n<!doctype html>")
    data = page_data(page)
    assert [e["name"] for e in data["episodes"]] == [e.name for e in few]
    assert [e["steps"] for e in data["episodes"]] == [len(e) for e in few]
    assert data["title"] == f"dicestack episodes: {few_folder}"
    assert "four <b>built-in</b> episodes" in data["facts"]
    assert "<b>built-in</b>" not in text  # inlined as \u003c escapes, never as markup
    # Each episode's script sits in the media generation the page links, in view_files/.
    scripts = [tmp_path / e["script"] for e in data["episodes"]]
    assert all(s.parent.parent.parent == tmp_path / "view_files" and s.is_file() for s in scripts)
    assert sorted(p.name for p in scripts[0].parent.iterdir()) == [f"episode_{i:06d}.js" for i in range(len(few))]
    dicestack.view_dataset(few_folder, page)  # its own page: replaced


def test_view_dataset_is_byte_for_byte_the_command_lines(few_folder, tmp_path, cli):
    ours, theirs = tmp_path / "py" / "view.html", tmp_path / "cli" / "view.html"
    ours.parent.mkdir()
    theirs.parent.mkdir()
    dicestack.view_dataset(few_folder, ours)
    subprocess.run([cli, "dataset", "view", str(few_folder), "--out", str(theirs)], check=True, capture_output=True)
    assert ours.read_bytes() == theirs.read_bytes()
    for e in page_data(theirs)["episodes"]:
        assert (ours.parent / e["script"]).read_bytes() == (theirs.parent / e["script"]).read_bytes()


def test_view_dataset_takes_episodes(few, tmp_path):
    page = tmp_path / "mine.html"
    dicestack.view_dataset(few[:2], page, world=dicestack.default_world())
    data = page_data(page)
    assert data["title"] == "dicestack episodes: <episodes from Python>"
    assert [e["name"] for e in data["episodes"]] == [e.name for e in few[:2]]
    assert [e["success"] for e in data["episodes"]] == [e.realistic_success for e in few[:2]]
    assert "<episodes from Python>" not in page.read_text()
    with pytest.raises(TypeError, match="dicestack.Episode"):
        dicestack.view_dataset([{"states": []}], tmp_path / "bad.html")


def test_view_dataset_refuses_a_users_files_and_leaves_them_as_they_were(few_folder, tmp_path):
    mine = tmp_path / "notes.html"
    mine.write_text("<p>my notes</p>")
    with pytest.raises(ValueError, match=r"notes.html: exists and is not a dicestack results page; refusing to replace"):
        dicestack.view_dataset(few_folder, mine)
    assert mine.read_text() == "<p>my notes</p>"
    assert not (tmp_path / "notes_files").exists()
    folder = tmp_path / "other_files"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="other_files: exists and is not a episode viewer's folder"):
        dicestack.view_dataset(few_folder, tmp_path / "other.html")
    assert [p.name for p in folder.iterdir()] == ["keep.txt"]
    assert not (tmp_path / "other.html").exists()
    with pytest.raises(FileNotFoundError, match="nowhere"):
        dicestack.view_dataset(tmp_path / "nowhere", tmp_path / "x.html")


def test_evaluate_writes_the_report_of_evaluate_report(knn, tmp_path):
    report = tmp_path / "report"
    stats = dicestack.evaluate(knn, episodes=2, seed=3, world=short_world(40), report=report, progress=False)
    plain = dicestack.evaluate(knn, episodes=2, seed=3, world=short_world(40), progress=False)
    assert stats.keys() == plain.keys()  # the same dict as without a report
    for key in ("episodes", "realistic_success_rate", "stacked_rate", "wall_contact_rate", "dice_in_cup_mean"):
        assert stats[key] == plain[key], key
    assert json.loads((report / "dicestack-report.json").read_text())["format"] == "dicestack-report"
    data = page_data(report / "index.html")
    (row,) = data["rows"]
    assert row["regressor"] == "knn"
    assert row["realistic_success_rate"] == stats["realistic_success_rate"]
    assert row["dice_in_cup_mean"] == stats["dice_in_cup_mean"]
    info = json.loads((report / "index_files" / "eval_info" / "row-01.json").read_text())
    assert [e["index"] for e in info["per_episode"]] == [0, 1]
    assert all(e["length"] <= 40 for e in info["per_episode"])
    assert info["video_paths"] and all((report / "index_files" / v).stat().st_size > 0 for v in info["video_paths"])
    # Its own report is replaced whole.
    dicestack.evaluate(knn, episodes=1, seed=3, world=short_world(40), report=report, progress=False)
    info = json.loads((report / "index_files" / "eval_info" / "row-01.json").read_text())
    assert len(info["per_episode"]) == 1


def test_evaluate_report_is_what_the_command_line_writes(knn, tmp_path, cli):
    model, world = tmp_path / "knn.dsm", tmp_path / "world.json"
    knn.save(model)
    world.write_text(json.dumps(short_world(40)))
    ours, theirs = tmp_path / "py", tmp_path / "cli"
    dicestack.evaluate(dicestack.load_model(model), episodes=3, seed=5, world=os.fspath(world), report=ours,
                       progress=False)
    subprocess.run([cli, "evaluate", "--model", str(model), "--episodes", "3", "--seed", "5", "--world", str(world),
                    "--report", str(theirs)], check=True, capture_output=True)
    files = sorted(p.relative_to(theirs) for p in theirs.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(ours) for p in ours.rglob("*") if p.is_file())
    for f in files:
        if f.suffix in (".json", ".gif") and f.name != "dicestack-report.json":
            assert (ours / f).read_bytes() == (theirs / f).read_bytes(), f
    a, b = page_data(ours / "index.html"), page_data(theirs / "index.html")
    for key in ("realistic_success_rate", "stacked_rate", "wall_contact_rate", "dice_in_cup_mean", "episodes"):
        assert a["rows"][0][key] == b["rows"][0][key], key


def test_evaluate_refuses_a_users_folder_before_any_rollout(knn, tmp_path):
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    (theirs / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="theirs: exists and is not a evaluation report dicestack wrote"):
        dicestack.evaluate(knn, episodes=1, report=theirs, progress=False)
    assert [p.name for p in theirs.iterdir()] == ["keep.txt"]
    a_file = tmp_path / "a_file"
    a_file.write_text("mine")
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.evaluate(knn, episodes=1, report=a_file, progress=False)
    assert a_file.read_text() == "mine"
    with pytest.raises(TypeError, match="report"):
        dicestack.evaluate(knn, episodes=1, report=3)
