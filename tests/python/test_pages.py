"""Results pages loaded in headless Chromium as a person would open them, from
file:// with no network: the rows shown are the rows of the JSON, sorting works, a preview
loads, text from the demonstrations and models shows as text, and the console has no errors.
Pages: the leaderboard's, evaluate --report's, the episode viewer and the robustness table's.

With DICESTACK_SCREENSHOTS=DIR set, each page's screenshot is saved there (docs/images/)."""
import json
import math
import os
import shutil
import subprocess
import time

import pytest

import dicestack
from conftest import short_world

webdriver = pytest.importorskip("selenium.webdriver")
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")
pytestmark = pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER), reason="chromium and chromium-driver are not installed")

HOSTILE = "<script>window.pwned = 1</script><b>bold?</b>"


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1600,1000",
                "--allow-file-access-from-files"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    # The sanitizer build preloads the ASan runtime into Python; the browser must not inherit it.
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "ASAN_OPTIONS", "UBSAN_OPTIONS", "LSAN_OPTIONS")}
    service = webdriver.ChromeService(CHROMEDRIVER, env=env) if hasattr(webdriver, "ChromeService") else None
    if service is None:
        from selenium.webdriver.chrome.service import Service
        service = Service(CHROMEDRIVER, env=env)
    driver = webdriver.Chrome(service=service, options=options)
    yield driver
    driver.quit()


def open_page(driver, path):
    driver.get(path.resolve().as_uri())
    WebDriverWait(driver, 20).until(lambda d: d.execute_script("return document.body.dataset.ready === 'true'"))
    driver.get_log("browser")  # what loading said is checked by no_console_errors


def no_console_errors(driver):
    return [e for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]


def shown_rows(driver):
    """Each table row as {column key: (text, data-value or None)}."""
    return driver.execute_script("""
        return [...document.querySelectorAll('#board tbody tr')].map(tr => {
          const row = {};
          for (const td of tr.querySelectorAll('td[data-key]'))
            row[td.dataset.key] = [td.textContent, td.dataset.value === undefined ? null : Number(td.dataset.value)];
          return row;
        });""")


def assert_rows_equal(shown, rows):
    assert len(shown) == len(rows)
    for s, r in zip(shown, rows):
        for key in ("regressor", "learner", "features"):
            assert s[key][0] == r[key]
        for key in ("train_error", "test_error", "dice_in_cup_mean", "stacked_rate", "wall_contact_rate",
                    "realistic_success_rate", "episodes", "fit_s", "us_per_step"):
            assert s[key][1] == pytest.approx(r[key], rel=1e-12, abs=1e-12), key


def preview_loads(driver, selector):
    img = driver.find_element(By.CSS_SELECTOR, selector)
    driver.execute_script("arguments[0].scrollIntoView()", img)
    WebDriverWait(driver, 20).until(lambda d: d.execute_script(
        "return arguments[0].complete && arguments[0].naturalWidth > 0", img))
    return img


def screenshot(driver, name):
    folder = os.environ.get("DICESTACK_SCREENSHOTS")
    if folder:
        driver.execute_script("window.scrollTo(0, 0)")
        driver.save_screenshot(os.path.join(folder, name))


@pytest.fixture(scope="module")
def demos(builtin_episodes, tmp_path_factory):
    path = tmp_path_factory.mktemp("pages") / "set <b>x</b>"
    dicestack.save_demos(builtin_episodes[:10], path, description=HOSTILE)
    return path


@pytest.fixture(scope="module")
def board(demos, tmp_path_factory):
    page = tmp_path_factory.mktemp("board") / "board.html"
    rows = dicestack.leaderboard(["knn", "linear_svr"], ["bc"], demos, episodes=4, seed=1, out=page, progress=False)
    return page, rows


