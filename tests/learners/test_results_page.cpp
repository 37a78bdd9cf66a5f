// The leaderboard's formats as one table, and the html page's files (issue 26). The page in a
// browser: tests/python/test_pages.py.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/leaderboard.hpp>
#include <dicestack/learners/results_page.hpp>

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

TEST(ResultsPage, WritesEvalInfoPerLearnedRowAndPreviewsWhereKept) {
  const fs::path dir = test::scratch_path("dicestack_page_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_leaderboard(small_board(), "html", dir / "board.html");
  const fs::path media = dir / "board_files";
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
  EXPECT_NE(page.find("\"board_files/previews/row-01-success.gif\""), std::string::npos);
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
  const std::string open = "<script type=\"application/json\" id=\"page-data\">";
  const auto from = page.find(open) + open.size();
  const auto data = nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
  EXPECT_EQ(data["rows"][0]["regressor"], "</script><script>alert(1)</script>");
}

TEST(ResultsPage, RefersToAMediaFolderWhateverItsName) {
  const std::string page = results_page_html(small_board(), "my #1 b\xc3\xb6" "ard_files");
  EXPECT_NE(page.find("\"my%20%231%20b%C3%B6ard_files/previews/row-01-success.gif\""), std::string::npos);
  EXPECT_NE(page.find("\"my%20%231%20b%C3%B6ard_files/eval_info/row-01.json\""), std::string::npos);
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

}  // namespace
}  // namespace dicestack
