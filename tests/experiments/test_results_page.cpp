// The leaderboard's html page: its media folder beside it and the generation it links, and no
// text from the run closing its script. The pages in a browser: tests/python/test_pages.py.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/experiments/results_page.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/pages.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using test::page_data;
using test::read;
using test::small_board;

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

}  // namespace
}  // namespace dicestack
