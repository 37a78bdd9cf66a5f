// The leaderboard's formats as one table, the html page's files, and the robustness table's
// page. The pages in a browser: tests/python/test_pages.py.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/leaderboard.hpp>
#include <dicestack/learners/results_page.hpp>
#include <dicestack/learners/robustness.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The JSON a page inlines between its data script's tags.
nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"page-data\">";
  const auto from = page.find(open) + open.size();
  return nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
}

// Two learned rows (one with previews) and the playback row, as a run would leave them.
Leaderboard small_board(const std::string& name = "knn") {
  Leaderboard b;
  b.header = "test board";
  b.meta_json = R"({"demos": "d", "seed": 1})";
  LeaderboardRow a{name, "bc", "state"};
  for (int i = 0; i < 3; ++i) {
    EpisodeResult e;
    e.index = i;
    e.seed = 100u + static_cast<unsigned>(i);
    e.success = e.stacked = i == 1;
    e.wall_contact = i == 2;
    e.wall_step = i == 2 ? 7 : -1;
    e.length = 20;
    a.rollouts.push_back({0, e});
  }
  a.episodes = 3, a.success = a.stacked = 1, a.walls = 1;
  const State s = paper_start_state(b.world);
  a.success_preview.push_back({0, 1, 101, std::vector<State>(4, s)});
  a.failure_preview.push_back({0, 0, 100, std::vector<State>(3, s)});
  LeaderboardRow c{"linear_svr", "bc", "state"};
  c.rollouts = a.rollouts;
  c.episodes = 3;
  LeaderboardRow playback{"(demonstrations)", "playback"};
  b.rows = {a, c, playback};
  return b;
}

TEST(LeaderboardFormats, OneEntryEachWithAUniqueNameAndSuffix) {
  std::set<std::string> names, suffixes;
  for (const LeaderboardFormat& f : leaderboard_formats()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(suffixes.insert(f.suffix).second) << f.suffix;
    EXPECT_FALSE(f.description.empty()) << f.name;
    EXPECT_FALSE(render_leaderboard(small_board(), f.name).empty()) << f.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"md", "csv", "latex", "json", "html"}));
  EXPECT_THROW(leaderboard_format("pdf"), ConfigError);
}

TEST(LeaderboardFormats, EachWrittenFileIsRecognisedAsOursAndReplacedAgain) {
  const fs::path dir = test::scratch_path("dicestack_formats_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const LeaderboardFormat& f : leaderboard_formats()) {
    const fs::path out = dir / ("board" + f.suffix);
    write_leaderboard(small_board(), f.name, out);
    EXPECT_TRUE(f.ownership().recognises(out)) << f.name;
    EXPECT_EQ(read(out).rfind(f.marker, 0), 0u) << f.name;
    write_leaderboard(small_board("gbt"), f.name, out);  // ours: replaced
    EXPECT_NE(read(out).find("gbt"), std::string::npos) << f.name;
  }
  fs::remove_all(dir);
}

// The generation folder of PAGE_files/ that the page at `page` links (empty if none).
fs::path linked_media(const fs::path& page) {
  const std::string text = read(page);
  const std::string folder = page.stem().string() + "_files/";
  const std::size_t at = text.find("\"" + folder + "m-");
  if (at == std::string::npos) return {};
  return page.parent_path() / (page.stem().string() + "_files") / text.substr(at + 1 + folder.size(), 18);
}