def test_the_leaderboard_page_shows_the_json_rows_and_sorts(browser, board):
    page, rows = board
    open_page(browser, page)
    assert_rows_equal(shown_rows(browser), rows)
    # Sorting by realistic success: ascending, then descending on a second click; "-" stays last.
    header = browser.find_element(By.CSS_SELECTOR, "th[data-key='test_error'] button")
    header.click()
    values = [r["test_error"][1] for r in shown_rows(browser)]
    present = [v for v in values if v >= 0]
    assert present == sorted(present) and values[len(present):] == [-1] * (len(values) - len(present))
    header.click()
    values = [r["test_error"][1] for r in shown_rows(browser)]
    assert [v for v in values if v >= 0] == sorted(present, reverse=True)
    browser.find_element(By.CSS_SELECTOR, "th[data-key='regressor'] button").click()
    names = [r["regressor"][0] for r in shown_rows(browser)]
    assert names == sorted(names, key=str.lower) or names == sorted(names)
    browser.find_element(By.CSS_SELECTOR, "th[data-key='rank'] button").click()
    assert_rows_equal(shown_rows(browser), rows)  # back in table order
    assert no_console_errors(browser) == []


def test_a_preview_loads_and_each_learned_row_links_its_per_episode_results(browser, board):
    page, rows = board
    open_page(browser, page)
    img = preview_loads(browser, "img.preview")
    assert img.get_attribute("loading") == "lazy"
    links = browser.find_elements(By.CSS_SELECTOR, "#board tbody a")
    learned = [r for r in rows if r["learner"] != "playback"]
    assert len(links) == len(learned)
    for link, row in zip(links, learned):
        info_path = page.parent / link.get_attribute("href").split(page.parent.as_uri() + "/")[1]
        info = json.loads(info_path.read_text())
        # LeRobot's eval_info.json: per_episode entries and the aggregate with its count.
        assert info["row"] == {k: row[k] for k in ("regressor", "learner", "features")}
        assert info["aggregated"]["n_episodes"] == row["episodes"] == len(info["per_episode"])
        assert sum(e["success"] for e in info["per_episode"]) == row["realistic_success"]
        assert sum(e["stacked"] for e in info["per_episode"]) == row["stacked"]
        assert info["aggregated"]["pc_success"] == pytest.approx(100 * row["realistic_success_rate"])
        for e in info["per_episode"]:
            assert {"episode_ix", "seed", "success", "sum_reward", "dice_in_cup", "wall_step", "length"} <= e.keys()
            assert (e["wall_step"] is None) == (not e["wall_contact"])
            assert e["wall_step"] is None or 0 <= e["wall_step"] < e["length"]
        for video in info["video_paths"]:
            assert (info_path.parent.parent / video).stat().st_size > 1000  # relative to the media's folder
    screenshot(browser, "leaderboard-page.png")
    assert no_console_errors(browser) == []


def test_text_from_the_demonstrations_shows_as_text(browser, board, demos):
    page, _ = board
    open_page(browser, page)
    facts = browser.find_element(By.ID, "facts").text
    assert HOSTILE in facts
    assert str(demos) in facts
    assert browser.execute_script("return window.pwned") is None
    assert len(browser.find_elements(By.CSS_SELECTOR, "#facts b, #facts script")) == 0
    assert no_console_errors(browser) == []


def test_the_leaderboard_page_fits_a_laptops_width_and_says_its_facts_once(browser, demos, tmp_path):
    # At 1,400 px the table, its longest names and its previews fit without a horizontal
    # scrollbar; the header line is not repeated above the facts that say the same.
    page = tmp_path / "wide.html"
    dicestack.leaderboard(["knn", "linear_svr"], ["bc"], demos, features=["state+clock+start_state@dice+retry/position"],
                          episodes=4, seed=1, out=page, progress=False)
    browser.set_window_size(1400, 900)
    try:
        open_page(browser, page)
        widths = browser.execute_script(
            "return [document.documentElement.scrollWidth, document.documentElement.clientWidth]")
        assert widths[0] <= widths[1], widths
        folded = browser.find_element(By.ID, "header-line")  # the one-line header, folded under the facts
        assert folded.tag_name == "details" and folded.get_attribute("open") is None
        assert not browser.find_element(By.ID, "header").is_displayed()
        assert "state+clock+start_state@dice+retry/position" in browser.find_element(By.ID, "facts").text
        assert no_console_errors(browser) == []
    finally:
        browser.set_window_size(1600, 1000)


