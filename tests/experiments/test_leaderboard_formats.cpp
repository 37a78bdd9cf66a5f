// The leaderboard's formats as one table: one entry each with a unique name and suffix, and each
// written file recognised as ours and replaced again.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/leaderboard.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/pages.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using test::read;
using test::small_board;

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

}  // namespace
}  // namespace dicestack