std::vector<std::string> entries_of(const fs::path& folder) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(folder)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ResultsPage, WritesEvalInfoPerLearnedRowAndPreviewsWhereKept) {
  const fs::path dir = test::scratch_path("dicestack_page_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_leaderboard(small_board(), "html", dir / "board.html");
  const fs::path media = linked_media(dir / "board.html");
  ASSERT_FALSE(media.empty()) << "the page links no generation of its media";
  EXPECT_EQ(entries_of(dir / "board_files"), (std::vector<std::string>{"dicestack-page.json", media.filename().string()}));
  EXPECT_TRUE(fs::exists(media / "previews" / "row-01-success.gif"));
  EXPECT_TRUE(fs::exists(media / "previews" / "row-01-failure.gif"));
  EXPECT_FALSE(fs::exists(media / "previews" / "row-02-success.gif")) << "row 2 kept no previews";
  EXPECT_FALSE(fs::exists(media / "eval_info" / "row-03.json")) << "playback has no rollouts of its own";
  const auto info = nlohmann::json::parse(read(media / "eval_info" / "row-01.json"));
  ASSERT_EQ(info["per_episode"].size(), 3u);
  EXPECT_EQ(info["per_episode"][2]["wall_step"], 7);
  EXPECT_TRUE(info["per_episode"][0]["wall_step"].is_null());
  EXPECT_EQ(info["per_episode"][1]["seed"], 101u);
  EXPECT_EQ(info["aggregated"]["n_episodes"], 3);
  EXPECT_DOUBLE_EQ(info["aggregated"]["pc_success"].get<double>(), 100.0 / 3);
  EXPECT_EQ(info["video_paths"], (nlohmann::json{"previews/row-01-success.gif", "previews/row-01-failure.gif"}));
  // The page refers to its media by the folder's name, relative to itself.
  const std::string page = read(dir / "board.html");
  EXPECT_NE(page.find("\"board_files/" + media.filename().string() + "/previews/row-01-success.gif\""), std::string::npos);
  fs::remove_all(dir);
}

TEST(ResultsPage, APageAndItsMediaAreOneUnitAndOnlyTheLinkedMediaStay) {
  const fs::path dir = test::scratch_path("dicestack_page_pair_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path page = dir / "board.html";
  // A run killed while it created the media folder left its scratch beside it: the next one removes it.
  fs::create_directories(dir / ".board_files.tmp-999999999-x");
  write_leaderboard(small_board(), "html", page);
  EXPECT_FALSE(fs::exists(dir / ".board_files.tmp-999999999-x"));
  const std::string first_page = read(page);
  const fs::path first = linked_media(page);
  // The same board again: the same media, the same generation, the same page.
  write_leaderboard(small_board(), "html", page);
  EXPECT_EQ(read(page), first_page);
  EXPECT_EQ(linked_media(page), first);
  // Another board: a new generation, linked; the old one is gone; a dead run's scratch too.
  const fs::path dead_scratch = dir / "board_files" / ".generation.tmp-999999999-x";
  fs::create_directories(dead_scratch);
  std::ofstream(dir / "board_files" / ".dicestack-page.json.tmp-999999999-x") << "{";  // a killed marker write
  write_leaderboard(small_board("another"), "html", page);
  const fs::path second = linked_media(page);
  ASSERT_FALSE(second.empty());
  EXPECT_NE(second, first);
  EXPECT_EQ(entries_of(dir / "board_files"), (std::vector<std::string>{"dicestack-page.json", second.filename().string()}));
  EXPECT_TRUE(fs::exists(second / "previews" / "row-01-success.gif"));
  const auto marker = nlohmann::json::parse(read(dir / "board_files" / "dicestack-page.json"));
  EXPECT_EQ(marker["version"], 2) << "a folder of generations";
  fs::remove_all(dir);
}

TEST(ResultsPage, AMediaFolderOfTheOlderLayoutBecomesOneOfGenerations) {
  // Version 1 wrote the media at the folder's top; the page that linked them is replaced whole.
  const fs::path dir = test::scratch_path("dicestack_page_v1_test");
  fs::remove_all(dir);
  fs::create_directories(dir / "board_files" / "previews");
  std::ofstream(dir / "board_files" / "dicestack-page.json") << R"({"format": "dicestack-page-media", "version": 1})";
  std::ofstream(dir / "board_files" / "previews" / "row-01-success.gif") << "GIF89a";
  std::ofstream(dir / "board.html") << kResultsPageMarker << "\n<p>old</p>";
  write_leaderboard(small_board(), "html", dir / "board.html");
  const fs::path media = linked_media(dir / "board.html");
  EXPECT_EQ(entries_of(dir / "board_files"), (std::vector<std::string>{"dicestack-page.json", media.filename().string()}));
  EXPECT_EQ(nlohmann::json::parse(read(dir / "board_files" / "dicestack-page.json"))["version"], 2);
  fs::remove_all(dir);
}

TEST(ResultsPage, NoTextFromTheRunCanCloseItsScript) {
  Leaderboard b = small_board("</script><script>alert(1)</script>");
  b.demos_description = "<!-- & -->";
  const std::string page = results_page_html(b, "m");
  EXPECT_EQ(page.find("alert(1)</script>"), std::string::npos);
  EXPECT_EQ(page.find("<!-- & -->"), std::string::npos);
  EXPECT_NE(page.find("\\u003c/script\\u003e\\u003cscript\\u003ealert(1)"), std::string::npos);
  // The data is one JSON object between the script tags; it reads back to the same text.
  const auto data = page_data(page);
  EXPECT_EQ(data["rows"][0]["regressor"], "</script><script>alert(1)</script>");
}

TEST(ResultsPage, RefersToAMediaFolderWhateverItsName) {
  const fs::path dir = test::scratch_path("dicestack_page_name_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_leaderboard(small_board(), "html", dir / "my #1 b\xc3\xb6" "ard.html");
  const std::string page = read(dir / "my #1 b\xc3\xb6" "ard.html");
  const std::size_t at = page.find("\"my%20%231%20b%C3%B6ard_files/m-");
  ASSERT_NE(at, std::string::npos);
  const std::string generation = page.substr(at + 1 + std::string("my%20%231%20b%C3%B6ard_files/").size(), 18);
  EXPECT_NE(page.find("\"my%20%231%20b%C3%B6ard_files/" + generation + "/previews/row-01-success.gif\""), std::string::npos);
  EXPECT_NE(page.find("\"my%20%231%20b%C3%B6ard_files/" + generation + "/eval_info/row-01.json\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "my #1 b\xc3\xb6" "ard_files" / generation / "previews" / "row-01-success.gif"));
  fs::remove_all(dir);
}

TEST(ResultsPage, AUsersFolderBesideThePageIsRefusedBeforeAnythingIsWritten) {
  const fs::path dir = test::scratch_path("dicestack_page_refuse_test");
  fs::remove_all(dir);
  fs::create_directories(dir / "board_files");
  std::ofstream(dir / "board_files" / "notes.txt") << "mine";
  try {
    write_leaderboard(small_board(), "html", dir / "board.html");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("board_files"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "board.html"));
  EXPECT_EQ(read(dir / "board_files" / "notes.txt"), "mine");
  // A user's page at --out is refused too, and the folder beside it untouched.
  fs::remove_all(dir / "board_files");
  std::ofstream(dir / "board.html") << "<p>mine</p>";
  EXPECT_THROW(write_leaderboard(small_board(), "html", dir / "board.html"), InputError);
  EXPECT_FALSE(fs::exists(dir / "board_files"));
  fs::remove_all(dir);
}

// A robustness table of three rows, run by `policy`, with `record` as the model's training record.
RobustnessTable robustness_example(const std::string& policy, const std::map<std::string, std::string>& record = {}) {
  std::vector<RobustnessRow> rows;
  const std::vector<std::pair<const char*, const char*>> names{{"none", "none"}, {"friction", "hard"}, {"all", "easy"}};
  for (std::size_t i = 0; i < names.size(); ++i) {
    RobustnessRow r{names[i].first, names[i].second, {}};
    r.stats.episodes = 4;
    r.stats.realistic_success = wilson(3 - static_cast<int>(i), 4);
    r.stats.wall_contact = wilson(static_cast<int>(i), 4);
    r.stats.dice_in_cup_mean = 3.0 - 0.5 * static_cast<double>(i);
    rows.push_back(r);
  }
  RobustnessRun run;
  run.policy = policy;
  run.world = "short.json";
  run.episodes = 4;
  run.seed = 7;
  run.record = record;
  return robustness_table(rows, run);
}

TEST(RobustnessPage, HoldsTheJsonRowsAndTheRunsFactsWithNoNetwork) {
  const RobustnessTable table = robustness_example("model m.dsm (knn, state)", {{"learner", "bc"}});
  const std::string page = render_robustness(table, "html");
  EXPECT_EQ(page.rfind(std::string(kResultsPageMarker) + "\n<!doctype html>", 0), 0u);
  for (const char* remote : {"http://", "https://", "//cdn", "<link", "src="}) EXPECT_EQ(page.find(remote), std::string::npos) << remote;
  const auto data = page_data(page);
  const auto json = nlohmann::json::parse(render_robustness(table, "json"));
  EXPECT_EQ(data["title"], "dicestack robustness: model m.dsm (knn, state)");
  EXPECT_EQ(data["header"], json["header"]);
  ASSERT_EQ(data["rows"].size(), json["rows"].size());
  for (std::size_t i = 0; i < data["rows"].size(); ++i) {
    const auto& shown = data["rows"][i];
    for (const auto& [key, value] : json["rows"][i].items()) EXPECT_EQ(shown[key], value) << key;  // the json row, whole
    EXPECT_EQ(shown["rank"], i + 1);
    const auto& ci = json["rows"][i]["realistic_success_rate_ci95"];
    EXPECT_EQ(shown["realistic_success_ci95"], (nlohmann::json{ci[1], ci[2]})) << "the interval the page shows";
    EXPECT_EQ(shown["successes"], 3 - static_cast<int>(i));
  }
  std::map<std::string, nlohmann::json> facts;
  for (const auto& f : data["facts"]) facts[f[0]] = f[1];
  EXPECT_EQ(facts["policy"], "model m.dsm (knn, state)");
  EXPECT_EQ(facts["world"], "short.json");
  EXPECT_EQ(facts["rollouts_per_row"], 4);
  EXPECT_EQ(facts["seed"], 7);
  EXPECT_EQ(facts["dicestack_version"], json["dicestack_version"]);
  EXPECT_EQ(facts["model_record"], (nlohmann::json{{"learner", "bc"}}));
  EXPECT_EQ(facts.count("sensing_factors"), 0u);
}

TEST(RobustnessPage, TextFromTheModelAndTheSetCannotCloseItsScript) {
  const std::string hostile = "</script><script>alert(1)</script>";
  const RobustnessTable table = robustness_example("model " + hostile, {{"demos", "<!-- & -->"}});
  const std::string page = render_robustness(table, "html");
  EXPECT_EQ(page.find("alert(1)</script>"), std::string::npos);
  EXPECT_EQ(page.find("<!-- & -->"), std::string::npos);
  const auto data = page_data(page);
  EXPECT_EQ(data["title"], "dicestack robustness: model " + hostile);
  EXPECT_THAT(data["header"].get<std::string>(), ::testing::HasSubstr(hostile));
  bool record = false;
  for (const auto& f : data["facts"]) record |= f[0] == "model_record" && f[1]["demos"] == "<!-- & -->";
  EXPECT_TRUE(record);
}

TEST(RobustnessPage, ReplacesOnlyAPageOfOursAndLeavesNothingBeside) {
  const fs::path dir = test::scratch_path("dicestack_robustness_page_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "robust.html";
  write_robustness(robustness_example("expert scripted"), "html", out);
  EXPECT_TRUE(results_page_ownership().recognises(out));
  write_robustness(robustness_example("expert mpc"), "html", out);  // ours: replaced
  EXPECT_NE(read(out).find("expert mpc"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "one file, no media folder";
  std::ofstream(out) << "<p>mine</p>";
  EXPECT_THROW(check_robustness_out(out, "html"), InputError);
  EXPECT_THROW(write_robustness(robustness_example("expert mpc"), "html", out), InputError);
  EXPECT_EQ(read(out), "<p>mine</p>");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dicestack