def test_the_page_needs_no_network(board):
    page, _ = board
    text = page.read_text()
    assert text.startswith("<!-- dicestack results page -->\n<!doctype html>")
    for remote in ("http://", "https://", "//cdn"):
        assert remote not in text.replace("http://www.w3.org", "")


def test_a_users_file_is_not_replaced_by_a_page(demos, tmp_path):
    mine = tmp_path / "mine.html"
    mine.write_text("<p>my notes</p>")
    with pytest.raises(ValueError, match="refusing to replace"):
        dicestack.leaderboard(["knn"], ["bc"], demos, episodes=1, out=mine, progress=False)
    assert mine.read_text() == "<p>my notes</p>"
    folder = tmp_path / "board_files"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    with pytest.raises(ValueError, match="board_files"):
        dicestack.leaderboard(["knn"], ["bc"], demos, episodes=1, out=tmp_path / "board.html", progress=False)
    assert (folder / "keep.txt").read_text() == "mine"
    assert not (tmp_path / "board.html").exists()


@pytest.mark.skipif(not os.environ.get("DICESTACK_EXE"), reason="the command line is not built")
def test_evaluate_report_is_a_page_of_one_model(browser, demos, tmp_path):
    exe = os.environ["DICESTACK_EXE"]
    model = tmp_path / "m.dsm"
    subprocess.run([exe, "train", "--demos", str(demos), "--regressor", "knn", "--out", str(model)], check=True,
                   capture_output=True)
    report = tmp_path / "report"
    done = subprocess.run([exe, "evaluate", "--model", str(model), "--episodes", "4", "--seed", "2", "--json",
                           "--report", str(report)], check=True, capture_output=True, text=True)
    stats = json.loads(done.stdout)
    open_page(browser, report / "index.html")
    shown = shown_rows(browser)
    assert len(shown) == 1
    assert shown[0]["regressor"][0] == "knn"
    assert shown[0]["realistic_success_rate"][1] == pytest.approx(stats["realistic_success_rate"])
    assert shown[0]["stacked_rate"][1] == pytest.approx(stats["stacked_rate"])
    preview_loads(browser, "img.preview")
    info = json.loads((report / "index_files" / "eval_info" / "row-01.json").read_text())
    assert [e["index"] for e in info["per_episode"]] == [0, 1, 2, 3]
    assert sum(e["success"] for e in info["per_episode"]) == round(4 * stats["realistic_success_rate"])
    screenshot(browser, "evaluate-report.png")
    assert no_console_errors(browser) == []
    # Again over its own report: replaced; over a user's folder: refused.
    subprocess.run([exe, "evaluate", "--model", str(model), "--episodes", "2", "--report", str(report)], check=True,
                   capture_output=True)
    assert len(json.loads((report / "index_files" / "eval_info" / "row-01.json").read_text())["per_episode"]) == 2
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    refused = subprocess.run([exe, "evaluate", "--model", str(model), "--episodes", "2", "--report", str(theirs)],
                             capture_output=True, text=True)
    assert refused.returncode != 0 and "refusing to replace" in refused.stderr
    assert list(theirs.iterdir()) == []


@pytest.mark.skipif(not os.environ.get("DICESTACK_EXE"), reason="the command line is not built")
def test_the_episode_viewer_lists_the_set_and_its_cursor_follows_the_playback(browser, demos, builtin_episodes, tmp_path):
    exe = os.environ["DICESTACK_EXE"]
    page = tmp_path / "view.html"
    subprocess.run([exe, "dataset", "view", str(demos), "--out", str(page)], check=True, capture_output=True)
    open_page(browser, page)
    listed = browser.execute_script("""
        return [...document.querySelectorAll('#list tbody tr')].map(tr => [...tr.children].map(td => td.textContent));""")
    episodes = builtin_episodes[:10]
    assert [row[1] for row in listed] == [f"episode_{i:04d}" for i in range(10)]
    assert [int(row[2]) for row in listed] == [len(e.states) for e in episodes]
    assert [row[4] == "yes" for row in listed] == [bool(e.stacked) for e in episodes]
    assert [row[3] == "yes" for row in listed] == [bool(e.realistic_success) for e in episodes]
    assert HOSTILE in browser.find_element(By.ID, "facts").text
    assert browser.execute_script("return window.pwned") is None
    # Choose the third episode; its numbers load, the cursor starts at step 0 and moves while it plays.
    browser.find_elements(By.CSS_SELECTOR, "#list tbody tr")[2].click()
    WebDriverWait(browser, 10).until(lambda d: d.execute_script("return document.body.dataset.loaded === '2'"))
    cursor = browser.find_element(By.ID, "cursor")
    assert cursor.get_attribute("data-step") == "0"
    start = browser.execute_script("return arguments[0].getBoundingClientRect().left", cursor)
    browser.find_element(By.ID, "play").click()
    WebDriverWait(browser, 10).until(lambda d: int(cursor.get_attribute("data-step")) >= 20)
    moved = browser.execute_script("return arguments[0].getBoundingClientRect().left", cursor)
    assert moved > start
    browser.find_element(By.ID, "play").click()  # pause: the cursor stays
    paused = cursor.get_attribute("data-step")
    time.sleep(0.3)
    assert cursor.get_attribute("data-step") == paused
    screenshot(browser, "episode-viewer.png")
    assert no_console_errors(browser) == []
    # The page is ours to replace; a user's folder beside it is not.
    subprocess.run([exe, "dataset", "view", str(demos), "--out", str(page)], check=True, capture_output=True)
    other = tmp_path / "other.html"
    (tmp_path / "other_files").mkdir()
    refused = subprocess.run([exe, "dataset", "view", str(demos), "--out", str(other)], capture_output=True, text=True)
    assert refused.returncode != 0 and "other_files" in refused.stderr
    assert not other.exists()
    # A page moved without its folder says what is missing when an episode is chosen.
    moved = tmp_path / "moved"
    moved.mkdir()
    shutil.copy(page, moved / "view.html")
    open_page(browser, moved / "view.html")
    browser.find_elements(By.CSS_SELECTOR, "#list tbody tr")[1].click()
    WebDriverWait(browser, 10).until(lambda d: "is missing" in d.find_element(By.ID, "name").text)
    browser.get_log("browser")  # the failed load is reported there, as it should be


def rate_text(rate, low, high):
    """What the page shows for a rate and its interval (JavaScript's Math.round)."""
    pc = lambda v: math.floor(100 * v + 0.5)  # noqa: E731
    return f"{pc(rate)}% [{pc(low)}-{pc(high)}]"


@pytest.mark.skipif(not os.environ.get("DICESTACK_EXE"), reason="the command line is not built")
def test_the_robustness_page_shows_the_json_rows_and_sorts(browser, tmp_path):
    exe = os.environ["DICESTACK_EXE"]
    # The scripted expert in the paper's world, 2 rollouts per row: a few seconds, rates that differ.
    args = [exe, "robustness", "--expert", "scripted", "--episodes", "2", "--seed", "1"]
    table = json.loads(subprocess.run(args + ["--format", "json"], check=True, capture_output=True, text=True).stdout)
    page = tmp_path / "robust.html"
    done = subprocess.run(args + ["--format", "html", "--out", str(page)], check=True, capture_output=True, text=True)
    assert done.stdout.startswith("<!-- dicestack robustness -->")  # the terminal gets the Markdown
    assert page.read_text().startswith("<!-- dicestack results page -->\n<!doctype html>")
    assert list(tmp_path.iterdir()) == [page]  # one file: data, style and script inside
    open_page(browser, page)
    rows = table["rows"]
    shown = shown_rows(browser)
    assert len(shown) == len(rows) == 1 + 3 * 7 + 3  # nominal, the 7 factors an expert meets, all
    for s, r in zip(shown, rows):
        assert s["factor"][0] == r["factor"] and s["level"][0] == r["level"]
        for key in ("realistic_success_rate", "wall_contact_rate", "dice_in_cup_mean", "episodes"):
            assert s[key][1] == pytest.approx(r[key], rel=1e-12, abs=1e-12), key
        assert s["realistic_success_rate"][0] == rate_text(*r["realistic_success_rate_ci95"])
        assert s["wall_contact_rate"][0] == rate_text(*r["wall_contact_rate_ci95"])
        assert s["successes"][0] == f"{round(r['realistic_success_rate'] * r['episodes'])} of {r['episodes']}"
    facts = browser.find_element(By.ID, "facts").text
    for text in ("expert scripted", "rollouts_per_row", "default", table["dicestack_version"], "sensing_factors"):
        assert text in facts
    assert browser.find_element(By.ID, "title").text == "dicestack robustness: expert scripted"
    # Sorting: by realistic success up, then down; by level in order of severity; # restores.
    header = browser.find_element(By.CSS_SELECTOR, "th[data-key='realistic_success_rate'] button")
    header.click()
    values = [s["realistic_success_rate"][1] for s in shown_rows(browser)]
    assert values == sorted(values) and len(set(values)) > 1
    header.click()
    assert [s["realistic_success_rate"][1] for s in shown_rows(browser)] == sorted(values, reverse=True)
    browser.find_element(By.CSS_SELECTOR, "th[data-key='level'] button").click()
    levels = [s["level"][0] for s in shown_rows(browser)]
    assert levels == sorted(levels, key=["none", "easy", "medium", "hard"].index)
    browser.find_element(By.CSS_SELECTOR, "th[data-key='factor'] button").click()
    factors = [s["factor"][0] for s in shown_rows(browser)]
    assert factors == sorted(factors)
    browser.find_element(By.CSS_SELECTOR, "th[data-key='rank'] button").click()
    assert [(s["factor"][0], s["level"][0]) for s in shown_rows(browser)] == [(r["factor"], r["level"]) for r in rows]
    browser.find_element(By.CSS_SELECTOR, "th[data-key='realistic_success_rate'] button").click()
    browser.find_element(By.CSS_SELECTOR, "th[data-key='realistic_success_rate'] button").click()
    screenshot(browser, "robustness-page.png")
    assert no_console_errors(browser) == []
    # Ours is replaced; a user's page is not.
    subprocess.run(args + ["--format", "html", "--out", str(page)], check=True, capture_output=True)
    mine = tmp_path / "mine.html"
    mine.write_text("<p>my notes</p>")
    refused = subprocess.run(args + ["--format", "html", "--out", str(mine)], capture_output=True, text=True)
    assert refused.returncode != 0 and "refusing to replace" in refused.stderr
    assert mine.read_text() == "<p>my notes</p>"


@pytest.mark.skipif(not os.environ.get("DICESTACK_EXE"), reason="the command line is not built")
def test_text_from_the_model_shows_as_text_on_the_robustness_page(browser, demos, tmp_path):
    exe = os.environ["DICESTACK_EXE"]
    folder = tmp_path / "<img src=x onerror=window.pwned=1>"
    folder.mkdir()
    model, world = folder / "m.dsm", tmp_path / "short.json"
    subprocess.run([exe, "train", "--demos", str(demos), "--regressor", "knn", "--split", "none", "--out", str(model)],
                   check=True, capture_output=True)
    world.write_text(json.dumps(short_world(20)))
    page = tmp_path / "robust.html"
    subprocess.run([exe, "robustness", "--model", str(model), "--world", str(world), "--episodes", "1",
                    "--format", "html", "--out", str(page)], check=True, capture_output=True)
    open_page(browser, page)
    assert len(shown_rows(browser)) == 1 + 3 * 9 + 3
    facts = browser.find_element(By.ID, "facts").text
    assert str(model) in facts and str(demos) in facts and str(world) in facts
    assert str(model) in browser.find_element(By.ID, "title").text
    assert browser.execute_script("return window.pwned") is None
    assert len(browser.find_elements(By.CSS_SELECTOR, "img, #facts b")) == 0
    assert no_console_errors(browser) == []
